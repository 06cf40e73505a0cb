"""A live console session: one scenario's simulation stepped in a thread, paced to wall-clock time.

Pacing. With ``speed`` the ratio of simulated to wall time, the loop (100 Hz) keeps

    t_sim_target = t_sim(anchor) + speed * (t_wall - t_wall(anchor))

and advances the simulation by whole clock ticks (``sim.tick * sim.dt``, so every block keeps its
firing schedule) up to the target with ``sim.run``. The anchor is reset on resume and whenever the
simulation falls more than ``max_lag`` s of simulated time behind (then the run is slower than asked
and the page shows the measured real-time factor). Simulated time therefore tracks wall time to
within one tick plus one loop period, independent of how long the run lasts.

Commands (validated in :mod:`oceangnc.console.messages`) are queued by the web server and applied in
the simulation thread between two chunks, by writing the shared bus keys with ``sim.inject``:
``console.mode``, ``console.loop``, ``joystick.surge``, ``joystick.yaw``, ``console.waypoints``,
``_estop``, and the logged flags ``console.failsafe``, ``console.estop``.

Failsafe. In remote mode, if no client is connected or no stick message arrived for
``stick_timeout`` (1 s), the stick is zeroed and the vehicle goes to its failsafe: thrust to zero
(``_estop`` on the bus) unless the scenario says it can station-keep (``failsafe_station_keep``;
then only ``console.failsafe`` is raised and the scenario holds position). The failsafe clears when
the link is back *and* the stick is at neutral (so a stick held over during the outage cannot
launch the vehicle), or when the operator switches to autonomous mode. The emergency stop is
separate and latched: only an explicit reset clears it. When either sets ``_estop``, the session
fires the scenario's blocks once at that instant, so the actuator blocks' outputs are zero before the
next integration step and in the very next state message (not one actuator period later).

Log. Every logged row goes both to ``log.parquet`` in the run folder (through
:class:`oceangnc.io.logs.LogWriter`, closed when the run ends) and to column arrays in memory, from
which :meth:`Session.log_bytes` writes, with the same LogWriter, the Parquet file the page downloads.
"""

from __future__ import annotations

import io
import json
import math
import threading
import time
import traceback
from array import array
from collections import deque
from pathlib import Path

import numpy as np

from ..errors import DivergenceError, OceanGNCError
from ..io.logs import LogWriter, atomic_write_text
from .messages import Pause, Rejected, check_gains
from .view import infer_view

NEUTRAL = 0.05  #: stick deflection below which the stick counts as centred (failsafe reset)


class _TeeLog:
    """Log sink for ``sim.run``: forwards rows to a LogWriter and keeps them as column arrays."""

    def __init__(self, writer: LogWriter | None):
        self.writer = writer
        self.columns: list[str] | None = None
        self.t = array("d")
        self.data: dict[str, array] = {}

    def append(self, t: float, row: dict) -> None:
        if self.writer is not None:
            self.writer.append(t, row)
        if self.columns is None:
            self.columns = list(row)
            self.data = {c: array("d") for c in self.columns}
        self.t.append(float(t))
        for c in self.columns:
            self.data[c].append(float(row.get(c, math.nan)))

    def __len__(self) -> int:
        return len(self.t)


def _finite(v):
    v = float(v)
    return v if math.isfinite(v) else None


def collect_gains(sim) -> dict[str, dict]:
    """Adjustable gains of a simulation's blocks: ``"<block>.<gain>" -> spec`` with a setter.

    A block offering ``gain_specs()`` / ``set_gain(name, value)`` is asked; otherwise every
    :class:`oceangnc.control.pid.PID` attribute of a block exposes its kp, ki, kd with the range
    [0, max(10 |value|, 1)].
    """
    from ..control.pid import PID

    out: dict[str, dict] = {}
    for b in sim.blocks:
        if hasattr(b, "gain_specs") and hasattr(b, "set_gain"):
            for s in b.gain_specs():
                name = f"{b.name}.{s['name']}"
                spec = {k: s[k] for k in ("value", "min", "max") if k in s}
                spec.update(
                    {
                        "unit": s.get("unit", ""),
                        "description": s.get("description", ""),
                        "setter": (lambda v, b=b, n=s["name"]: b.set_gain(n, v)),
                        "getter": (
                            lambda b=b, n=s["name"]: next(
                                (x["value"] for x in b.gain_specs() if x["name"] == n), math.nan
                            )
                        ),
                    }
                )
                out[name] = spec
            continue
        for attr, obj in vars(b).items():
            if isinstance(obj, PID):
                for g in ("kp", "ki", "kd"):
                    v = getattr(obj, g)
                    out[f"{b.name}.{attr}.{g}"] = {
                        "value": v,
                        "min": 0.0,
                        "max": max(10 * abs(v), 1.0),
                        "unit": "",
                        "description": f"{attr} PID {g}",
                        "setter": (lambda val, o=obj, g=g: setattr(o, g, float(val))),
                        "getter": (lambda o=obj, g=g: getattr(o, g)),
                    }
    return out


class Session:
    """One live console session (see the module docstring).

    Parameters
    ----------
    scenario : str, optional
        Scenario name (default: ``combined-survey`` when it runs live, else ``usv-remote``).
    overrides : dict, optional
        Config overrides (dotted keys) for every run of the first scenario (other scenarios started
        with "new run" get their defaults).
    speed : float
        Simulated seconds per wall-clock second (0 < speed <= 100).
    out_root : path
        Folder under which each run gets ``console-<scenario>-<time>/`` with ``log.parquet``.
    stick_timeout : float
        Seconds without a stick message (remote mode) before the failsafe trips.
    clock : callable
        Wall clock in seconds (tests pass a fake one and call :meth:`step_once` themselves).
    start_on_connect : bool
        Hold the first run paused at t = 0 until the first operator connects (the command line
        does this, so that a route is not over before anyone watches).
    """

    def __init__(
        self,
        scenario: str | None = None,
        overrides: dict | None = None,
        speed: float = 1.0,
        out_root: str | Path = "runs",
        stick_timeout: float = 1.0,
        loop_hz: float = 100.0,
        max_lag: float = 0.5,
        write_log: bool = True,
        clock=time.perf_counter,
        start_on_connect: bool = False,
    ):
        if not (0 < speed <= 100 and math.isfinite(speed)):
            from ..errors import InputError

            raise InputError(f"--speed {speed}: allowed range 0 < speed <= 100 (simulated s per wall s)")
        self.overrides = dict(overrides or {})
        self.speed = float(speed)
        self.out_root = Path(out_root)
        self.stick_timeout = float(stick_timeout)
        self.resume_ramp_s = 2.0  #: after an e-stop / failsafe, controller outputs ramp up over this, s
        self.loop_period = 1.0 / loop_hz
        self.max_lag = float(max_lag)
        self.write_log = write_log
        self.clock = clock
        self._lock = threading.RLock()
        self._cmds: deque = deque()
        self._stop = threading.Event()
        self._thread: threading.Thread | None = None
        self.events: deque = deque(maxlen=1000)
        self._event_id = 0
        self.clients = 0  # connected pages and scripts (operator + viewers)
        self.operator: int | None = None  # client id holding control
        self._next_client = 0
        self._held = False  # controllers' integrators held (e-stop / failsafe)
        self.run_id = 0
        self.snapshot: dict = {}
        self.snapshot_json = "{}"
        self.hello: dict = {}
        self.sim = None
        self._tee = None
        self.error: str | None = None
        self._load(scenario or self.default_scenario())
        self._await_operator = bool(start_on_connect)
        if self._await_operator:
            self.paused = True
            self._publish()

    # -- scenarios -------------------------------------------------------------------------------------
    @staticmethod
    def default_scenario() -> str:
        from ..scenarios.base import registry

        reg = registry()
        return "combined-survey" if "combined-survey" in reg and _builds(reg["combined-survey"]) else "usv-remote"

    @staticmethod
    def live_scenarios() -> list[str]:
        """Scenarios that build one live simulation (they override ``Scenario.build``)."""
        from ..scenarios.base import registry

        return [n for n, s in registry().items() if _builds(s)]

    def _load(self, name: str) -> None:
        """Build a new run of scenario ``name`` (raises ConfigError/InputError; keeps the old run then)."""
        from ..api import new_run_dir, resolve_config
        from ..io.config import dump_toml

        if not hasattr(self, "_override_scenario"):
            self._override_scenario = name  # --set overrides belong to the scenario named at start
        sc, cfg = resolve_config(name, overrides=self.overrides if name == self._override_scenario else None)
        if not _builds(sc):
            from ..errors import InputError

            raise InputError(
                f"scenario {name} has no live simulation; live scenarios: {', '.join(self.live_scenarios())}"
            )
        sim = sc.build(cfg, np.random.default_rng(cfg.sim.seed))
        gate_pilots(sim)
        self._close_run()
        run_dir = None
        writer = None
        if self.write_log:
            run_dir = new_run_dir(self.out_root, f"console-{sc.name}")
            run_dir.mkdir(parents=True, exist_ok=True)
            dump_toml(cfg, run_dir / "config.toml")
            writer = LogWriter(run_dir / "log.parquet", flush_period=cfg.log.flush_period, fsync=cfg.log.fsync)
        with self._lock:
            self.scenario, self.cfg, self.sim = sc, cfg, sim
            self.run_dir = run_dir
            self._tee = _TeeLog(writer)
            self.run_id += 1
            self.mode = str(sim.bus.get("console.mode", "auto"))
            if self.mode not in ("remote", "auto"):
                self.mode = "auto"
            self.loop = str(sim.bus.get("console.loop", "closed"))
            self.estop = False
            self._held = False
            self.failsafe = False
            self.failsafe_reason = ""
            self.paused = False
            self.ended = False
            self.error = None
            self.stick = (0.0, 0.0)
            self.stick_source = "none"
            self.t_stick = -math.inf
            self.gains = collect_gains(sim)
            self.station_keep = bool(getattr(sc, "failsafe_station_keep", False))
            self.tick_s = sim.tick * sim.dt
            self._push_bus()
            sim.run(0.0, log=self._tee)  # fire the blocks at t = 0 (first log row) so their outputs exist
            self.view = infer_view(sc, cfg, sim.bus)
            self.tracks = {b["name"]: deque(maxlen=4000) for b in self.view["bodies"]}
            self._track_t = -math.inf
            self._anchor = (self.clock(), sim.t)
            self._rtf_ref = (self.clock(), sim.t)
            self.rtf = 0.0
            self._lag_events = 0
            self._push_bus()
            self._make_hello()
            self._publish()
        self.event(
            "info",
            f"new run {self.run_id}: scenario {sc.name}" + (f", log {run_dir / 'log.parquet'}" if run_dir else ""),
        )

    def _close_run(self) -> None:
        """Close the current run's log and write its summary."""
        tee = self._tee
        if tee is None or tee.writer is None:
            return
        tee.writer.close()
        try:
            if len(tee) > 1:
                from ..io.logs import read_log

                df = read_log(tee.writer.path)
                s = self.scenario.summarize(df, self.cfg)
                s = {
                    "scenario": self.scenario.name,
                    "source": "console",
                    "duration_s": float(self.sim.t),
                    **{k: _finite(v) if isinstance(v, (float, np.floating)) else v for k, v in s.items()},
                }
                atomic_write_text(tee.writer.path.parent / "summary.json", json.dumps(s, indent=2))
        except Exception as e:  # summary is a convenience; never lose the session over it
            self.event("warning", f"summary not written: {e}")
        tee.writer = None

    # -- events and snapshots --------------------------------------------------------------------------
    def event(self, level: str, text: str) -> None:
        """Record an event for the page's log (level info, warning, error, alarm)."""
        with self._lock:
            self._event_id += 1
            t = float(self.sim.t) if self.sim is not None else 0.0
            self.events.append({"id": self._event_id, "t": t, "level": level, "text": text, "wall": time.time()})

    def events_since(self, last_id: int) -> list[dict]:
        with self._lock:
            return [e for e in self.events if e["id"] > last_id]

    def _make_hello(self) -> None:
        gains = {k: {kk: vv for kk, vv in v.items() if kk not in ("setter", "getter")} for k, v in self.gains.items()}
        self.hello = {
            "type": "hello",
            "run": self.run_id,
            "scenario": self.scenario.name,
            "summary": self.scenario.summary,
            "scenarios": self.live_scenarios(),
            "view": self.view,
            "gains": gains,
            "speed": self.speed,
            "stick_timeout": self.stick_timeout,
            "tick_s": self.tick_s,
            "log_dir": str(self.run_dir) if self.run_dir else None,
            "tracks": {k: [list(p) for p in v] for k, v in self.tracks.items()},
            "station_keep": self.station_keep,
            "loop_switch": bool(getattr(self.scenario, "console_loop_switch", False)),
            "route_edit": bool(getattr(self.scenario, "console_route_edit", False)),
        }

    def hello_message(self) -> dict:
        with self._lock:
            self.hello["tracks"] = {k: [list(p) for p in v] for k, v in self.tracks.items()}
            for k, g in self.hello["gains"].items():
                g["value"] = _finite(self.gains[k]["getter"]())
            return dict(self.hello)

    def _publish(self) -> None:
        """Build the state message from the bus (simulation thread, under the lock)."""
        sim = self.sim
        bus = sim.bus
        sig = {}
        for k, v in bus.items():
            if k.startswith("_") or isinstance(v, (str, bytes)):
                continue
            if isinstance(v, (bool, np.bool_)):
                sig[k] = bool(v)
            elif isinstance(v, (int, float, np.floating, np.integer)):
                sig[k] = _finite(v)
            elif isinstance(v, (list, tuple, np.ndarray)) and k.startswith("cable"):
                try:
                    sig[k] = [_finite(x) for x in np.asarray(v, float).ravel()[:400]]
                except (TypeError, ValueError):
                    pass
        if sim.t - self._track_t >= 0.25:
            self._track_t = sim.t
            for b, tr in self.tracks.items():
                x, y = bus.get(f"{b}.x"), bus.get(f"{b}.y")
                if x is not None and y is not None and math.isfinite(x) and math.isfinite(y):
                    tr.append((round(float(x), 3), round(float(y), 3)))
        now = self.clock()
        age = now - self.t_stick
        self.snapshot = {
            "type": "state",
            "run": self.run_id,
            "t": float(sim.t),
            "mode": self.mode,
            "loop": self.loop,
            "estop": self.estop,
            "failsafe": self.failsafe,
            "failsafe_reason": self.failsafe_reason,
            "paused": self.paused,
            "ended": self.ended,
            "error": self.error,
            "speed": self.speed,
            "rtf": self.rtf,
            "clients": self.clients,
            "operator": self.operator,
            "stick": {
                "surge": self.stick[0],
                "yaw": self.stick[1],
                "source": self.stick_source,
                "age": age if math.isfinite(age) else None,
            },
            "waypoints": [list(p) for p in bus.get("console.waypoints", ())] or None,
            "signals": sig,
            "last_event": self._event_id,
        }
        self.snapshot_json = json.dumps(self.snapshot, separators=(",", ":"))

    def state(self) -> dict:
        with self._lock:
            return json.loads(self.snapshot_json)

    # -- commands (called from the web server's threads) ---------------------------------------------
    def submit(self, msg) -> None:
        """Queue a validated message for the simulation thread; semantic checks raise Rejected."""
        kind = msg.type
        if kind == "gains":
            with self._lock:
                check_gains(msg.gains, self.gains)
        elif kind == "waypoints" and not getattr(self.scenario, "console_route_edit", False):
            raise Rejected(
                f"waypoints: scenario {self.scenario.name} flies a fixed route; "
                f"start a scenario that takes a route from the console (usv-remote)"
            )
        elif kind == "new_run" and msg.scenario is not None and msg.scenario not in self.live_scenarios():
            raise Rejected(
                f"new_run: unknown or non-live scenario {msg.scenario!r}; live scenarios: "
                f"{', '.join(self.live_scenarios())}"
            )
        if kind == "stick":  # timestamp on arrival, so the watchdog sees the link, not the queue
            with self._lock:
                self.t_stick = self.clock()
        self._cmds.append(msg)

    # -- clients and roles ---------------------------------------------------------------------------------
    def attach(self, want_control: bool = True) -> tuple[int, str]:
        """A page or script connected: returns ``(client id, role)``. It becomes the operator when it
        asks for control and nobody holds it; otherwise a viewer (watches, cannot command)."""
        with self._lock:
            self._next_client += 1
            cid = self._next_client
            self.clients += 1
            role = "viewer"
            if want_control and self.operator is None:
                self.operator = cid
                role = "operator"
            first = role == "operator" and self._await_operator
            if first:
                self._await_operator = False
        self.event("info", f"client #{cid} connected as {role} ({self.clients} client(s))")
        if first:
            self._cmds.append(Pause(type="pause", paused=False))
        return cid, role

    def detach(self, cid: int) -> None:
        """A client left; when it was the operator, nobody holds control (remote mode: failsafe)."""
        with self._lock:
            self.clients = max(0, self.clients - 1)
            was_op = self.operator == cid
            if was_op:
                self.operator = None
        if was_op:
            self.event("warning", f"operator #{cid} disconnected ({self.clients} client(s) left); nobody holds control")
        else:
            self.event("info", f"viewer #{cid} disconnected ({self.clients} client(s) left)")

    def take_control(self, cid: int, force: bool = False) -> None:
        """Client ``cid`` asks for control; taking it from another operator needs ``force`` (an
        explicit take-over, logged with both ids). Raises :class:`Rejected` otherwise."""
        with self._lock:
            cur = self.operator
            if cur == cid:
                return
            if cur is not None and not force:
                raise Rejected(f"control: operator #{cur} holds control; send force=true to take it over")
            self.operator = cid
            first = self._await_operator
            self._await_operator = False
        if cur is None:
            self.event("info", f"client #{cid} took control (operator)")
        else:
            self.event("alarm", f"TAKE-OVER: client #{cid} took control from operator #{cur}")
        if first:
            self._cmds.append(Pause(type="pause", paused=False))

    def release_control(self, cid: int) -> None:
        with self._lock:
            if self.operator != cid:
                return
            self.operator = None
        self.event("info", f"operator #{cid} released control")

    def role(self, cid: int) -> str:
        return "operator" if self.operator == cid else "viewer"

    def client_connected(self) -> int:
        """Legacy helper (tests, scripts): attach as operator; returns the client id."""
        cid, _ = self.attach(True)
        if self.operator != cid:
            self.take_control(cid, force=True)
        return cid

    def client_disconnected(self, cid: int | None = None) -> None:
        """Legacy helper: detach ``cid`` (default: the operator)."""
        self.detach(self.operator if cid is None else cid)

    def _apply(self, msg) -> None:
        kind = msg.type
        if kind == "stick":
            self.stick = (float(msg.surge), float(msg.yaw))
            self.stick_source = msg.source
        elif kind == "mode":
            if msg.mode != self.mode:
                self.mode = msg.mode
                self.event("info", f"mode: {msg.mode}")
                if msg.mode == "remote":
                    self.t_stick = max(self.t_stick, self.clock())  # 1 s grace for the first stick message
                    self.stick = (0.0, 0.0)
                elif self.failsafe:
                    self._clear_failsafe("autonomous mode selected")
        elif kind == "loop":
            if msg.loop != self.loop:
                self.loop = msg.loop
                self.event(
                    "info",
                    f"stick drives the {'actuators (open loop)' if msg.loop == 'open' else 'speed and yaw-rate loops (closed loop)'}",
                )
        elif kind == "estop":
            if msg.engaged and not self.estop:
                self.estop = True
                self.event("alarm", "EMERGENCY STOP: all thrust zero (latched until reset)")
            elif not msg.engaged and self.estop:
                self.estop = False
                self.stick = (0.0, 0.0)
                self.event("info", "emergency stop reset")
        elif kind == "gains":
            for name, v in msg.gains.items():
                self.gains[name]["setter"](v)
                self.gains[name]["value"] = v
                self.event("info", f"gain {name} = {v:g} {self.gains[name].get('unit', '')}".rstrip())
        elif kind == "pause":
            if msg.paused != self.paused:
                self.paused = msg.paused
                self._anchor = (self.clock(), self.sim.t)
                self._rtf_ref = self._anchor
                self.event("info", "paused" if msg.paused else "resumed")
        elif kind == "waypoints":
            self.sim.inject({"console.waypoints": tuple((float(a), float(b)) for a, b in msg.points)})
            self.view["route"] = [[float(a), float(b)] for a, b in msg.points]
            self.event("info", f"new route of {len(msg.points)} waypoint(s)")

    def _trip_failsafe(self, reason: str) -> None:
        self.failsafe = True
        self.failsafe_reason = reason
        self.stick = (0.0, 0.0)
        what = "station-keeping" if self.station_keep else "thrust zero"
        self.event("alarm", f"FAILSAFE ({reason}): {what}")

    def _clear_failsafe(self, why: str) -> None:
        self.failsafe = False
        self.failsafe_reason = ""
        self.event("info", f"failsafe cleared: {why}")

    def _watchdog(self, now: float) -> None:
        if self.mode != "remote" or self.paused or self.ended:
            return
        if self.operator is None:
            reason = "operator link lost"
        elif now - self.t_stick > self.stick_timeout:
            reason = f"no stick input for {self.stick_timeout:g} s"
        else:
            reason = ""
        if reason and not self.failsafe:
            self._trip_failsafe(reason)
        elif not reason and self.failsafe:
            if abs(self.stick[0]) <= NEUTRAL and abs(self.stick[1]) <= NEUTRAL:
                self._clear_failsafe("link restored and stick centred")

    def _push_bus(self) -> None:
        """Write the console's keys; the stick only in remote mode (in auto a scenario's own pilot may
        write ``joystick.*``, as the scripted berthing pilot does)."""
        estop_bus = self.estop or (self.failsafe and not self.station_keep)
        vals = {
            "console.mode": self.mode,
            "console.loop": self.loop,
            "_estop": estop_bus,
            "console.failsafe": float(self.failsafe),
            "console.estop": float(self.estop),
        }
        if self.mode == "remote":
            surge, yaw = (0.0, 0.0) if (self.failsafe or self.estop) else self.stick
            vals["joystick.surge"] = surge
            vals["joystick.yaw"] = yaw
        self.sim.inject(vals)

    # -- the loop ------------------------------------------------------------------------------------------
    def step_once(self) -> None:
        """One pass of the pacing loop: apply commands, watchdog, advance to the wall-clock target."""
        now = self.clock()
        with self._lock:
            new_run = None
            while self._cmds:
                msg = self._cmds.popleft()
                if msg.type == "new_run":
                    new_run = msg.scenario or self.scenario.name
                elif not self.ended or msg.type in ("pause",):
                    try:
                        self._apply(msg)
                    except Exception as e:  # a command must never kill the run
                        self.event("error", f"{msg.type} failed: {e}")
        if new_run is not None:
            try:
                self._load(new_run)
            except OceanGNCError as e:
                self.event("error", f"new run refused: {e}")
            except Exception as e:
                self.event("error", f"new run failed: {type(e).__name__}: {e}")
            return
        with self._lock:
            self._watchdog(now)
            was_stopped = bool(self.sim.bus.get("_estop", False))
            self._push_bus()
            sim = self.sim
            if bool(sim.bus["_estop"]) != self._held:
                self._held = bool(sim.bus["_estop"])
                hold_controllers(sim, self._held, ramp_s=self.resume_ramp_s)
            if self.sim.bus["_estop"] and not was_stopped:
                # all thrust to zero at once: fire the blocks now with _estop set, so the actuators'
                # outputs are zero before the next integration step (not one actuator period later)
                for b in sim.blocks:
                    b.step(sim.t, sim.bus)
            if not (self.paused or self.ended):
                w0, s0 = self._anchor
                lag = s0 + self.speed * (now - w0) - sim.t
                if lag > self.max_lag:
                    self._lag_events += 1
                    if self._lag_events in (1, 10, 100) or self._lag_events % 1000 == 0:
                        self.event(
                            "warning",
                            f"simulation fell {lag:.2f} s behind the {self.speed:g}x wall "
                            f"clock (machine busy); it continues from here",
                        )
                    self._anchor = (now, sim.t)
                    lag = self.max_lag
                n = int(math.floor(lag / self.tick_s + 1e-9))
                if n >= 1:
                    try:
                        sim.run(n * self.tick_s, log=self._tee)
                    except DivergenceError as e:
                        self._end(f"simulation diverged: {e}", "error")
                    except Exception as e:
                        traceback.print_exc()
                        self._end(f"simulation failed: {type(e).__name__}: {e}", "error")
                    else:
                        if sim.bus.get("_stop", False):
                            self._end(f"scenario finished at t = {sim.t:.1f} s", "info")
            w_ref, s_ref = self._rtf_ref
            if now - w_ref >= 1.0:
                self.rtf = (sim.t - s_ref) / (now - w_ref) if not self.paused else 0.0
                self._rtf_ref = (now, sim.t)
            self._publish()

    def _end(self, text: str, level: str) -> None:
        self.ended = True
        self.error = text if level == "error" else None
        self.event(level, text + "; start a new run to continue")
        self._close_run()

    def _loop(self) -> None:
        while not self._stop.is_set():
            t0 = self.clock()
            try:
                self.step_once()
            except Exception as e:  # keep the server alive whatever happens
                traceback.print_exc()
                self.event("error", f"console loop error: {type(e).__name__}: {e}")
            dt = self.loop_period - (self.clock() - t0)
            self._stop.wait(max(0.001, dt))

    def start(self) -> None:
        """Start the simulation thread."""
        if self._thread is None:
            with self._lock:
                self._anchor = (self.clock(), self.sim.t)
                self._rtf_ref = self._anchor
            self._thread = threading.Thread(target=self._loop, name="oceangnc-console-sim", daemon=True)
            self._thread.start()

    def stop(self) -> None:
        """Stop the thread and close the log."""
        self._stop.set()
        if self._thread is not None:
            self._thread.join(timeout=10)
            self._thread = None
        with self._lock:
            self._close_run()

    # -- log download -----------------------------------------------------------------------------------
    def log_bytes(self) -> tuple[bytes, str]:
        """The current run's log as Parquet bytes (same format as ``oceangnc run``) and a file name."""
        with self._lock:
            tee = self._tee
            n = len(tee)
            cols = list(tee.columns or [])
            t = tee.t[:n]
            data = {c: tee.data[c][:n] for c in cols}
            name = f"{self.scenario.name}-run{self.run_id}.parquet"
        import pyarrow as pa
        import pyarrow.parquet as pq

        table = pa.table(
            {"t": pa.array(t, type=pa.float64()), **{c: pa.array(data[c], type=pa.float64()) for c in cols}}
        )
        buf = io.BytesIO()
        pq.write_table(table, buf, compression="zstd")
        return buf.getvalue(), name

    # -- warm-up ----------------------------------------------------------------------------------------------
    def warmup(self, seconds: float = 1.0) -> float:
        """Compile and exercise the scenario's code before anyone connects (numba compiles on first
        use: without this the first page would see simulated time frozen for seconds). Runs a
        throwaway copy of the scenario in autonomous then remote mode; returns the wall time taken."""
        t0 = time.perf_counter()
        sc, cfg = self.scenario, self.cfg
        sim = sc.build(cfg, np.random.default_rng(cfg.sim.seed))
        gate_pilots(sim)
        half = max(sim.tick * sim.dt, seconds / 2)
        try:
            sim.inject({"console.mode": "auto", "console.loop": "closed", "_estop": False})
            sim.run(half)
            sim.inject({"console.mode": "remote", "joystick.surge": 0.5, "joystick.yaw": 0.2})
            sim.run(half)
            sim.inject({"_estop": True})
            sim.run(sim.tick * sim.dt)
        except Exception as e:  # a warm-up failure shows up again in the real run, with its message
            self.event("warning", f"warm-up stopped early: {type(e).__name__}: {e}")
        with self._lock:
            self._anchor = (self.clock(), self.sim.t)
            self._rtf_ref = self._anchor
        return time.perf_counter() - t0


def _pids(obj, depth=0, seen=None):
    """PID objects inside a block (attributes, one level of nesting, gated pilots)."""
    from ..control.pid import PID

    seen = set() if seen is None else seen
    if id(obj) in seen or depth > 2:
        return
    seen.add(id(obj))
    for v in list(vars(obj).values()) if hasattr(obj, "__dict__") else []:
        if isinstance(v, PID):
            if id(v) not in seen:
                seen.add(id(v))
                yield v
        elif hasattr(v, "__dict__") and not isinstance(v, type) and type(v).__module__.startswith("oceangnc."):
            yield from _pids(v, depth + 1, seen)


def hold_controllers(sim, on: bool, ramp_s: float = 2.0) -> int:
    """Hold (``on``) or release every PID of the simulation's blocks (see
    :meth:`oceangnc.control.pid.PID.hold`): integrators frozen while stopped, outputs ramped from zero
    over ``ramp_s`` s on release (no thrust step at Reset). Returns how many PIDs."""
    n = 0
    seen: set = set()
    for b in sim.blocks:
        for pid in _pids(b, 0, seen):
            pid.hold(on, ramp_s=ramp_s)
            n += 1
    return n


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


def _builds(sc) -> bool:
    from ..scenarios.base import Scenario

    return type(sc).build is not Scenario.build
