"""The Python API: ``oceangnc.run(scenario, overrides=..., duration=...)``; the CLI is a thin layer on it."""

from __future__ import annotations

import datetime as _dt
import json
import math
import os
import time
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np

from . import postproc, run_stop
from .errors import DivergenceError
from .io.config import deep_merge, dump_toml, load_toml, to_dict, validate
from .io.logs import LogWriter, atomic_write_text, read_table, remove_log
from .scenario_index import DEFAULT_SCENARIO, FALLBACK_SCENARIO  # noqa: F401  (re-exported)
from .scenarios.base import RunContext, get_scenario, scenario_summaries


@dataclass
class RunResult:
    """What :func:`run` returns.

    Attributes
    ----------
    log : pyarrow.Table
        The run's log (one row per sample, time column ``t`` in s). ``df`` gives it as pandas.
    summary : dict
        The scenario's metrics (flat keys, SI units) plus ``scenario`` and ``duration_s``.
    config : pydantic model
        The fully resolved config.
    out_dir : Path
        Folder holding ``log.parquet``, ``summary.json``, ``config.toml`` and the plots.
    plots : list of Path
    """

    log: Any
    summary: dict
    config: Any
    out_dir: Path
    plots: list

    @property
    def df(self):
        """The log as a pandas DataFrame."""
        return self.log.to_pandas()


def default_scenario() -> str:
    """The flagship scenario if it exists, else the USV turn."""
    return DEFAULT_SCENARIO if DEFAULT_SCENARIO in scenario_summaries() else FALLBACK_SCENARIO


def list_scenarios() -> dict[str, str]:
    """Scenario name -> one-line description."""
    return scenario_summaries()


def resolve_config(
    scenario: str | None = None,
    config: str | Path | dict | None = None,
    overrides: dict | None = None,
    duration: float | None = None,
):
    """Build and validate a scenario's config from defaults, a TOML file/dict and overrides.

    ``overrides`` may be nested or use dotted keys (``{"environment.current.speed": 0.5}``).
    The environment variable ``OCEANGNC_MAX_DURATION`` (s), if set, caps ``sim.duration`` (smoke
    runs of the examples in the test suite).
    Returns ``(scenario_object, config_model)``.
    """
    from .io.config import set_dotted

    file_cfg: dict = {}
    if isinstance(config, (str, Path)):
        file_cfg = load_toml(config)
    elif isinstance(config, dict):
        file_cfg = config
    name = scenario or file_cfg.get("scenario") or default_scenario()
    sc = get_scenario(name)
    over: dict = {}
    for k, v in (overrides or {}).items():
        if isinstance(v, dict):  # a section, possibly under a dotted key: merged into what is there
            nested: dict = {}
            set_dotted(nested, k, v)
            over = deep_merge(over, nested)
        else:
            set_dotted(over, k, v)
    if duration is not None:
        set_dotted(over, "sim.duration", duration)
    data = deep_merge(deep_merge(sc.defaults, file_cfg), over)
    data["scenario"] = sc.name
    cfg = validate(sc.Config, data)
    cap = os.environ.get("OCEANGNC_MAX_DURATION")
    if cap:  # smoke runs of the examples and docs (tests/test_examples.py): every run made short
        cfg.sim.duration = min(cfg.sim.duration, float(cap))
    return sc, cfg


def resolve_run_config(scenario=None, config=None, overrides=None, duration=None, model=None):
    """:func:`resolve_config` with an identified model file's parameters under ``overrides`` (as :func:`run`)."""
    if model is not None:
        from .identification.model_file import load_model_overrides

        overrides = {**load_model_overrides(model), **dict(overrides or {})}
    return resolve_config(scenario, config, overrides, duration)


def new_run_dir(root: str | Path = "runs", name: str = "run") -> Path:
    """A new, unique folder ``runs/<name>-<timestamp>``."""
    stamp = _dt.datetime.now().strftime("%Y%m%d-%H%M%S")
    base = Path(root) / f"{name}-{stamp}"
    out = base
    i = 1
    while out.exists():
        out = Path(f"{base}-{i}")
        i += 1
    return out


def _prepare_out_dir(out_dir: Path, overwrite: bool) -> bool:
    """Create the run folder (True when it is new). An existing run folder needs ``overwrite``; a path
    that is a file, cannot be created or is too long is a one-line InputError."""
    from .errors import InputError

    try:
        if out_dir.exists() and not out_dir.is_dir():
            raise InputError(f"--out {out_dir}: exists and is not a folder")
        if out_dir.is_dir():
            holds_run = any((out_dir / f).exists() for f in ("summary.json", "log.parquet", "config.toml"))
            if holds_run and not overwrite:
                raise InputError(
                    f"--out {out_dir}: holds a run already; give --overwrite to replace it, or a new folder"
                )
            return False
        out_dir.mkdir(parents=True)
    except OSError as e:
        raise InputError(f"--out {out_dir}: cannot create the folder ({e.strerror or e})") from None
    return True


def _jsonable(v):
    if isinstance(v, (np.floating, float)):
        v = float(v)
        return v if math.isfinite(v) else None
    if isinstance(v, (np.integer,)):
        return int(v)
    if isinstance(v, (np.bool_,)):
        return bool(v)
    return v


def run(
    scenario: str | None = None,
    overrides: dict | None = None,
    duration: float | None = None,
    config: str | Path | dict | None = None,
    out: str | Path | None = None,
    plots: bool = True,
    progress: bool = False,
    verbose: bool = False,
    checkpoint_every: float | None = None,
    resume: str | Path | None = None,
    model: str | Path | None = None,
    overwrite: bool = False,
    _post: postproc.PostProcess | None = None,
    _track: run_stop.Track | None = None,
) -> RunResult:
    """Run a scenario and write its outputs.

    Parameters
    ----------
    scenario : str, optional
        Scenario name (see :func:`list_scenarios`); default the flagship ``combined-survey``.
    overrides : dict, optional
        Config overrides, nested or with dotted keys, e.g. ``{"environment.current.speed": 0.5}``.
    duration : float, optional
        Simulated time (s); shorthand for ``sim.duration``.
    config : path or dict, optional
        A TOML file (or dict) merged over the scenario's defaults before the overrides.
    out : path, optional
        Output folder (default a new ``runs/<scenario>-<timestamp>``).
    plots : bool
        Draw the PNG plots.
    progress : bool
        Show a progress bar on long runs.
    verbose : bool
        Say once (stderr) whether the fused compiled loop runs, or why the Python clock does.
    checkpoint_every : float, optional
        Save a checkpoint (:mod:`oceangnc.core.checkpoint`) every this many simulated seconds.
    resume : path, optional
        A run folder holding a checkpoint: continue that run (its own ``config.toml``; the other
        config arguments must be absent) from its last checkpoint. The finished log equals the one
        of an uninterrupted run.
    model : path, optional
        An identified model file (``identified.toml`` from ``oceangnc identify``): its
        ``[parameters]`` (dotted keys) are applied over the config, under ``overrides``.
    _post : internal
        The summary/plot helper forked by the command line (:mod:`oceangnc.postproc`); without it
        the summary and plots are made in this process.

    Raises
    ------
    ConfigError, InputError
        Bad config or input (the CLI exits 2).
    DivergenceError
        The simulation blew up; ``log.parquet`` up to that point and ``summary.json`` with
        ``status = "diverged"`` are still written (the CLI exits 1).
    overwrite : bool
        Allow ``out`` to be a folder that already holds a run (its log, summary and plots are replaced);
        without it such a folder is refused (one-line InputError), so old plots never sit beside a new log.
    KeyboardInterrupt
        Ctrl-C (or SIGTERM under the command line, :class:`~oceangnc.errors.Terminated`): the log so
        far is kept and closed, and ``summary.json`` says ``status = "interrupted"`` and which signal.
    """
    from .core import checkpoint as ckpt
    from .errors import ConfigError, InputError, OceanGNCError, Terminated

    if checkpoint_every is not None and not (math.isfinite(checkpoint_every) and checkpoint_every > 0):
        raise ConfigError(f"--checkpoint-every {checkpoint_every}: must be a finite number of simulated seconds > 0")
    state = None
    created = False
    if resume is not None:
        if scenario or overrides or config is not None or duration is not None:
            raise InputError(
                "--resume DIR continues that run with its own config.toml; "
                "give no scenario, --config, --set or --duration with it"
            )
        out_dir = Path(resume)
        if not out_dir.is_dir():
            raise InputError(f"run folder not found: {out_dir}")
        status = _summary_status(out_dir / "summary.json")
        if status == "ok":
            raise InputError(f"run {out_dir} finished (summary.json status ok); nothing to resume")
        state = ckpt.load(out_dir)
        if checkpoint_every is None:
            checkpoint_every = state.get("every")  # the run keeps checkpointing at its own period
        sc, cfg = resolve_config(None, load_toml(out_dir / "config.toml"))
        # the log is cut to the checkpoint (by the folder's own parts) only once the checkpoint was restored
        # into the rebuilt simulation, checked whole: a refused checkpoint leaves the log as it was
        log = LogWriter.for_run(out_dir, cfg.log, start_part=1, start_row=state["log"]["rows"])
        state["on_restored"] = lambda: _cut_log(out_dir, log, state)
    else:
        sc, cfg = resolve_run_config(scenario, config, overrides, duration, model)
        if checkpoint_every is not None and not sc.single_simulation(cfg):
            raise ConfigError(
                f"--checkpoint-every: {sc.name} runs several simulations one after the other with this config; "
                "checkpoints and --resume support single-simulation runs"
            )
        if cfg.sim.duration < cfg.sim.dt:
            raise ConfigError(
                f"config error: sim.duration = {cfg.sim.duration:g}: shorter than one physics step "
                f"(sim.dt = {cfg.sim.dt:g} s); nothing would be simulated"
            )
        out_dir = Path(out) if out is not None else new_run_dir("runs", sc.name)
        created = _prepare_out_dir(out_dir, overwrite)
        for stale in ("summary.json", ckpt.FILE, ckpt.OLD_FILE):
            (out_dir / stale).unlink(missing_ok=True)
        remove_log(out_dir / "log.parquet")  # and the hidden folders of an interrupted merge beside it
        dump_toml(cfg, out_dir / "config.toml")
        log = LogWriter.for_run(out_dir, cfg.log)
    if _track is not None:  # what an interrupt keeps from here on (oceangnc.run_stop)
        _track.folder(out_dir, log, sc.name)
    ctx = RunContext(
        out_dir=out_dir, log=log, rng=np.random.default_rng(cfg.sim.seed), progress=progress, verbose=verbose
    )
    if checkpoint_every is not None or state is not None:
        ctx.checkpointer = ckpt.Checkpointer(out_dir, checkpoint_every, log, resume_state=state, scenario=sc.name)
    # summary and plots in forked helpers that imported pandas/matplotlib while this process simulated
    # (the command line forks them; a Python caller's later runs reuse its own imports)
    post = _post
    t0 = time.perf_counter()
    summary: dict = {"scenario": sc.name, "wall_time_start_unix_s": time.time()}  # the MCAP export's clock

    def write_summary():
        atomic_write_text(out_dir / "summary.json", json.dumps(summary, indent=2))
        if _track is not None:
            _track.status = summary.get("status")

    try:
        metrics = sc.run(cfg, ctx)
    except DivergenceError as e:
        postproc.cancel(post)
        log.close()
        summary.update(
            {"status": "diverged", "error": str(e), "duration_s": e.t, "wall_time_s": time.perf_counter() - t0}
        )
        write_summary()
        raise
    except KeyboardInterrupt as e:  # Ctrl-C, or SIGTERM through the command line's handler (Terminated)
        postproc.cancel(post)
        if state is None or state.get("restored"):
            log.close()
        summary.update(
            {
                "status": "interrupted",
                "signal": "SIGTERM" if isinstance(e, Terminated) else "SIGINT",
                "rows": log.rows_written,
                "wall_time_s": time.perf_counter() - t0,
            }
        )
        write_summary()
        raise
    except BaseException as e:
        postproc.cancel(post)
        if state is None or state.get("restored"):  # a refused resume leaves the log untouched
            log.close()
        if state is None and created and isinstance(e, OceanGNCError) and log.rows_written == 0:
            import shutil

            shutil.rmtree(out_dir, ignore_errors=True)  # refused before it simulated: leave nothing behind
        raise
    log.close()
    if state is not None and ctx.checkpointer.attached == 0:
        postproc.cancel(post)
        raise InputError(f"scenario {sc.name} runs without a single simulation; it cannot be resumed")
    table = read_table(out_dir / "log.parquet")
    df = None
    if post is not None:
        post.go(out_dir, cfg)
    try:
        found = post.summary() if post is not None else None
        if found is None:  # no helper, or it failed: here (an error surfaces as it would without helpers)
            df = log_frame(sc, table)
            found = sc.summarize(df, cfg)
        metrics = {**(metrics or {}), **found}
        summary.update({k: _jsonable(v) for k, v in metrics.items()})
        summary.setdefault("duration_s", float(ctx.info.get("t_end", cfg.sim.duration)))
        summary["status"] = "ok"
        summary["wall_time_s"] = time.perf_counter() - t0
        if ctx.checkpointer is not None:
            summary["checkpoints"] = ctx.checkpointer.saved
            if state is not None:
                summary["resumed_from_t"] = float(state["t"])
        write_summary()
        plot_paths = (post.plots() if post is not None else None) if plots else []
        if plot_paths is None:
            plot_paths = sc.plot(log_frame(sc, table) if df is None else df, cfg, out_dir)
    finally:
        postproc.cancel(post, done=True)
    return RunResult(log=table, summary=summary, config=cfg, out_dir=out_dir, plots=plot_paths)


run = run_stop.guarded(run)  # an interrupt in any phase writes summary.json or says what was kept


def log_frame(sc, table):
    """A run's log for its scenario's summary and plots: :class:`~oceangnc.io.frame.Columns` when the
    scenario reads columns only (``frame = "columns"``: no pandas import), else a DataFrame."""
    if getattr(sc, "frame", "pandas") == "columns":
        from .io.frame import Columns

        return Columns.from_table(table)
    return table.to_pandas()


def _summary_status(path: Path):
    """The ``status`` of a run's ``summary.json`` (None when absent or not a JSON object); the file is read
    bounded (:func:`oceangnc.core.files.read_text_bounded`) and an unreadable one is a one-line InputError."""
    from .core.files import LIMIT_JSON, read_text_bounded
    from .errors import InputError

    if not os.path.lexists(path):
        return None
    try:
        s = json.loads(read_text_bounded(path, LIMIT_JSON, "summary"))
    except (ValueError, RecursionError):
        raise InputError(f"summary {path}: not a JSON document; remove it to resume") from None
    return s.get("status") if isinstance(s, dict) else None


def _cut_log(out_dir: Path, log, state: dict) -> None:
    """After the checkpoint was restored: cut the log to it (the folder's own parts decide,
    :mod:`oceangnc.io.log_resume`), point the writer after it, and drop the stale summary."""
    from .io.log_resume import cut_to_checkpoint

    log.parts = cut_to_checkpoint(out_dir / "log.parquet", state["log"]["rows"], state["t"])
    log.rows = log.rows_written = state["log"]["rows"]
    state["restored"] = True
    (out_dir / "summary.json").unlink(missing_ok=True)


def replot(run_dir: str | Path) -> list[Path]:
    """Re-draw a finished run's plots from its ``log.parquet`` and ``config.toml``."""
    from .errors import InputError

    d = Path(run_dir)
    if not d.is_dir():
        raise InputError(f"run folder not found: {d}")
    if not (d / "config.toml").is_file():
        raise InputError(f"{d} is not a run folder: it has no config.toml")
    cfg_dict = load_toml(d / "config.toml")
    sc, cfg = resolve_config(cfg_dict.get("scenario"), cfg_dict)
    table = read_table(d / "log.parquet")
    if table.num_rows == 0:  # empty figures would replace good ones
        raise InputError(f"{d}: the log has no rows; nothing to plot (the existing plots are kept)")
    return sc.plot(log_frame(sc, table), cfg, d)


def config_dict(cfg) -> dict:
    """A resolved config as a plain nested dict."""
    return to_dict(cfg)
