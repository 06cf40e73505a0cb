"""Running a sweep: validation up front, execution on ``dask.distributed``, rows recorded as runs finish.

* Every point of the design is validated with :func:`oceangnc.api.resolve_config` (with the largest
  seed of the sweep) before anything runs: a bad key or an out-of-range value raises the config's
  one-line :class:`~oceangnc.errors.ConfigError`, which names the key, plus the point that holds it.
* Runs are Dask tasks (:func:`run_one`, one ordinary :func:`oceangnc.api.run` each). By default a
  ``LocalCluster`` of ``workers`` single-threaded worker processes on 127.0.0.1 is started and closed
  again; with ``scheduler="tcp://host:port"`` the runs go to that existing cluster (its workers must
  have oceangnc installed; run folders are written on the worker's file system, while the results
  row travels back to this process). ``workers=0`` runs them one after the other in this process,
  without Dask (debugging).
* Each finished run's row goes into :class:`~oceangnc.sweep.table.ResultsTable`, which is rewritten
  atomically after every batch of completions. A run that raises (``ConfigError``,
  ``DivergenceError``, anything) becomes a row with ``status`` ``diverged`` or ``failed`` and its error;
  the sweep goes on. A task lost with its worker is recorded the same way.
* Numba-compiled functions are compiled (or loaded from numba's on-disk cache) once per worker
  process, so each worker's first run is slower; ``wall_time_s`` of those rows includes it. Workers
  are long-lived processes, so that cost is paid once per worker, not once per run.
"""

from __future__ import annotations

import datetime as _dt
import json
import os
import socket
import time
import uuid
from dataclasses import dataclass, field
from pathlib import Path

import pandas as pd

from ..errors import ConfigError, DivergenceError, InputError
from .design import Design, RunSpec
from .table import FIXED_COLUMNS, PARAM, ResultsTable
from ..core.files import LIMIT_JSON, read_text_bounded

SPEC_FILE = "sweep.json"


def _one_line(text: str, limit: int = 400) -> str:
    line = " ".join(str(text).split())
    return line if len(line) <= limit else line[: limit - 3] + "..."


def run_one(task: dict) -> dict:
    """Run one scenario (a Dask task) and return its results row; never raises.

    ``task`` holds ``scenario``, ``config`` (dict or None), ``overrides`` (dotted), ``out_dir``,
    ``plots``, ``keep`` (keep the run folder) and the row's identity fields (``row``).
    """
    from .. import api

    t0, c0 = time.perf_counter(), time.process_time()
    row = dict(task["row"])
    out_dir = Path(task["out_dir"])
    status, error, summary = "ok", "", {}
    try:
        res = api.run(
            task["scenario"],
            overrides=task["overrides"],
            config=task["config"],
            out=out_dir,
            plots=task["plots"],
            progress=False,
            overwrite=True,  # a run the killed sweep had started is run again from the start
        )
        summary = res.summary
    except DivergenceError as e:
        status, error = "diverged", _one_line(e)
        try:
            summary = json.loads(read_text_bounded(out_dir / "summary.json", LIMIT_JSON, "summary"))
        except (OSError, ValueError, RecursionError):
            summary = {}
    except Exception as e:  # noqa: BLE001 - any failure of one run is a data point of the sweep
        status, error = "failed", _one_line(f"{type(e).__name__}: {e}")
    for k, v in summary.items():
        if k in ("scenario", "status", "error", "wall_time_s"):
            continue
        if k in FIXED_COLUMNS or k.startswith(PARAM):
            k = f"metric.{k}"  # never let a metric overwrite a bookkeeping column
        row[k] = v if isinstance(v, (int, float, str, bool)) or v is None else json.dumps(v)
    if not task.get("keep", True):
        import shutil

        shutil.rmtree(out_dir, ignore_errors=True)
    row.update(
        {
            "status": status,
            "error": error,
            "wall_time_s": time.perf_counter() - t0,
            "cpu_time_s": time.process_time() - c0,
            "worker": f"{socket.gethostname()}:{os.getpid()}",
            "finished_at": _dt.datetime.now(_dt.timezone.utc).isoformat(timespec="milliseconds"),
            "out_dir": str(out_dir) if task.get("keep", True) else "",
        }
    )
    return row


def run_many(tasks: list[dict]) -> list[dict]:
    """Run several tasks of one scenario as one compiled batch (:func:`oceangnc.batch.run_batch`);
    a Dask task of ``oceangnc sweep --batch K``. Returns the rows :func:`run_one` would; never raises
    (if the batch itself fails, its tasks are run one by one)."""
    from ..batch import run_batch

    if not tasks:
        return []
    t0, c0 = time.perf_counter(), time.process_time()
    try:
        summaries = run_batch(
            tasks[0]["scenario"],
            [t["overrides"] for t in tasks],
            config=tasks[0]["config"],
            out_dirs=[t["out_dir"] for t in tasks],
            workers=1,  # a Dask task is already one of the sweep's processes
        )
    except Exception:  # noqa: BLE001 - fall back to one by one, which records each failure
        return [run_one(t) for t in tasks]
    wall, cpu = (time.perf_counter() - t0) / len(tasks), (time.process_time() - c0) / len(tasks)
    rows = []
    for task, summary in zip(tasks, summaries):
        row = dict(task["row"])
        status = summary.get("status", "failed")
        error = _one_line(summary.get("error", "")) if status != "ok" else ""
        for k, v in summary.items():
            if k in ("scenario", "status", "error", "wall_time_s"):
                continue
            if k in FIXED_COLUMNS or k.startswith(PARAM):
                k = f"metric.{k}"
            row[k] = v if isinstance(v, (int, float, str, bool)) or v is None else json.dumps(v)
        out_dir = Path(task["out_dir"])
        if task.get("plots") and status == "ok":
            from ..api import replot

            replot(out_dir)
        if not task.get("keep", True):
            import shutil

            shutil.rmtree(out_dir, ignore_errors=True)
        row.update(
            {
                "status": status,
                "error": error,
                "wall_time_s": wall,
                "cpu_time_s": cpu,
                "worker": f"{socket.gethostname()}:{os.getpid()}",
                "finished_at": _dt.datetime.now(_dt.timezone.utc).isoformat(timespec="milliseconds"),
                "out_dir": str(out_dir) if task.get("keep", True) else "",
            }
        )
        rows.append(row)
    return rows


def validate_design(design: Design) -> list[RunSpec]:
    """Check every point of ``design`` with ``resolve_config`` before any run; return the runs.

    Raises ConfigError (one line, naming the key) for the first bad point, InputError for an
    unknown scenario.
    """
    from ..api import resolve_config

    runs = design.runs()
    top_seed = design.base_seed + design.seeds - 1
    checked: set[str] = set()
    for r in runs:
        if r.point_id in checked:
            continue
        checked.add(r.point_id)
        try:
            resolve_config(design.scenario, design.config, {**design.fixed, **r.params, "sim.seed": top_seed})
        except ConfigError as e:
            where = ", ".join(f"{k}={v!r}" for k, v in r.params.items())
            raise ConfigError(f"{e} (sweep point {r.point}: {where or 'no swept keys'}); no run was started") from None
    return runs


@dataclass
class SweepResult:
    """What :func:`run_sweep` returns.

    Attributes
    ----------
    out_dir : Path
        The sweep folder (``results.parquet``, ``sweep.json``, ``runs/<run_id>/``).
    table : pandas.DataFrame
        The whole results table (every run of the folder, design order).
    executed : list of str
        ``run_id`` of the runs this call ran (not those skipped by ``resume``).
    skipped : int
        Runs already in the table and not run again.
    wall_time_s : float
        Wall time of this call, cluster start-up included.
    """

    out_dir: Path
    table: pd.DataFrame
    executed: list = field(default_factory=list)
    skipped: int = 0
    wall_time_s: float = 0.0

    @property
    def n_ok(self) -> int:
        return int((self.table["status"] == "ok").sum()) if len(self.table) else 0

    @property
    def n_failed(self) -> int:
        return len(self.table) - self.n_ok


def _prepare_dir(out: Path, design: Design, resume: bool) -> None:
    spec = out / SPEC_FILE
    has_results = (out / "results.parquet").exists()
    if spec.exists() or has_results:
        if not resume:
            raise InputError(f"{out} already holds a sweep; pass --resume to continue it or choose another --out")
        try:
            stored = json.loads(read_text_bounded(spec, LIMIT_JSON, "sweep spec"))
        except (OSError, ValueError, RecursionError):
            stored = None
        if stored is not None and Design.from_json(stored).identity() != design.identity():
            raise InputError(
                f"{out} holds a sweep of another scenario/config/fixed overrides; "
                "--resume needs the same command (choose another --out)"
            )
    out.mkdir(parents=True, exist_ok=True)
    from ..core.files import atomic_write_text

    atomic_write_text(spec, json.dumps(design.to_json(), indent=2, default=str))  # never through a link


def _start_client(workers: int, scheduler: str | None):
    """A ``distributed.Client`` (and the LocalCluster it owns, if any)."""
    try:
        from distributed import Client, LocalCluster
    except ModuleNotFoundError as e:  # pragma: no cover - optional dependency
        raise InputError(f"sweeps need the optional package '{e.name}'; pip install 'oceangnc[sweep]'") from None
    if scheduler:
        try:
            return Client(scheduler, timeout=15), None
        except (OSError, TimeoutError, ValueError) as e:
            raise InputError(f"cannot reach the Dask scheduler at {scheduler}: {_one_line(e, 200)}") from None
    import logging

    # no dashboard; the scheduler's small HTTP server on a free port (not 8787, which may be taken)
    cluster = LocalCluster(
        n_workers=workers,
        threads_per_worker=1,
        processes=True,
        host="127.0.0.1",
        dashboard_address=None,
        silence_logs=logging.ERROR,
        scheduler_kwargs={"dashboard": False, "dashboard_address": "127.0.0.1:0"},
        env={"NUMBA_NUM_THREADS": os.environ.get("NUMBA_NUM_THREADS", "1")},
    )
    return Client(cluster), cluster


def run_sweep(
    design: Design,
    out: str | Path,
    workers: int = 2,
    scheduler: str | None = None,
    resume: bool = False,
    retry_failed: bool = False,
    plots: bool = False,
    keep: bool = True,
    progress: bool = True,
    batch: int = 1,
) -> SweepResult:
    """Validate, then run every run of ``design`` not yet in ``out``'s table; see the module docstring.

    Parameters
    ----------
    design : Design
    out : path
        Sweep folder. Must not hold a sweep unless ``resume``.
    workers : int
        Worker processes of the local Dask cluster (0: in this process, no Dask).
    scheduler : str, optional
        Address of an existing Dask scheduler (``tcp://host:port``); then ``workers`` is ignored.
    resume : bool
        Skip the runs whose ``run_id`` is already in the table.
    retry_failed : bool
        With ``resume``, run again the runs recorded as failed or diverged (their rows are replaced).
    plots, keep : bool
        Draw each run's PNG plots; keep each run's folder (log, summary, config).
    progress : bool
        tqdm progress bar (runs done, failed, estimated time left) on stderr.
    batch : int
        Runs per task: with ``batch > 1`` each task runs that many runs as one compiled batch
        (:func:`run_many`, :func:`oceangnc.batch.run_batch`); the rows are the same.
    """
    t_start = time.perf_counter()
    if scheduler is None and not 0 <= workers <= 512:
        raise InputError(f"--workers {workers}: expected 0..512")
    runs = validate_design(design)
    out = Path(out)
    _prepare_dir(out, design, resume)
    table = ResultsTable(out)
    todo = [r for r in runs if r.run_id not in table or (retry_failed and table.status(r.run_id) != "ok")]
    skipped = len(runs) - len(todo)

    def task(r: RunSpec) -> dict:
        row = {
            "run_id": r.run_id,
            "point_id": r.point_id,
            "index": r.index,
            "point": r.point,
            "seed": r.seed,
            **{PARAM + k: v for k, v in r.params.items()},
        }
        return {
            "scenario": design.scenario,
            "config": design.config,
            "overrides": r.overrides(design.fixed),
            "out_dir": str((out / "runs" / r.run_id).resolve()),
            "plots": plots,
            "keep": keep,
            "row": row,
        }

    executed: list[str] = []
    bar = None
    if progress and todo:
        from tqdm.auto import tqdm

        bar = tqdm(total=len(todo), unit="run", desc=f"sweep {design.scenario}", dynamic_ncols=True)
    n_failed = 0

    def record(rows: list[dict]) -> None:
        nonlocal n_failed
        for row in rows:
            table.add(row)
            executed.append(row["run_id"])
            n_failed += row["status"] != "ok"
        table.flush()
        if bar is not None:
            bar.set_postfix(ok=len(executed) - n_failed, failed=n_failed, refresh=False)
            bar.update(len(rows))

    try:
        if batch > 1:
            groups = [todo[i : i + batch] for i in range(0, len(todo), batch)]
            if groups and scheduler is None and workers == 0:
                for g in groups:
                    record(run_many([task(r) for r in g]))
            elif groups:
                _run_dask(groups, task, record, workers, scheduler, batched=True)
        elif todo and scheduler is None and workers == 0:
            for r in todo:
                record([run_one(task(r))])
        elif todo:
            _run_dask([[r] for r in todo], task, record, workers, scheduler, batched=False)
    finally:
        if bar is not None:
            bar.close()
        if todo:
            table.flush()
    return SweepResult(out, table.frame(), executed, skipped, time.perf_counter() - t_start)


def _lost_row(task_row: dict, e: BaseException) -> dict:
    """The row of a run whose Dask task was lost (worker died, task cancelled)."""
    row = dict(task_row)
    row.update(
        {
            "status": "failed",
            "error": _one_line(f"{type(e).__name__}: {e}"),
            "wall_time_s": float("nan"),
            "cpu_time_s": float("nan"),
            "worker": "",
            "out_dir": "",
            "finished_at": _dt.datetime.now(_dt.timezone.utc).isoformat(timespec="milliseconds"),
        }
    )
    return row


def _run_dask(groups, task, record, workers, scheduler, batched: bool) -> None:
    """One Dask task per group of runs: :func:`run_many` when ``batched``, else :func:`run_one` (groups of
    one). Rows are recorded as tasks complete; a lost task records a failed row for each of its runs."""
    from distributed import as_completed

    client, cluster = _start_client(workers, scheduler)
    futures = []
    try:
        by_key = {}
        token = uuid.uuid4().hex[:8]  # task keys unique to this call, even on a shared cluster
        for g in groups:
            if batched:
                fut = client.submit(
                    run_many, [task(r) for r in g], key=f"oceangnc-batch-{g[0].run_id}-{token}", pure=False
                )
            else:
                fut = client.submit(run_one, task(g[0]), key=f"oceangnc-run-{g[0].run_id}-{token}", pure=False)
            by_key[fut.key] = g
            futures.append(fut)
        for done in as_completed(futures).batches():
            rows = []
            for fut in done:
                try:
                    result = fut.result()
                    rows.extend(result if batched else [result])
                except Exception as e:  # noqa: BLE001 - worker lost, task cancelled: record it
                    rows.extend(_lost_row(task(r)["row"], e) for r in by_key[fut.key])
                fut.release()
            record(rows)
    finally:
        for f in futures:
            if not f.done():
                f.cancel()
        client.close()
        if cluster is not None:
            cluster.close()
