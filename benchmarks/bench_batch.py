"""Throughput of ``oceangnc.run_batch``: K combined-survey runs with random current and start offsets.

    python benchmarks/bench_batch.py [K] [duration]

Runs the same batch on one core (one process, one numba thread: the compiled batch with the
per-run Python work in between) and on two (``workers=2``: two spawned processes sharing the runs,
one thread each), after a warm-up; reports runs per minute and the speed-up, and checks that three
of the runs equal the same runs made one by one with :func:`oceangnc.run` (bit for bit in the log).
"""

import sys
import tempfile
import time

import numpy as np

import oceangnc
from oceangnc.io.logs import read_log

from record import record

if __name__ == "__main__":
    K = int(sys.argv[1]) if len(sys.argv) > 1 else 1000
    dur = float(sys.argv[2]) if len(sys.argv) > 2 else 40.0
    rng = np.random.default_rng(2026)
    over = [
        {
            "environment.current.speed": float(rng.uniform(0.0, 0.3)),
            "environment.current.direction_deg": float(rng.uniform(0.0, 360.0)),
            "usv.x0": float(rng.uniform(-2.0, 2.0)),
            "usv.y0": float(rng.uniform(-2.0, 2.0)),
        }
        for _ in range(K)
    ]
    seeds = list(range(K))
    tmp = tempfile.mkdtemp()
    oceangnc.run_batch("combined-survey", over[:2], seeds=seeds[:2], duration=2.0, out=f"{tmp}/warm", workers=1)
    res = {}
    for w in (1, 2):
        w0 = time.perf_counter()
        s = oceangnc.run_batch(
            "combined-survey", over, seeds=seeds, duration=dur, out=f"{tmp}/t{w}", threads=1, workers=w, chunk=64
        )
        wall = time.perf_counter() - w0
        res[w] = wall
        ok = sum(x["status"] == "ok" for x in s)
        print(
            f"cores={w}: {K} runs x {dur:g} s in {wall:.1f} s wall: {60 * K / wall:.0f} runs/min, "
            f"{K * dur / wall:.0f}x real time aggregate, {ok} ok",
            flush=True,
        )
    print(f"speed-up 2 cores / 1 core: {res[1] / res[2]:.2f}x")
    record("batches (run_batch)", f"{K} flagship runs of {dur:g} s on 1 core", 60 * K / res[1], "runs/min")
    record("batches (run_batch)", f"{K} flagship runs of {dur:g} s, speed-up 2 cores / 1 core", res[1] / res[2], "x")
    for i in range(3):
        r = oceangnc.run(
            "combined-survey",
            overrides={**over[i], "sim.seed": seeds[i]},
            duration=dur,
            out=f"{tmp}/one{i}",
            plots=False,
        )
        same = np.array_equal(read_log(f"{tmp}/t2/run-{i:05d}").to_numpy(), read_log(r.out_dir).to_numpy())
        same = same and np.array_equal(read_log(f"{tmp}/t1/run-{i:05d}").to_numpy(), read_log(r.out_dir).to_numpy())
        print(f"run {i}: log identical to the run made alone: {same}")
