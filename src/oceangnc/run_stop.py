"""What an interrupted ``oceangnc run`` keeps, whatever the phase it was stopped in (issue 41).

Before, SIGTERM during start-up and Ctrl-C after the simulation (while the summary or the plots were
made) printed "summary.json status: interrupted" and wrote no summary.json, or left one saying ok.
:func:`guarded` runs :func:`oceangnc.api.run`'s body with a :class:`Track` of its run folder, and on
``KeyboardInterrupt`` (Ctrl-C, or SIGTERM as :class:`~oceangnc.errors.Terminated`) makes sure that:

* stopped before the run started (its folder and log not ready): no summary, and the message says so;
* a run folder, no summary yet: ``summary.json`` with ``status = "interrupted"`` is written (the log
  closed, its rows counted);
* a summary already written (the run had finished; the plots were being drawn): it is kept, and the
  message says its status.

While the command line's handler is installed, pyarrow's own signal handlers are off for the run
(``pyarrow.enable_signal_handlers(False)``): during a read (the log read back for the summary) they
take SIGINT and SIGTERM from Python's handler, and a helper thread of Arrow's passes the signal on; a
read that ended before that thread did dropped the signal (the stress test saw a SIGTERM lost so).
Our handler then runs when the read returns, which our own log reads do within milliseconds.

The text is put on the exception as ``kept``; the command line prints it. The hard stop of
:mod:`oceangnc.core.interrupts` (a signal that waited for numba compiling) writes the same summary,
without closing the log (its parts are whole files, readable as they are).
"""

from __future__ import annotations

import functools
import json
import sys
import time
from pathlib import Path

from .errors import Terminated


class Track:
    """The run folder of one run, its log writer and the status of the summary written (None: none)."""

    def __init__(self):
        self.out_dir: Path | None = None
        self.log = None
        self.scenario = ""
        self.status: str | None = None
        self.t0 = time.perf_counter()

    def folder(self, out_dir: Path, log, scenario: str) -> None:
        """The run folder is made and its log open."""
        self.out_dir, self.log, self.scenario = Path(out_dir), log, scenario

    def _write(self, signum_name: str, phase: str) -> str:
        from .core.files import atomic_write_text

        assert self.out_dir is not None

        rows = int(getattr(self.log, "rows_written", 0))
        summary = {
            "scenario": self.scenario,
            "status": "interrupted",
            "signal": signum_name,
            "phase": phase,
            "rows": rows,
            "wall_time_s": time.perf_counter() - self.t0,
        }
        atomic_write_text(self.out_dir / "summary.json", json.dumps(summary, indent=2))
        self.status = "interrupted"
        return f"summary.json status: interrupted in {self.out_dir} ({rows} log rows kept)"

    def after_interrupt(self, e: BaseException) -> str:
        """Write what is missing after ``e`` and say what was kept (module docstring)."""
        if self.out_dir is None:
            return "no summary written: stopped before the run started"
        if self.status == "interrupted":
            rows = int(getattr(self.log, "rows_written", 0))
            return f"summary.json status: interrupted in {self.out_dir} ({rows} log rows kept)"
        if self.status is not None:
            done = f"summary.json status {self.status} in {self.out_dir}"
            return f"the run had finished: {done}; the plots are not all drawn"
        if self.log is not None:
            try:
                self.log.close()
            except Exception:  # noqa: BLE001  (the summary below still says how many rows are in visible parts)
                pass
        return self._write("SIGTERM" if isinstance(e, Terminated) else "SIGINT", "start-up or summary")

    def hard_stop(self, signum: int) -> str:
        """The hard stop's summary (the process ends right after): written unless one exists."""
        import signal

        if self.out_dir is None:
            return ""
        if self.status is not None:
            return f"summary.json status {self.status} kept in {self.out_dir}"
        return self._write(signal.Signals(signum).name, "compiling")


def guarded(fn):
    """Wrap :func:`oceangnc.api.run`'s body ``fn`` (which takes ``_track``) as described above."""

    @functools.wraps(fn)
    def run(*args, **kwargs):
        from .core import interrupts

        track = Track()
        interrupts.on_hard_stop(track.hard_stop)
        quiet = interrupts.installed() and "pyarrow" in sys.modules
        if quiet:  # pyarrow's own SIGINT/SIGTERM handlers during a read lose a signal (module docstring)
            sys.modules["pyarrow"].enable_signal_handlers(False)
        try:
            return fn(*args, _track=track, **kwargs)
        except KeyboardInterrupt as e:
            try:
                e.kept = track.after_interrupt(e)  # type: ignore[attr-defined]
            except OSError as err:
                e.kept = f"summary.json could not be written ({err.strerror or err})"  # type: ignore[attr-defined]
            raise
        finally:
            interrupts.on_hard_stop(None)
            if quiet:
                sys.modules["pyarrow"].enable_signal_handlers(True)

    return run
