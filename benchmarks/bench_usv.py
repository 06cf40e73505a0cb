"""Real-time factor of the USV open-loop turn (``usv-turn``): simulated seconds per wall second.

Runs the scenario's simulation (physics RK4 at 1 ms, 100 Hz command/thrusters, 10 Hz environment,
20 Hz log) once to compile, then times ``--repeat`` runs and prints the best. Usage::

    python benchmarks/bench_usv.py [--duration 300] [--repeat 3]
"""

from __future__ import annotations

import argparse
import os
import platform
import time

import numpy as np

from record import record

os.environ.setdefault("NUMBA_NUM_THREADS", "1")


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__)
    ap.add_argument("--duration", type=float, default=300.0, help="simulated seconds per run")
    ap.add_argument("--repeat", type=int, default=3)
    args = ap.parse_args()

    import oceangnc
    from oceangnc.io.logs import LogWriter

    sc, cfg = oceangnc.resolve_config("usv-turn")
    sc.build(cfg, np.random.default_rng(0)).run(1.0)  # compile
    best = float("inf")
    for _ in range(args.repeat):
        sim = sc.build(cfg, np.random.default_rng(0))
        import tempfile

        with tempfile.TemporaryDirectory() as d, LogWriter(f"{d}/log.parquet") as log:
            t0 = time.perf_counter()
            sim.run(args.duration, log=log)
            best = min(best, time.perf_counter() - t0)
    steps = args.duration / cfg.sim.dt
    print(
        f"machine: {platform.processor() or platform.machine()}, {os.cpu_count()} cores, python {platform.python_version()}"
    )
    print(
        f"usv-turn: {args.duration:.0f} s simulated in {best:.3f} s wall -> real-time factor {args.duration / best:.0f}x"
    )
    record(
        "USV",
        f"`usv-turn` {args.duration:.0f} s with its 20 Hz log, best of {args.repeat}",
        args.duration / best,
        "x",
        "",
        f"{steps / best / 1e6:.2f} M physics steps/s (dt {cfg.sim.dt} s)",
    )
    print(
        f"  physics steps (dt={cfg.sim.dt} s): {steps / best / 1e6:.2f} M steps/s; "
        f"clock ticks (100 Hz): {args.duration * 100 / best:.0f} ticks/s"
    )


if __name__ == "__main__":
    main()
