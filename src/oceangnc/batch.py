"""Batches of runs in one compiled call: :func:`run_batch` (issue 19).

K independent copies of a scenario -- each with its own overrides and seed -- are built in Python
(their first tick runs there, as in :mod:`oceangnc.core.fused`), their fused loops' arrays are
stacked run by run, and the generated ``drive_batch`` advances all of them with a numba ``prange``
over runs, so the runs share the cores. Each run writes exactly what :func:`oceangnc.run` writes in
its own folder (``config.toml``, ``log.parquet``, ``summary.json``); the logged numbers are those of
the same run made alone (tested in ``tests/test_batch.py``). Runs are processed in chunks of
``chunk`` to bound the memory of the log buffers. Scenarios without a fused path, or runs whose
overrides change the loop's structure (e.g. the number of waypoints), are run one by one.

A Dask sweep composes with it: each task can be one batch (``oceangnc.sweep`` is unchanged here).
"""

from __future__ import annotations

import json
import os
import time
from pathlib import Path

import numpy as np

from .core.files import atomic_write_text
from .errors import DivergenceError


def _same_structure(loops) -> bool:
    f0 = loops[0]
    if any(isinstance(v, np.random.Generator) for v in f0.args.values()):
        return False
    for f in loops[1:]:
        if f.module is not f0.module or f.sig.size != f0.sig.size or f.log_signals != f0.log_signals:
            return False
        for a in f0.arg_names:
            x, y = f0.args[a], f.args[a]
            if isinstance(x, np.random.Generator):
                return False  # per-run generators cannot be stacked: such runs go one by one
            if isinstance(x, np.ndarray) and (not isinstance(y, np.ndarray) or x.shape != y.shape):
                return False
        if not np.array_equal(f.nbs, f0.nbs):
            return False
    return True


def run_batch(
    scenario: str,
    overrides_list: list[dict] | None = None,
    seeds: list[int] | None = None,
    duration: float | None = None,
    out: str | Path | None = None,
    threads: int | None = None,
    chunk: int = 64,
    config: str | Path | dict | None = None,
    out_dirs: list[str | Path] | None = None,
    workers: int | None = None,
) -> list[dict]:
    """Run K copies of ``scenario`` in compiled batches; returns the K summaries (as ``summary.json``).

    Parameters
    ----------
    overrides_list : list of dict, optional
        Config overrides per run (dotted or nested keys); default K = len(seeds) runs of the defaults.
    seeds : list of int, optional
        ``sim.seed`` per run (default: the config's own).
    duration : float, optional
        Simulated time of every run (s).
    out : path, optional
        Batch folder; run i writes ``out/run-<i>`` (default ``runs/batch-<scenario>-<time>``).
    threads : int, optional
        Numba threads for the prange over runs (default: numba's default, all cores).
    chunk : int
        Runs stacked per compiled call.
    config : path or dict, optional
        A TOML file or dict merged over the defaults of every run (as in :func:`oceangnc.run`).
    out_dirs : list of path, optional
        Each run's own folder instead of ``out/run-<i>`` (the sweep's layout).
    workers : int, optional
        Processes sharing the runs (each runs its share in compiled batches, one numba thread each
        unless ``threads`` says otherwise). Default: one per core for 64 runs or more, else 1. The
        per-run work that is Python (config, build, first tick, log and summary files) runs in
        parallel only across processes, so this is what scales a batch with the cores. Processes are
        started with ``spawn``: call from under ``if __name__ == "__main__":`` in a script.
    """
    from .api import _jsonable, log_frame, new_run_dir, resolve_config
    from .io.config import dump_toml
    from .io.logs import LogWriter
    from .scenarios.base import RunContext

    if overrides_list is None and seeds is None:
        raise ValueError("run_batch: give overrides_list or seeds")
    n = len(overrides_list) if overrides_list is not None else len(seeds)
    if seeds is not None and len(seeds) != n:
        raise ValueError(f"run_batch: {len(seeds)} seeds for {n} override sets")
    if out_dirs is not None and len(out_dirs) != n:
        raise ValueError(f"run_batch: {len(out_dirs)} out_dirs for {n} runs")
    if workers is None:
        workers = (os.cpu_count() or 1) if n >= 64 else 1
    if int(workers) < 1:
        raise ValueError(f"run_batch: workers must be >= 1, got {workers}")
    workers = min(int(workers), n)
    out_dir = (
        Path(out) if out is not None else (None if out_dirs is not None else new_run_dir("runs", f"batch-{scenario}"))
    )
    if out_dir is not None:
        out_dir.mkdir(parents=True, exist_ok=True)
    if workers > 1:
        dirs = [Path(x) for x in out_dirs] if out_dirs is not None else [out_dir / f"run-{i:05d}" for i in range(n)]
        return _run_in_processes(
            scenario, overrides_list, seeds, duration, threads or 1, chunk, config, dirs, workers, n
        )
    if threads is not None:
        import numba

        numba.set_num_threads(int(threads))
    summaries: list[dict] = [{} for _ in range(n)]
    for c0 in range(0, n, chunk):
        idx = list(range(c0, min(n, c0 + chunk)))
        runs = []
        for i in idx:
            over = dict((overrides_list or [{}] * n)[i])
            if seeds is not None:
                over["sim.seed"] = int(seeds[i])
            sc, cfg = resolve_config(scenario, config=config, overrides=over, duration=duration)
            d = Path(out_dirs[i]) if out_dirs is not None else out_dir / f"run-{i:05d}"
            d.mkdir(parents=True, exist_ok=True)
            dump_toml(cfg, d / "config.toml")
            # the log stays in memory and is written once when the run ends (or diverges): a batch
            # run is short and re-runnable, and one file per run instead of one part per flush
            # period is most of the per-run cost saved (benchmarks/RESULTS.md)
            log = LogWriter(d / "log.parquet", flush_period=cfg.sim.duration + 1.0)
            ctx = RunContext(out_dir=d, log=log, rng=np.random.default_rng(cfg.sim.seed))
            runs.append(
                {
                    "i": i,
                    "sc": sc,
                    "cfg": cfg,
                    "dir": d,
                    "log": log,
                    "ctx": ctx,
                    "t0": time.perf_counter(),
                    "error": None,
                }
            )
        _run_chunk(runs)
        for r in runs:
            sc, cfg, d = r["sc"], r["cfg"], r["dir"]
            summary: dict = {"scenario": sc.name}
            r["log"].close()
            if r["error"] is not None:
                e = r["error"]
                summary.update(
                    {
                        "status": "diverged",
                        "error": str(e),
                        "duration_s": e.t,
                        "wall_time_s": time.perf_counter() - r["t0"],
                    }
                )
            else:
                table = r["log"].table()
                if table is None:
                    import pyarrow.parquet as pq

                    table = pq.read_table(d / "log.parquet")
                df = log_frame(sc, table)  # columns for a scenario that reads columns: no pandas import
                metrics = dict(r.get("metrics") or {})
                metrics.update(sc.summarize(df, cfg))
                summary.update({k: _jsonable(v) for k, v in metrics.items()})
                summary.setdefault("duration_s", float(r["ctx"].info.get("t_end", cfg.sim.duration)))
                summary["status"] = "ok"
                summary["wall_time_s"] = time.perf_counter() - r["t0"]
            atomic_write_text(d / "summary.json", json.dumps(summary, indent=2))  # never through a link
            summaries[r["i"]] = summary
    return summaries


def _run_in_processes(scenario, overrides_list, seeds, duration, threads, chunk, config, dirs, workers, n):
    """Share the runs among this process and ``workers - 1`` spawned ones, in tasks of a few runs
    taken from one queue as each process becomes free (this process starts at once, so the others'
    start-up is hidden behind its work; a feeder thread per spawned process hands it the next task
    as soon as it returns one)."""
    import multiprocessing
    import threading
    from collections import deque
    from concurrent.futures import ProcessPoolExecutor

    size = max(1, min(chunk, -(-n // (16 * workers))))
    pending = deque(list(range(i, min(n, i + size))) for i in range(0, n, size))
    lock = threading.Lock()
    summaries: list[dict] = [{} for _ in range(n)]
    errors: list[BaseException] = []

    def take():
        with lock:
            return pending.popleft() if pending and not errors else None

    def args(idx) -> dict:
        return {
            "scenario": scenario,
            "overrides_list": [dict(overrides_list[i]) for i in idx] if overrides_list is not None else None,
            "seeds": [seeds[i] for i in idx] if seeds is not None else None,
            "duration": duration,
            "threads": threads,
            "chunk": chunk,
            "config": config,
            "out_dirs": [dirs[i] for i in idx],
            "workers": 1,
        }

    def store(idx, result):
        for i, summary in zip(idx, result):
            summaries[i] = summary

    with ProcessPoolExecutor(workers - 1, mp_context=multiprocessing.get_context("spawn")) as pool:

        def feed():
            while (idx := take()) is not None:
                try:
                    store(idx, pool.submit(run_batch, **args(idx)).result())
                except BaseException as e:  # noqa: BLE001 - re-raised in the calling thread
                    errors.append(e)

        feeders = [threading.Thread(target=feed, daemon=True) for _ in range(workers - 1)]
        for f in feeders:
            f.start()
        try:
            while (idx := take()) is not None:
                store(idx, run_batch(**args(idx)))
        except BaseException as e:
            errors.append(e)
        for f in feeders:
            f.join()
    if errors:
        raise errors[0]
    return summaries


def _run_chunk(runs: list[dict]) -> None:
    """Build every run's simulation, run the fused ones stacked, the others one by one."""
    sims = []
    for r in runs:
        sim = r["sc"].build(r["cfg"], r["ctx"].rng)
        sim.use_fused = True
        try:
            sim.run(0.0, log=r["log"])  # first tick in Python, fused loop built
        except DivergenceError as e:
            r["error"] = e
        sims.append(sim)
    fused = [i for i, s in enumerate(sims) if s.path == "fused" and runs[i]["error"] is None]
    loops = [sims[i]._fused for i in fused]
    durations = {runs[i]["cfg"].sim.duration for i in fused}
    dts = {(sims[i].dt, sims[i].tick, sims[i].log_steps) for i in fused}
    if not fused or not _same_structure(loops) or len(durations) != 1 or len(dts) != 1:
        fused = []
    for i, (r, sim) in enumerate(zip(runs, sims)):
        if i not in fused and r["error"] is None:
            try:
                r["ctx"].simulate(sim, r["cfg"].sim.duration)
            except DivergenceError as e:
                r["error"] = e
    if not fused:
        return
    f0 = loops[0]
    s0 = sims[fused[0]]
    K = len(fused)
    n_end = s0.k + int(round(durations.pop() / s0.dt))
    SIG = np.ascontiguousarray(np.stack([f.sig for f in loops]))
    B = []
    for a in f0.arg_names:
        if isinstance(f0.args[a], np.ndarray):
            B.append(np.ascontiguousarray(np.stack([f.args[a] for f in loops])))
        else:
            B.append(np.array([f.args[a] for f in loops]))
    cap = 2000
    BUF = np.empty((K, cap, len(f0.log_slots) + 1))
    OUT = np.zeros((K, 6))
    active = np.ones(K, dtype=np.int64)
    ks = np.array([sims[i].k for i in fused], dtype=np.int64)
    dones = np.array([sims[i]._done_k for i in fused], dtype=np.int64)
    while active.any():
        f0.module.drive_batch(
            active,
            ks,
            dones,
            n_end,
            s0.tick,
            s0.dt,
            SIG,
            f0.stop_slot,
            True,
            s0.log_steps,
            f0.log_slots,
            f0.nan_ok,
            BUF,
            1 << 62,
            f0.nbs,
            *B,
            OUT,
        )
        for j in np.flatnonzero(active):
            ks[j], dones[j] = int(OUT[j, 0]), int(OUT[j, 1])
            rows, status = int(OUT[j, 2]), int(OUT[j, 3])
            r = runs[fused[j]]
            if rows:
                r["log"].append_rows(BUF[j, :rows, 0], f0.log_signals, BUF[j, :rows, 1:])
            if status in (0, 2, 3):
                active[j] = 0
                sim = sims[fused[j]]
                fz = loops[j]
                fz.sig[:] = SIG[j]
                for a, arr in zip(f0.arg_names, B):
                    if isinstance(fz.args[a], np.ndarray):
                        fz.args[a][:] = arr[j]
                sim.k, sim._done_k = int(ks[j]), int(dones[j])
                sim.t = sim._done_k * sim.dt
                if status == 0:
                    fz.to_bus(sim.bus)
                    sim.t = sim.k * sim.dt
                    r["ctx"].info["t_end"] = sim.t
                else:
                    r["error"] = sim._fused_error(status, int(OUT[j, 4]), float(OUT[j, 5]))
