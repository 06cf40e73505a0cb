"""Throughput of a sweep (runs per minute) on 1 and 2 local Dask workers.

Default: 200 runs of ``cable-current`` (10 current speeds x 20 seeds) if that scenario exists, else
``usv-turn-current`` (same grid on its current speed). For each worker count the script runs
the sweep through ``oceangnc.sweep.run_sweep`` into a fresh folder and prints

* ``end-to-end``: runs / wall time of the whole call (cluster start, per-worker numba load or
  compile, every run, table writes);
* ``warm``: runs finished after every worker had finished its first run, divided by the time from
  that moment to the last run (the steady rate once each process has its compiled code);
* ``first run``: mean wall and CPU time of each worker's first run (import + numba compilation)
  and of the others (the per-run cost; CPU time does not depend on how loaded the machine is).

Usage: ``NUMBA_NUM_THREADS=1 python benchmarks/bench_sweep.py [--runs 200] [--workers 1 2]
[--scenario NAME] [--duration S]``
"""

from __future__ import annotations

import argparse
import os
import shutil
import tempfile
import time
from pathlib import Path

import numpy as np
import pandas as pd


def measure(
    scenario: str, key: str, values: list, seeds: int, workers: int, duration: float | None, root: Path
) -> dict:
    from oceangnc.sweep import build_design, run_sweep

    design = build_design(scenario, grid={key: values}, seeds=seeds, duration=duration)
    out = root / f"{scenario}-w{workers}"
    shutil.rmtree(out, ignore_errors=True)
    t0 = time.perf_counter()
    res = run_sweep(design, out, workers=workers, progress=False, keep=False)
    wall = time.perf_counter() - t0
    df = res.table.copy()
    df["end"] = pd.to_datetime(df["finished_at"])
    df = df.sort_values("end")
    first = df.groupby("worker", sort=False).head(1)
    rest = df.drop(first.index)
    t_warm = first["end"].max()
    after = df[df["end"] > t_warm]
    span = (df["end"].max() - t_warm).total_seconds()
    return {
        "scenario": scenario,
        "workers": workers,
        "runs": len(df),
        "ok": int((df["status"] == "ok").sum()),
        "wall_s": wall,
        "end_to_end_rpm": 60 * len(df) / wall,
        "warm_rpm": 60 * len(after) / span if span > 0 and len(after) else float("nan"),
        "first_run_s": float(first["wall_time_s"].mean()),
        "other_run_s": float(rest["wall_time_s"].mean()),
        "first_cpu_s": float(first["cpu_time_s"].mean()),
        "other_cpu_s": float(rest["cpu_time_s"].mean()),
        "cpu_total_s": float(df["cpu_time_s"].sum()),
        "workers_used": df["worker"].nunique(),
    }


def main(argv=None) -> int:
    from oceangnc.api import list_scenarios

    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--runs", type=int, default=200, help="total runs (10 grid values x runs/10 seeds)")
    ap.add_argument("--workers", type=int, nargs="+", default=[1, 2])
    ap.add_argument("--scenario", help="default cable-current if present, else usv-turn-current")
    ap.add_argument("--duration", type=float, help="simulated time per run, s (default: the scenario's)")
    ap.add_argument("--out", help="folder for the sweep folders (default: a temporary one)")
    args = ap.parse_args(argv)
    os.environ.setdefault("NUMBA_NUM_THREADS", "1")
    scen = args.scenario or ("cable-current" if "cable-current" in list_scenarios() else "usv-turn-current")
    key = "environment.current.speed"
    values = [round(float(v), 3) for v in np.linspace(0.1, 1.0 if scen == "cable-current" else 0.3, 10)]
    seeds = max(1, args.runs // len(values))
    root = Path(args.out) if args.out else Path(tempfile.mkdtemp(prefix="bench-sweep-"))
    print(
        f"# sweep benchmark: {scen}, {key} in {values} x {seeds} seeds = {len(values) * seeds} runs, "
        f"duration {args.duration or 'default'}; load average at start {os.getloadavg()[0]:.2f}"
    )
    rows = []
    for w in args.workers:
        r = measure(scen, key, values, seeds, w, args.duration, root)
        rows.append(r)
        print(
            f"workers {w}: {r['runs']} runs ({r['ok']} ok) in {r['wall_s']:.1f} s -> end-to-end "
            f"{r['end_to_end_rpm']:.1f} runs/min, warm {r['warm_rpm']:.1f} runs/min; first run per worker "
            f"{r['first_run_s']:.2f} s wall / {r['first_cpu_s']:.2f} s CPU, other runs {r['other_run_s']:.2f} s wall / "
            f"{r['other_cpu_s']:.2f} s CPU (sum of run CPU {r['cpu_total_s']:.0f} s); workers used {r['workers_used']}; "
            f"load average now {os.getloadavg()[0]:.2f}",
            flush=True,
        )
    if len(rows) > 1:
        base = rows[0]
        for r in rows[1:]:
            print(
                f"scaling {base['workers']} -> {r['workers']} workers: end-to-end x"
                f"{r['end_to_end_rpm'] / base['end_to_end_rpm']:.2f}, warm x{r['warm_rpm'] / base['warm_rpm']:.2f}"
            )
    if not args.out:
        shutil.rmtree(root, ignore_errors=True)
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
