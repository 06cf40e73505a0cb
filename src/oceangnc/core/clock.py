"""The simulation clock: continuous plants integrated at the physics step, discrete blocks at their rates.

The clock owns time (Drake-style). All periods are integer multiples of the physics step ``dt``; the
clock ticks at the greatest common divisor of the block periods and the log period, and at each tick

1. fires, in the listed order, every block whose period divides the tick time (sensors, guidance,
   control, actuators: the order of a microcontroller loop), so a block sees the outputs of the blocks
   before it from the same instant and the plants' state at that instant;
2. logs one row when the log period divides the tick time;
3. integrates every plant over the tick with the inputs held (zero-order hold), in one compiled call
   per plant, and publishes the plants' outputs.

A block may set ``bus["_stop"] = True`` to end the run early (e.g. the last waypoint reached).
"""

from __future__ import annotations

import math
import time
from collections.abc import Sequence

import numpy as np

from ..errors import ConfigError, DivergenceError
from .blocks import Block, Plant
from .signals import check_wiring


def _steps(period: float, dt: float, what: str) -> int:
    k = period / dt
    n = int(round(k))
    if n < 1 or abs(k - n) > 1e-6 * max(1.0, k):
        raise ConfigError(f"{what}: period {period:g} s must be a positive integer multiple of the "
                          f"physics step dt={dt:g} s")
    return n


class Simulation:
    """A multi-rate simulation of plants and discrete blocks sharing one signal bus.

    Parameters
    ----------
    plants : sequence of Plant
        Continuous systems (integrated with RK4 at ``dt``).
    blocks : sequence of Block
        Discrete blocks, fired in this order at their own periods.
    dt : float
        Physics step (s). Refused if above any plant's ``max_dt``.
    log_period : float
        Time between logged rows (s).
    rng : numpy.random.Generator
        Parent generator; each block gets its own child generator, so results do not depend on how
        many random numbers another block draws.
    log_signals : sequence of str, optional
        Bus keys to log (default: every scalar key not starting with ``_``, fixed at the first row).
    external : dict, optional
        Signals written from outside the loop (console, MAVLink, test stimuli) as ``{signal: unit}``;
        they count as producers in the wiring check (:func:`oceangnc.core.signals.check_wiring`),
        which raises :class:`~oceangnc.core.signals.WiringError` naming the block and the signal.
    """

    def __init__(self, plants: Sequence[Plant], blocks: Sequence[Block], dt: float, log_period: float,
                 rng: np.random.Generator | None = None, log_signals: Sequence[str] | None = None,
                 external: dict[str, str] | None = None):
        if not (dt > 0 and math.isfinite(dt)):
            raise ConfigError(f"sim.dt: must be > 0 s, got {dt}")
        self.plants = list(plants)
        self.blocks = list(blocks)
        self.dt = float(dt)
        self.external = dict(external or {})
        for pl in self.plants:
            if pl.max_dt is not None and self.dt > pl.max_dt * (1 + 1e-9):
                raise ConfigError(f"sim.dt: {self.dt:g} s is above the stability limit of '{pl.name}' "
                                  f"({pl.max_dt:.4g} s); allowed range 0 < dt <= {pl.max_dt:.4g}")
        self.signal_units = check_wiring([*self.plants, *self.blocks], self.external)
        self.block_steps = [_steps(b.period, self.dt, f"block '{b.name}'") for b in self.blocks]
        self.log_steps = _steps(log_period, self.dt, "sim.log_rate")
        self.tick = math.gcd(self.log_steps, *self.block_steps) if self.block_steps else self.log_steps
        self.bus: dict = {}
        self.t = 0.0
        self.k = 0  # physics steps taken
        self.log_signals = list(log_signals) if log_signals is not None else None
        rng = rng if rng is not None else np.random.default_rng(0)
        children = rng.spawn(len(self.blocks)) if self.blocks else []
        for b, g in zip(self.blocks, children):
            b.reset(g)
        for pl in self.plants:
            pl.publish(self.bus)
        self.fire_count = [0] * len(self.blocks)
        self._done_k = -1  # last physics step whose blocks fired and row was logged
        #: ``(every_steps, callback(sim))``: called at steps that are multiples of ``every_steps``, after
        #: the blocks fired and the row was logged (checkpoints, :mod:`oceangnc.core.checkpoint`)
        self.checkpoint_hook = None

    def inject(self, values: dict) -> None:
        """Write values onto the bus between runs (console commands, test stimuli)."""
        self.bus.update(values)

    # -- logging helpers --------------------------------------------------------------------------
    def _row(self) -> dict[str, float]:
        if self.log_signals is None:
            scalar = (int, float, bool, np.floating, np.integer)
            self.log_signals = sorted(k for k, v in self.bus.items() if not k.startswith("_") and isinstance(v, scalar))
        return {k: float(self.bus.get(k, np.nan)) for k in self.log_signals}

    def run(self, duration: float, log=None, progress: bool = False, wall_limit: float | None = None) -> float:
        """Run for ``duration`` s of simulated time (or until a block sets ``_stop``).

        ``log`` is an object with ``append(t, row)`` (e.g. :class:`oceangnc.io.logs.LogWriter`).
        Returns the simulated time reached. Raises :class:`DivergenceError` when a plant blows up or a
        block writes a non-finite value; rows logged so far have been handed to ``log``.
        """
        n_end = self.k + int(round(duration / self.dt))
        bar = None
        if progress:
            from tqdm import tqdm

            bar = tqdm(total=round(duration, 3), unit="sim s", delay=2.0, mininterval=0.5, leave=False,
                       desc="compiling")  # numba compiles on the first steps: no rate, no ETA yet
        t_start = self.t
        k_start = self.k
        last_bar = self.t
        t_wall0 = time.perf_counter()
        try:
            while True:
                t = self.k * self.dt
                self.t = t
                fresh = self.k != self._done_k  # a chunked run resumes at a tick already handled
                self._done_k = self.k
                for i, (b, nb) in enumerate(zip(self.blocks, self.block_steps)):
                    if fresh and self.k % nb == 0:
                        b.step(t, self.bus)
                        self.fire_count[i] += 1
                if fresh and log is not None and self.k % self.log_steps == 0:
                    row = self._row()
                    log.append(t, row)
                    bad = [k for k, v in row.items() if not math.isfinite(v) and not k.endswith("_nan_ok")]
                    if bad:
                        src = bad[0].split(".")[0]
                        raise DivergenceError(t, src, {k: row[k] for k in row if k.startswith(src + ".")},
                                              reason=f"non-finite signal {bad[0]}")
                if self.k >= n_end or self.bus.get("_stop", False):
                    break
                if fresh and self.checkpoint_hook is not None and self.k % self.checkpoint_hook[0] == 0 \
                        and self.k > 0:
                    self.checkpoint_hook[1](self)
                n = min(self.tick, n_end - self.k)
                for pl in self.plants:
                    pl.read_inputs(self.bus)
                    pl.advance(t, self.dt, n)
                    pl.publish(self.bus)
                self.k += n
                if bar is not None and bar.desc == "compiling" and self.k > k_start:
                    bar.set_description_str("")
                    bar.reset()  # restart the rate (ETA) clock after compilation
                    last_bar = t_start
                if bar is not None and self.k * self.dt - last_bar >= 0.5:
                    bar.update(round(self.k * self.dt - last_bar, 3))
                    last_bar = self.k * self.dt
                if wall_limit is not None and time.perf_counter() - t_wall0 > wall_limit:
                    break
        finally:
            if bar is not None:
                if self.bus.get("_stop", False):  # ended early: close the bar at 100 % with the reason
                    bar.set_description_str("")
                    bar.n = bar.total
                    bar.set_postfix_str(str(self.bus.get("_stop_reason", f"scenario ended at t = {self.t:.1f} s")))
                    bar.leave = True
                bar.close()
        return self.t
