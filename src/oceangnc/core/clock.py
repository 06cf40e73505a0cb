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

**Fused path** (issue 19): with ``use_fused = True`` (what :func:`oceangnc.run` and the sweeps
set) and a compiled form for every block and plant, the ticks run in one compiled driver per call
(:mod:`oceangnc.core.fused`), many ticks at a time, the log buffered in row blocks. The driver runs
the first tick too when the declarations fix the signals and log columns
(:func:`oceangnc.core.fused.first_tick_plan`) and no child process is compiling ahead; otherwise the
first tick runs here in Python. Without a compiled form (or with a checkpoint hook) the Python loop
runs; ``verbose = True`` says once which path runs and why.
"""

from __future__ import annotations

import math
import time
from collections.abc import Sequence
from typing import Any

import numpy as np

from ..errors import ConfigError, DivergenceError
from . import compile_note
from .blocks import Block, Plant
from .signals import WiringError, check_wiring

#: wall time of one call of the fused driver (s): a signal is handled between two calls (issue 41)
CALL_S = 0.1
#: the most physics steps between two ticks of the clock (block firings, log rows): the plants advance them in
#: one compiled call, which a signal cannot interrupt (2e4 steps: 0.01 s of the fastest vehicle, 0.5 s of a
#: plant 40 times slower; a tick is 10-50 steps at the default dt)
MAX_TICK_STEPS = 20_000


def _steps(period: float, dt: float, what: str) -> int:
    k = period / dt
    n = int(round(k))
    if n < 1 or abs(k - n) > 1e-6 * max(1.0, k):
        divisors = "" if period <= 0 else f"; allowed sim.dt here: {period:g} s divided by a whole number"
        raise ConfigError(
            f"config error: sim.dt = {dt:g}: {what} runs every {period:g} s, which must be a whole number of "
            f"physics steps{divisors}"
        )
    return n


def ahead_jobs(plants: Sequence[Plant], blocks: Sequence[Block], publish: bool = False) -> list[tuple]:
    """What a child compiles ahead (:func:`oceangnc.core.caches.compile_ahead`) for a simulation of these
    plants and blocks: each plant's stepper (which the fused driver alone calls, last), its output
    function (``publish``: when the child starts before the simulation publishes; it shares the cable's
    kernels with the stepper, which the child then compiled already), then the blocks' laws from the
    *last* block, so that this process, running the first tick from the first block, meets the child's
    laws only at the end."""
    jobs: list[tuple] = []
    for pl in plants:
        try:
            jobs += pl.compile_jobs()
        except AttributeError:  # a plant without the base class's stepper
            pass
    for pl in plants:
        jobs += pl.publish_jobs() if publish and hasattr(pl, "publish_jobs") else []
    for b in reversed(blocks):
        jobs += getattr(b, "compile_jobs", list)()
    return jobs


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

    def __init__(
        self,
        plants: Sequence[Plant],
        blocks: Sequence[Block],
        dt: float,
        log_period: float,
        rng: np.random.Generator | None = None,
        log_signals: Sequence[str] | None = None,
        external: dict[str, str] | None = None,
    ):
        if not (dt > 0 and math.isfinite(dt)):
            raise ConfigError(f"sim.dt: must be > 0 s, got {dt}")
        self.plants = list(plants)
        self.blocks = list(blocks)
        self.dt = float(dt)
        self.external = dict(external or {})
        for pl in self.plants:
            if pl.max_dt is not None and self.dt > pl.max_dt * (1 + 1e-9):
                raise ConfigError(
                    f"sim.dt: {self.dt:g} s is above the stability limit of '{pl.name}' "
                    f"({pl.max_dt:.4g} s); allowed range 0 < dt <= {pl.max_dt:.4g}"
                )
        self.signal_units = check_wiring([*self.plants, *self.blocks], self.external)
        self.block_steps = [_steps(b.period, self.dt, f"block '{b.name}'") for b in self.blocks]
        self.log_steps = _steps(log_period, self.dt, "sim.log_rate")
        self.tick = math.gcd(self.log_steps, *self.block_steps) if self.block_steps else self.log_steps
        if self.tick > MAX_TICK_STEPS:
            raise ConfigError(
                f"sim.dt = {self.dt:g} s: {self.tick} physics steps between two block firings or log rows "
                f"({self.tick * self.dt:g} s), more than {MAX_TICK_STEPS}: the loop could not stop within a "
                "second on a signal; raise sim.dt (or sim.log_rate)"
            )
        self.bus: dict = {}
        self._injected: set[str] = set()  # keys written by inject(): front ends' inputs
        self.t = 0.0
        self.k = 0  # physics steps taken
        self.log_signals = list(log_signals) if log_signals is not None else None
        rng = rng if rng is not None else np.random.default_rng(0)
        children = rng.spawn(len(self.blocks)) if self.blocks else []
        for b, g in zip(self.blocks, children):
            b.reset(g)
        self._ahead = self._start_ahead()
        for pl in self.plants:
            pl.publish(self.bus)
        self.fire_count = [0] * len(self.blocks)
        self._done_k = -1  # last physics step whose blocks fired and row was logged
        #: ``(every_steps, callback(sim))``: called at steps that are multiples of ``every_steps``, after
        #: the blocks fired and the row was logged (checkpoints, :mod:`oceangnc.core.checkpoint`)
        self.checkpoint_hook = None
        self.use_fused = False  # set by oceangnc.run / sweeps: run the compiled fused loop when possible
        self.verbose = False
        self._fused: Any = None  # FusedLoop, or the reason string why not, once decided
        self.path = "python"

    def _start_ahead(self) -> list:
        """The children compiling the plants' functions (:func:`oceangnc.core.caches.compile_ahead`): those
        the plants' builders started, else one for every plant's stepper, forked now so that it compiles
        while this process publishes and runs the blocks' first tick (a first run, under ``oceangnc run``)."""
        started = [pl.ahead for pl in self.plants if getattr(pl, "ahead", None) is not None]
        if started or not self.plants:
            return started
        from .caches import compile_ahead

        child = compile_ahead(ahead_jobs(self.plants, self.blocks))
        return [child] if child is not None else []

    def _wait_ahead(self) -> None:
        """Wait for :meth:`_start_ahead`'s children (before a plant is advanced or the fused loop built)."""
        while self._ahead:
            self._ahead.pop().wait()

    def inject(self, values: dict) -> None:
        """Write values onto the bus between runs (console commands, test stimuli); logged like the
        declared external inputs when they are numbers."""
        self.bus.update(values)
        self._injected.update(values)

    # -- logging helpers --------------------------------------------------------------------------
    def _row(self) -> dict[str, float]:
        if self.log_signals is None:
            self.log_signals = self._log_schema()
        return {k: float(self.bus.get(k, np.nan)) for k in self.log_signals}

    def _log_schema(self) -> list[str]:
        """The log's columns, after the first tick: the declared outputs of every plant and block (their
        number units; internal ``_`` signals and strings are not logged) and the external inputs a
        front end has written (declared, or injected by :meth:`inject`). A scalar on the bus that
        nothing declares is a wiring error. With an undeclared part (``outputs = None``), the bus at
        the first tick decides."""
        scalar = (int, float, bool, np.floating, np.integer)
        on_bus = {k for k, v in self.bus.items() if not k.startswith("_") and isinstance(v, scalar)}
        if any(getattr(p, "outputs", None) is None for p in [*self.plants, *self.blocks]):
            return sorted(on_bus)
        declared = {
            k
            for k, unit in self.signal_units.items()
            if not k.startswith("_") and unit != "str" and (k not in self.external or k in on_bus)
        } | (self._injected & on_bus)
        stray = sorted(on_bus - declared)
        if stray:
            raise WiringError(
                f"signal '{stray[0]}' is on the bus after the first tick but no block or plant declares it "
                "as an output (declare it, or as an external input)"
            )
        return sorted(declared)

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

            # shown at once as "compiling" (numba compiles on the first step: no rate, no ETA yet)
            bar = tqdm(
                total=round(duration, 3),
                unit="sim s",
                mininterval=0.5,
                leave=False,
                desc="compiling",
                bar_format=compile_note.FORMAT,  # no empty bar before the first step (core/compile_note.py)
            )
            compile_note.ahead_note(bar, self._ahead)  # what the children compile (a first run only)
        self._t_start, self._k_start, self._last_bar = self.t, self.k, self.t
        t_wall0 = time.perf_counter()
        try:
            if self.use_fused and self.checkpoint_hook is None:
                if self._done_k < 0 and self._fused is None and not self._ahead:
                    # the declarations fix the first tick's signals: the driver runs it, and no law is
                    # loaded on its own (with a child compiling ahead, this process runs the first tick
                    # in Python meanwhile)
                    from .fused import first_tick_plan

                    plan = first_tick_plan(self)
                    if plan is not None:
                        self._decide_fused(plan)
                if self._done_k < 0 and self._fused is None:  # the first tick in Python: it fixes the signals
                    self._run_python(n_end, log, bar, wall_limit, t_wall0, max_ticks=1)
                if self._fused is None:
                    self._wait_ahead()  # the plants' compiled functions, before the driver that calls them
                    self._decide_fused()
                if not isinstance(self._fused, str):
                    compile_note.driver_note(bar, self, self._fused)
                    self._run_fused(n_end, log, bar, wall_limit, t_wall0)
                    return self.t
            self._run_python(n_end, log, bar, wall_limit, t_wall0)
        finally:
            if bar is not None:
                if self.bus.get("_stop", False):  # ended early: close the bar at 100 % with the reason
                    bar.set_description_str("")
                    bar.total = bar.n = round(self.t - self._t_start, 3)  # counts to where it ended
                    bar.set_postfix_str(str(self.bus.get("_stop_reason", f"scenario ended at t = {self.t:.1f} s")))
                    bar.leave = True
                bar.close()
        return self.t

    def _decide_fused(self, plan=None) -> None:
        import sys

        from .fused import build_fused

        fused, why = build_fused(self, plan)
        self._fused = fused if fused is not None else why
        self.path = "fused" if fused is not None else "python"
        if self.verbose:
            msg = (
                f"fused compiled loop ({len(self.blocks)} blocks, {len(self.plants)} plant(s))"
                if fused is not None
                else f"Python clock: {why}"
            )
            print(f"oceangnc: {msg}", file=sys.stderr)

    def _run_fused(self, n_end, log, bar, wall_limit, t_wall0) -> None:
        fz = self._fused
        fz.from_bus(self.bus)
        log_on = log is not None
        if log_on:
            if self.log_signals is None:
                self._row()
            if getattr(fz, "log_signals", None) != self.log_signals:
                fz.set_log(self.log_signals)
        elif fz.log_slots is None:
            fz.set_log([])
        if not hasattr(fz, "buf") or fz.buf.shape[1] != len(fz.log_slots) + 1:
            fz.buf = np.empty((2000, len(fz.log_slots) + 1))
        # chunk so that a progress bar, a wall-clock limit and a signal are honoured: the driver returns to
        # Python after about CALL_S of wall time (issue 41: a SIGINT/SIGTERM is handled between two calls);
        # the first call runs a few ticks, each next one as many as the last rate gives in CALL_S
        cap = 1 << 62
        flush = getattr(log, "flush_period", None) if log_on else None
        if flush:  # crash safety: hand the log its rows at least once per flush period of simulated time
            cap = max(1, int(flush / (self.tick * self.dt) + 1e-9))
        max_ticks = min(cap, 16)
        args = [fz.args[a] for a in fz.arg_names]
        # the first tick, when the driver runs it, with its own slots for the optional inputs (FirstTick)
        first = fz.first_args if self._done_k < 0 else None
        while True:
            call_args = args if first is None else [first[a] for a in fz.arg_names]
            k_call, w_call = self.k, time.perf_counter()
            k, done_k, rows, status, info, t_new = fz.drive(
                self.k,
                self._done_k,
                n_end,
                self.tick,
                self.dt,
                fz.sig,
                fz.stop_slot,
                log_on,
                self.log_steps,
                fz.log_slots,
                fz.nan_ok,
                fz.buf,
                max_ticks if first is None else 1,
                fz.nbs,
                *call_args,
            )
            first = None
            took = time.perf_counter() - w_call
            ticks_done = max(1, (int(k) - k_call) // self.tick)
            max_ticks = int(min(cap, max(1, ticks_done * min(CALL_S / max(took, 1e-6), 8.0))))
            if self._done_k < 0 <= done_k:  # the driver ran the first tick: every block fired
                self.fire_count = [n + 1 for n in self.fire_count]
            self.k, self._done_k = int(k), int(done_k)
            self.t = self._done_k * self.dt if self._done_k >= 0 else self.k * self.dt
            if rows and log_on:
                log.append_rows(fz.buf[:rows, 0], fz.log_signals, fz.buf[:rows, 1:])
            if status in (2, 3):
                raise self._fused_error(int(status), int(info), float(t_new))
            if self.k > self._k_start and compile_note.done(bar):
                bar.reset()
                self._last_bar = self._t_start
            if bar is not None and self.k * self.dt - self._last_bar >= 0.5:
                bar.update(round(self.k * self.dt - self._last_bar, 3))
                self._last_bar = self.k * self.dt
            if status == 0:
                break
            if status == 4 and wall_limit is not None and time.perf_counter() - t_wall0 > wall_limit:
                break
        fz.to_bus(self.bus)
        self.t = self.k * self.dt

    def _fused_error(self, status: int, info: int, t_new: float) -> DivergenceError:
        """The DivergenceError the Python path raises, for a fused driver's status 2 (bad logged
        signal, ``info`` its column) or 3 (plant ``info`` diverged, ``t_new`` its stepper's return)."""
        fz = self._fused
        fz.to_bus(self.bus)
        if status == 2:
            row = self._row()
            bad = fz.log_signals[info]
            src = bad.split(".")[0]
            return DivergenceError(
                self.t, src, {c: row[c] for c in row if c.startswith(src + ".")}, reason=f"non-finite signal {bad}"
            )
        pl = self.plants[info]
        kk = int(-t_new - 1.0)
        finite = bool(np.all(np.isfinite(pl.x)))
        return DivergenceError(
            self.k * self.dt + (kk + 1) * self.dt,
            pl.name,
            pl.state_dict(),
            reason=f"|state| above {pl.state_bound:g}" if finite else "non-finite state",
        )

    def _run_python(self, n_end, log, bar, wall_limit, t_wall0, max_ticks: int | None = None) -> None:
        ticks = 0
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
                    raise DivergenceError(
                        t,
                        src,
                        {k: row[k] for k in row if k.startswith(src + ".")},
                        reason=f"non-finite signal {bad[0]}",
                    )
            if self.k >= n_end or self.bus.get("_stop", False):
                break
            ticks += fresh
            if max_ticks is not None and ticks >= max_ticks:
                break
            if fresh and self.checkpoint_hook is not None and self.k % self.checkpoint_hook[0] == 0 and self.k > 0:
                self.checkpoint_hook[1](self)
            n = min(self.tick, n_end - self.k)
            if self._ahead:
                self._wait_ahead()
            for pl in self.plants:
                pl.read_inputs(self.bus)
                pl.advance(t, self.dt, n)
                pl.publish(self.bus)
            self.k += n
            if self.k > self._k_start and compile_note.done(bar):
                bar.reset()  # restart the rate (ETA) clock after compilation
                self._last_bar = self._t_start
            if bar is not None and self.k * self.dt - self._last_bar >= 0.5:
                bar.update(round(self.k * self.dt - self._last_bar, 3))
                self._last_bar = self.k * self.dt
            if wall_limit is not None and time.perf_counter() - t_wall0 > wall_limit:
                break
