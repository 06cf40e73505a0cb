"""A run's summary and plots computed in forked helper processes, overlapping the simulation.

What a user of ``oceangnc run`` waits for is mostly not the simulation (issue 19): importing pandas
(for the scenario's ``summarize``) and matplotlib, and drawing the figures, cost more than a cached
simulation of the flagship. On Linux ``oceangnc run`` calls :func:`start` to fork a helper right
after its first imports; while the parent resolves the config, builds and runs the simulation, the
helper imports pandas (and matplotlib, drawing one small figure so the fonts are loaded) and
resolves the same config. When the log is closed the parent says "go" with the run folder: the
helper reads the log, forks a second drawer, computes the summary metrics and sends them back, and
the two draw the scenario's :meth:`~oceangnc.scenarios.base.Scenario.plot_jobs`, each taking the
next job number from a shared pipe (balanced whatever the figures cost). The files
written, the summary and the returned paths are those of the in-process path; if a helper fails for
any reason the parent recomputes what is missing in-process, so errors surface as before.

A scenario with a light plot module (:data:`oceangnc.scenario_index.LIGHT_PLOTS`: the flagship
family) goes further, through :func:`start_early`: its drawer is forked first thing, before numpy,
pydantic, numba and the models are imported (``import oceangnc`` imports nothing heavy), and imports
only matplotlib, pyarrow and the plot module; with "go" the parent sends
the run folder and its config as plain values (:class:`oceangnc.io.frame.Plain`), and the drawers
read the log as :class:`oceangnc.io.frame.Columns`. Such a scenario's summary is computed in the
parent on columns (``frame = "columns"``), without pandas, and without plots it forks nothing.

The helpers are only used where ``fork`` is safe: Linux, a single Python thread in the parent, and
not disabled with ``OCEANGNC_POSTPROC=inline``. They ignore SIGINT (the parent handles Ctrl-C and
kills them) and end when their pipe closes, so they never outlive a failed run.
"""

from __future__ import annotations

import os
import pickle
import signal
import struct
import sys
import threading
from pathlib import Path

_HEAD = struct.Struct("<Q")


def can_fork() -> bool:
    """Whether forking helpers is safe here (Linux, one Python thread, not disabled by the environment)."""
    return (
        sys.platform.startswith("linux")
        and hasattr(os, "fork")
        and threading.active_count() == 1
        and os.environ.get("OCEANGNC_POSTPROC", "fork") != "inline"
    )


def _send(fd: int, obj) -> None:
    data = pickle.dumps(obj, protocol=pickle.HIGHEST_PROTOCOL)
    view = memoryview(_HEAD.pack(len(data)) + data)
    while view:
        view = view[os.write(fd, view) :]


def _read_exact(fd: int, n: int) -> bytes | None:
    chunks = []
    while n:
        b = os.read(fd, n)
        if not b:
            return None
        chunks.append(b)
        n -= len(b)
    return b"".join(chunks)


def _recv(fd: int):
    """The next message on ``fd``, or None when the other end closed (or sent garbage)."""
    try:
        head = _read_exact(fd, _HEAD.size)
        if head is None:
            return None
        data = _read_exact(fd, _HEAD.unpack(head)[0])
        return None if data is None else pickle.loads(data)
    except (OSError, pickle.UnpicklingError, EOFError, ValueError):
        return None


class PostProcess:
    """Handle on the helper of one run (see the module docstring); made by :func:`start`."""

    def __init__(self, pid: int, go: int, res_a: int, res_b: int, plots: bool, early: bool = False):
        self.pid, self._go, self._res_a, self._res_b, self.want_plots = pid, go, res_a, res_b, plots
        self.early = early  # a drawer of start_early: plots only, the config sent with "go"
        self._closed = False

    def go(self, out_dir: Path, cfg=None) -> None:
        """The log in ``out_dir`` is closed: start the summary and the plots (``cfg``: the run's config,
        which an early drawer gets as plain values)."""
        try:
            _send(self._go, (str(out_dir), cfg.model_dump()) if self.early else str(out_dir))
        except Exception:  # e.g. a plugin's config that does not pickle: the helper must not wait for ever
            try:
                os.close(self._go)  # it reads the end of the pipe, ends, and the parent draws in-process
            except OSError:
                pass

    def summary(self) -> dict | None:
        """The scenario's ``summarize`` metrics from the helper, or None if it failed (or computes none)."""
        if self.early:
            return None
        msg = _recv(self._res_a)
        return msg[1] if isinstance(msg, tuple) and msg[0] == "ok" else None

    def plots(self) -> list[Path] | None:
        """The paths of every plot job's files, in job order, or None if a drawer failed."""
        a = _recv(self._res_a)
        b = _recv(self._res_b)
        if not (isinstance(a, tuple) and isinstance(b, tuple) and a[0] == b[0] == "ok" and a[1] == b[1]):
            return None
        done = {**a[2], **b[2]}
        if sorted(done) != list(range(a[1])):
            return None
        return [Path(p) for i in range(a[1]) for p in done[i]]

    def close(self, kill: bool = False) -> None:
        """Close the pipes and reap the helper (``kill``: end it first, e.g. after a failed run)."""
        if self._closed:
            return
        self._closed = True
        for fd in (self._go, self._res_a, self._res_b):
            try:
                os.close(fd)
            except OSError:
                pass
        if kill:
            try:
                os.kill(self.pid, signal.SIGKILL)
            except OSError:
                pass
        try:
            os.waitpid(self.pid, 0)
        except ChildProcessError:
            pass


def start(resolve, plots: bool) -> PostProcess | None:
    """Fork the helper of a run; None where unsafe or useless.

    ``resolve()`` gives the run's ``(scenario, config)``: the helper calls it after its imports, so the
    command line can fork before its own :func:`~oceangnc.api.resolve_config` (both resolve the same
    arguments, deterministically). Only the command line forks helpers (one run per process): a
    Python program making many runs pays the imports once and is better served in-process.
    """
    if not can_fork() or (not plots and "pandas" in sys.modules):
        return None
    return _fork(_helper, resolve, plots, plots=plots)


def light_plots_for(scenario: str | None, config) -> tuple[str, str] | None:
    """``(scenario, light plot module)`` for a command-line run of ``scenario`` (None: the default
    one), or None: no light module, or a ``--config`` file (which may name another scenario). Such a
    scenario's drawer is :func:`start_early`'s; without plots it needs no helper (its summary reads
    columns); every other scenario's helper is :func:`start`'s."""
    from .scenario_index import DEFAULT_SCENARIO, FALLBACK_SCENARIO, SCENARIO_INDEX, light_plots

    if config is not None:
        return None
    if scenario is None:
        scenario = DEFAULT_SCENARIO if DEFAULT_SCENARIO in SCENARIO_INDEX else FALLBACK_SCENARIO
    module = light_plots(scenario)
    return (scenario, module) if module else None


def start_early(scenario: str, plots_module: str) -> PostProcess | None:
    """Fork the drawer of a scenario with a light plot module (module docstring); None where unsafe."""
    if not can_fork():
        return None
    return _fork(_early_helper, scenario, plots_module, plots=True, early=True)


def _fork(target, *args, plots: bool, early: bool = False) -> PostProcess:
    go_r, go_w = os.pipe()
    a_r, a_w = os.pipe()
    b_r, b_w = os.pipe()
    sys.stdout.flush()
    sys.stderr.flush()
    pid = os.fork()
    if pid == 0:  # the helper
        code = 0
        try:
            for fd in (go_w, a_r, b_r):
                os.close(fd)
            target(go_r, a_w, b_w, *args)
        except BaseException:
            code = 1
        finally:
            os._exit(code)
    for fd in (go_r, a_w, b_w):
        os.close(fd)
    return PostProcess(pid, go_w, a_r, b_r, plots, early=early)


def _early_helper(go: int, res_a: int, res_b: int, scenario: str, plots_module: str) -> None:
    import importlib

    from .io.frame import Plain
    from .io.plots import warm_up

    signal.signal(signal.SIGINT, signal.SIG_IGN)
    warm_up()
    plots = _LightPlots(importlib.import_module(plots_module), scenario)
    from .io.logs import read_table  # noqa: F401  (pyarrow's Parquet reader imported before the log is ready)

    msg = _recv(go)
    if msg is None:  # the run failed or was interrupted
        return
    out_dir = Path(msg[0])
    _draw_both(plots, Plain(msg[1]), out_dir, _read_columns(out_dir), res_a, res_b)


class _LightPlots:
    """A light plot module seen as a scenario's ``plot_jobs``."""

    def __init__(self, module, name: str):
        self.module, self.name = module, name

    def plot_jobs(self, df, cfg, out_dir: Path) -> list:
        return self.module.plot_jobs(self.name, df, cfg, out_dir)


def _helper(go: int, res_a: int, res_b: int, resolve, plots: bool) -> None:
    signal.signal(signal.SIGINT, signal.SIG_IGN)
    import pandas  # noqa: F401  (the point: imported while the parent simulates)

    if plots:
        from .io.plots import warm_up

        warm_up()
    sc, cfg = resolve()
    msg = _recv(go)
    if msg is None:  # the run failed or was interrupted
        return
    out_dir = Path(msg)
    df = _read_df(out_dir)

    def summary() -> None:
        try:
            _send(res_a, ("ok", sc.summarize(df, cfg)))
        except Exception:
            _send(res_a, ("error", None))

    if plots:
        _draw_both(sc, cfg, out_dir, df, res_a, res_b, first=summary)
    else:
        os.close(res_b)
        summary()


_TOKEN = struct.Struct("<I")
_MAX_JOBS = 16_384  # job numbers written at once into a pipe (64 KiB on Linux) before any is read


def _draw_both(sc, cfg, out_dir: Path, df, res_a: int, res_b: int, first=None) -> None:
    """Draw the scenario's plot jobs here and in a second drawer forked here, each reporting on its
    own pipe (``res_a`` here, ``res_b`` there).

    The drawers take the next job number from a shared pipe, so the work is balanced whatever the
    jobs cost (a scenario lists its costliest figure first). ``first`` (the classic helper's summary)
    runs here before this drawer starts taking jobs.
    """
    try:
        jobs = sc.plot_jobs(df, cfg, out_dir)
        if len(jobs) > _MAX_JOBS:
            raise ValueError("too many plot jobs for the job pipe")
        tokens_r, tokens_w = os.pipe()
        os.write(tokens_w, b"".join(_TOKEN.pack(i) for i in range(len(jobs))))
        os.close(tokens_w)
    except Exception:
        jobs, tokens_r = None, -1
    second = os.fork()
    if second == 0:
        try:
            os.close(res_a)
            _send(res_b, _draw_from(tokens_r, jobs))
        finally:
            os._exit(0)
    os.close(res_b)
    if first is not None:
        first()
    _send(res_a, _draw_from(tokens_r, jobs))
    os.waitpid(second, 0)


def _draw_from(tokens: int, jobs) -> tuple:
    """Run jobs by the numbers read from ``tokens`` until it is empty: ``("ok", n_jobs, {job: [path,
    ...]})``, or ``("error",)``. Reads of one token are atomic: every read returns a whole number."""
    if jobs is None:
        return ("error",)
    done: dict[int, list[str]] = {}
    try:
        while b := os.read(tokens, _TOKEN.size):
            i = _TOKEN.unpack(b)[0]
            done[i] = [str(p) for p in jobs[i]()]
    except Exception:
        return ("error",)
    return ("ok", len(jobs), done)


def _read_columns(out_dir: Path):
    from .io.frame import Columns
    from .io.logs import read_table

    return Columns.from_table(read_table(out_dir / "log.parquet"))


def _read_df(out_dir: Path):
    from .io.logs import read_table

    return read_table(out_dir / "log.parquet").to_pandas()


def cancel(post: PostProcess | None, done: bool = False) -> None:
    """Release a run's helper (None: nothing); ``done=False`` (the run failed) kills it first."""
    if post is not None:
        post.close(kill=not done)
