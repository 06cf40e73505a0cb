"""How a scenario runs live behind the MAVLink endpoint: the route hook into its guidance, which scenarios
can run live, whether they follow the stick, and the numba warm-up before serving."""

from __future__ import annotations

import math

import numpy as np

#: simulated time after a new route before the pilot's ``guidance.wp_index`` is read (a pilot period or more)
_FRESH_S = 0.1


class RouteHook:
    """How a mission reaches the scenario's guidance (see the module docstring).

    ``set_route(points)`` gives the route as (north, east) m; ``progress(bus)`` is the number of route
    points reached since; ``available`` says whether the scenario can fly a route at all.
    """

    def __init__(self, scenario, sim):
        self.sim = sim
        self.kind = "none"
        self.block = None
        self.n = 0
        if getattr(scenario, "console_route_edit", False):
            self.kind = "console"
        else:
            from ..guidance.pure_pursuit import PurePursuit

            for b in sim.blocks:
                inner = getattr(b, "block", b)
                if isinstance(inner, PurePursuit):
                    self.kind = "pure_pursuit"
                    self.block = inner
                    inner.stop_at_end = False  # a live vehicle holds after the mission, it does not stop
                    break
        self._base = 0
        self._t_set = -math.inf

    @property
    def available(self) -> bool:
        return self.kind != "none"

    def initial_route(self, cfg) -> list[tuple[float, float]]:
        g = getattr(cfg, "guidance", None)
        wps = getattr(g, "waypoints", None) if g is not None else None
        return [(float(a), float(b)) for a, b in (wps or [])]

    def set_route(self, points) -> None:
        pts = tuple((float(a), float(b)) for a, b in points)
        self.n = len(pts)
        bus = self.sim.bus
        if self.kind == "console":
            from ..guidance.route_pilot import send_route

            # the pilot restarts its route when the tuple changes; a repeated identical route is
            # made distinct by a sub-millimetre offset of the first point
            if tuple(bus.get("console.waypoints", ())) == pts and pts:
                pts = ((pts[0][0] + 1e-6, pts[0][1]),) + pts[1:]
            send_route(self.sim, pts)
            self._base = 0
            self._t_set = float(self.sim.t)
        elif self.kind == "pure_pursuit":
            b = self.block
            here = (float(bus.get(b.pos_keys[0], 0.0)), float(bus.get(b.pos_keys[1], 0.0)))
            wp = [here]
            for p in pts:
                if math.hypot(p[0] - wp[-1][0], p[1] - wp[-1][1]) > 1e-6:
                    wp.append(p)
            if len(wp) < 2:
                wp.append((here[0] + 1e-3, here[1]))
            b.wp = np.asarray(wp, float)
            b.reset(None)
            b._started = True
            b.reached = 1  # the start point (where the vehicle is)
            self._base = 1 - (len(pts) + 1 - len(wp))  # points dropped as coincident count as reached

    def progress(self, bus) -> int:
        if self.kind == "console":
            if "console.waypoints" not in bus or self.sim.t < self._t_set + _FRESH_S:
                return 0  # guidance.wp_index is the old route's until the pilot has run on the new one
            return int(bus.get("guidance.wp_index", 0.0))
        if self.kind == "pure_pursuit":
            return int(self.block.reached) - self._base
        return 0


def builds_live(sc) -> bool:
    """A scenario runs live if it overrides ``Scenario.build`` (one Simulation the loop can step)."""
    from ..scenarios.base import Scenario

    return type(sc).build is not Scenario.build


def live_scenarios() -> list[str]:
    from ..scenarios.base import registry

    return [n for n, s in registry().items() if builds_live(s)]


#: blocks that follow ``console.mode`` / ``joystick.*`` but do not declare them yet (core contract 4e36fa4:
#: blocks declare their inputs; until these do, they are known by class)
_STICK_BLOCKS = ("USVPilot", "USVController", "_RemoteGate")


def reads_stick(sim) -> bool:
    """Whether the scenario's blocks follow the operator's stick (``console.mode`` = "remote")."""
    for b in sim.blocks:
        for decl in (getattr(b, "inputs", None), getattr(b, "optional_inputs", None)):
            if isinstance(decl, dict) and ("console.mode" in decl or "joystick.surge" in decl):
                return True
        if type(b).__name__ in _STICK_BLOCKS:
            return True
    return False


class _RemoteGate:
    """Wraps a scenario's own pilot block (one that writes ``joystick.*``): it is silent while
    ``console.mode == "remote"``, so that the operator's stick, not the pilot's, reaches the vehicle."""

    def __init__(self, block):
        self.block = block
        self.name = block.name
        self.period = block.period

    def reset(self, rng) -> None:
        self.block.reset(rng)

    def step(self, t: float, bus: dict) -> None:
        if bus.get("console.mode") != "remote":
            self.block.step(t, bus)

    def __getattr__(self, item):
        return getattr(self.block, item)


def gate_pilots(sim) -> int:
    """Gate the pilot blocks of a built simulation (see :class:`_RemoteGate`); returns how many.

    A pilot block is one flagged ``console_pilot = True`` or the scripted berthing pilot.
    """
    n = 0
    for i, b in enumerate(sim.blocks):
        if getattr(b, "console_pilot", False) or type(b).__name__ == "ScriptedPilot":
            sim.blocks[i] = _RemoteGate(b)
            n += 1
    return n


def warm_up(sim, seconds: float = 0.5) -> None:
    """Run the simulation ``seconds`` ahead and restore it exactly (blocks' ``get_state`` / ``set_state``,
    plant states, bus, clock: the checkpoint of the core contract), so that numba compiles every path
    now and not inside the served loop, where a multi-second compile would delay the link watchdog."""
    import copy

    blocks = [b.get_state() for b in sim.blocks]
    xs = [pl.x.copy() for pl in sim.plants]
    bus = copy.deepcopy(sim.bus)
    clock = (sim.k, sim.t, sim._done_k, list(sim.fire_count))
    try:
        sim.run(seconds)
    except Exception:  # noqa: BLE001, S110 a warm-up only; the real run reports any error
        pass
    finally:
        for blk, st in zip(sim.blocks, blocks):
            blk.set_state(st)
        for pl, x in zip(sim.plants, xs):
            pl.x[:] = x
        sim.bus.clear()
        sim.bus.update(bus)
        sim.k, sim.t, sim._done_k, sim.fire_count = clock[0], clock[1], clock[2], list(clock[3])
