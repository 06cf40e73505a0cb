"""A scenario's closed loop as a Gymnasium environment (issue 44): :class:`ScenarioEnv`.

The scenario is built the usual way (:meth:`oceangnc.scenarios.base.Scenario.build`); the task drops the
blocks the agent replaces (the controller and the thrust allocation) and declares what it writes instead
(the thruster commands, the current) as external inputs of a new :class:`~oceangnc.core.clock.Simulation`
over the same plant and the remaining blocks (guidance, environment). That simulation runs on the fused
compiled loop (:mod:`oceangnc.core.fused`): one call of its driver per environment step advances every
physics step and block firing of the control period in compiled code; the action is written into, and
the observation read from, the driver's signal array by slot (:class:`SignalView`).

Reset does not rebuild anything: :class:`LoopSnapshot` keeps a copy of every array of the fused loop
(the signal array, the blocks' states, the plant's state) taken before the first tick, and puts it back
in place; the task then writes the episode's initial state and inputs, and the first tick runs. An
episode is therefore a function of the seed alone (``reset(seed=s)`` twice gives the same trajectory).
"""

from __future__ import annotations

from typing import Any

import gymnasium
import numpy as np

from ..core.clock import Simulation
from ..core.fused import first_tick_plan
from ..errors import ConfigError, DivergenceError


class LoopSnapshot:
    """The fused loop of ``sim`` before its first tick, to be restored at every reset.

    Holds copies of the signal array, of every array argument of the driver (blocks' states and
    parameters, the plants' states and inputs) and the bit-generator state of every block's generator;
    :meth:`restore` writes them back in place (the driver holds references to these very arrays)."""

    def __init__(self, sim: Simulation):
        sim.use_fused = True
        sim._wait_ahead()  # children compiling ahead (only under oceangnc.core.caches.ahead_of_time)
        sim._decide_fused(first_tick_plan(sim))
        fz = sim._fused
        if isinstance(fz, str):
            raise ConfigError(f"rl: the environment needs the fused compiled loop, which this scenario lacks: {fz}")
        fz.set_log([])
        self.sim, self.fz = sim, fz
        self.sig = fz.sig.copy()
        self.arrays = {k: v.copy() for k, v in fz.args.items() if isinstance(v, np.ndarray)}
        self.gens = [v for v in fz.args.values() if isinstance(v, np.random.Generator)]
        self.bus = dict(sim.bus)
        self.args = [fz.args[a] for a in fz.arg_names]
        self.buf = np.empty((1, len(fz.log_slots) + 1))
        self.signals = SignalView(fz)

    def advance(self, n: int) -> None:
        """``n`` physics steps from where the loop is, in one call of the fused driver, the signal array
        left as the driver leaves it (what :meth:`Simulation.run` does between its copies from and to the
        bus dict, which cost more than the driver here). Raises the clock's DivergenceError."""
        sim, fz = self.sim, self.fz
        k, done_k, _, status, info, t_new = fz.drive(
            sim.k, sim._done_k, sim.k + n, sim.tick, sim.dt, fz.sig, fz.stop_slot, False, sim.log_steps,
            fz.log_slots, fz.nan_ok, self.buf, 1 << 62, fz.nbs, *self.args,
        )  # fmt: skip
        sim.k, sim._done_k = int(k), int(done_k)
        sim.t = sim.k * sim.dt
        if status in (2, 3):
            raise sim._fused_error(int(status), int(info), float(t_new))

    def restore(self, rng: np.random.Generator) -> None:
        """Back to the state before the first tick; each block's generator restarts from a child of ``rng``."""
        sim, fz = self.sim, self.fz
        fz.sig[:] = self.sig
        for k, v in self.arrays.items():
            fz.args[k][...] = v
        for g, child in zip(self.gens, rng.spawn(len(self.gens)) if self.gens else []):
            g.bit_generator.state = child.bit_generator.state  # both PCG64 (numpy's default_rng and its spawn)
        sim.bus = dict(self.bus)
        sim.k, sim._done_k, sim.t = 0, -1, 0.0
        sim.fire_count = [0] * len(sim.blocks)


class SignalView:
    """The fused loop's signals by name, read from its signal array (``view["vehicle.u"]``, ``view.get``)."""

    def __init__(self, fz):
        self.sig, self.slot = fz.sig, fz.slot

    def __getitem__(self, name: str) -> float:
        return float(self.sig[self.slot[name]])

    def get(self, name: str, default=None):
        i = self.slot.get(name)
        return default if i is None else float(self.sig[i])

    def write(self, values: dict) -> None:
        for k, v in values.items():
            self.sig[self.slot[k]] = v


class ScenarioEnv(gymnasium.Env):
    """A :class:`gymnasium.Env` over a scenario's plant and blocks, driven by a task (:mod:`oceangnc.rl.tasks`).

    ``step(action)``: the task maps the action in [-1, 1] to the plant's declared inputs (thrust
    commands, N), the clock runs one control period (``task.params.control_period`` s) in one compiled
    call, and the task computes the observation, the reward and the termination from the bus. The
    episode is truncated at ``task.params.time_limit`` s. ``info`` carries ``t`` (s) and, at a
    termination, ``reason``.
    """

    metadata = {"render_modes": []}

    def __init__(self, task, sim: Simulation, seed: int | None = None):
        super().__init__()
        self.task = task
        self.sim = sim
        self.period = task.params.control_period  # a whole number of sim.dt (checked by oceangnc.rl.make)
        self._first_seed = seed
        self.action_space = task.action_space
        self.observation_space = task.observation_space
        self._snap = LoopSnapshot(sim)
        self._steps = int(round(self.period / sim.dt))
        #: the loop's signals by name (read-only use; the clock's bus dict is not updated between resets)
        self.signals = self._snap.signals
        self._ended = True

    def reset(self, *, seed: int | None = None, options: dict | None = None) -> tuple[np.ndarray, dict]:
        """A new episode: the initial state and inputs drawn by the task from ``self.np_random``."""
        if seed is None and self._first_seed is not None:
            seed, self._first_seed = self._first_seed, None
        super().reset(seed=seed)
        self._snap.restore(self.np_random)
        self.task.start(self.sim, self.np_random)
        self.sim.run(0.0)  # the first tick: every block fires at t = 0
        self._ended = False
        return self.task.observe(self.signals), {"t": 0.0}

    def step(self, action) -> tuple[np.ndarray, float, bool, bool, dict[str, Any]]:
        if self._ended:
            raise RuntimeError("rl: step() after the episode ended; call reset() first")
        a = np.clip(np.asarray(action, dtype=np.float64).reshape(self.action_space.shape), -1.0, 1.0)
        bus = self.signals
        bus.write(self.task.act(a))
        info: dict[str, Any] = {}
        diverged = False
        try:
            self._snap.advance(self._steps)
        except DivergenceError:  # reported as a termination named "diverged"
            diverged = True
        info["t"] = t = self.sim.k * self.sim.dt
        obs = self.task.observe(bus)
        reward, reason = self.task.reward(bus, a)
        if diverged:
            reason = "diverged"
        elif reason is None and bus.get("_stop", False):
            reason = self.task.stop_reason
        terminated = reason is not None
        if terminated:
            reward -= self.task.params.end_penalty if reason != self.task.stop_reason else 0.0
            info["reason"] = reason
        truncated = not terminated and t >= self.task.params.time_limit - 0.5 * self.sim.dt
        self._ended = terminated or truncated
        return obs, float(reward), terminated, truncated, info
