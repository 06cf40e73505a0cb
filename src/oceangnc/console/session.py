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

Events. The page's event log (``events``, the last 1,000; summaries of refused requests apart in
``access_events``) is also appended, event by event, to ``events.jsonl`` in the run folder
(:class:`oceangnc.core.files.LineAppender`: one ``write`` per line in append mode; alarms and refusal
summaries fsynced).
"""

from __future__ import annotations

import json
import math
import threading
import time
import traceback
from collections import deque
from pathlib import Path

import numpy as np

from ..errors import DivergenceError, OceanGNCError
from ..core.files import LineAppender
from ..io.logs import LogWriter, atomic_write_text
from ..mavlink.live import builds_live as _builds  # one home: live iff the scenario overrides build
from .access import AccessLog
from .clients import ClientsMixin
from .commands import NEUTRAL, CommandsMixin
from ..mavlink.live import gate_pilots
from .controls import collect_gains
from .runlog import _TeeLog, parquet_bytes
from .snapshots import SnapshotMixin, _finite
from .view import infer_view

__all__ = ["NEUTRAL", "Session", "collect_gains", "gate_pilots"]


class Session(ClientsMixin, CommandsMixin, SnapshotMixin):
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
        self.events: deque = deque(maxlen=1000)  # operators' and the run's events
        self.access_events: deque = deque(maxlen=100)  # summaries of refused requests (AccessLog)
        self._events_file: LineAppender | None = None  # the run's events.jsonl
        self._event_id = 0
        self.access = AccessLog(lambda text: self.event("warning", text, access=True))
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
        events_file = None
        if self.write_log:
            run_dir = new_run_dir(self.out_root, f"console-{sc.name}")
            run_dir.mkdir(parents=True, exist_ok=True)
            dump_toml(cfg, run_dir / "config.toml")
            writer = LogWriter.for_run(run_dir, cfg.log)
            events_file = LineAppender(run_dir / "events.jsonl")
        with self._lock:
            self.scenario, self.cfg, self.sim = sc, cfg, sim
            self.run_dir = run_dir
            self._events_file = events_file
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
        """Close the current run's log and write its summary; the pending summary of refused requests
        goes to its ``events.jsonl``, which is closed last."""
        self.access.flush(force=True)
        try:
            self._write_summary()
        finally:
            with self._lock:
                f, self._events_file = self._events_file, None
            if f is not None:
                f.close()

    def _write_summary(self) -> None:
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
                self.access.flush()  # the summary of refused requests, when its interval is over
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
            t, data = self._tee.columns_copy()
            name = f"{self.scenario.name}-run{self.run_id}.parquet"
        return parquet_bytes(t, data), name

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
