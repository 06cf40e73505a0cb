"""Cost of crash safety: per-flush log parts and checkpoints (issue 20).

    PYTHONPATH=src python benchmarks/bench_reliability.py [--duration 300]

Prints the wall time of ``usv-turn`` with the default 1 s flush period against one flush per hour
(the old single-file behaviour), and the size and time of one checkpoint of the flagship
``combined-survey`` (capture + pickle + atomic write) and of a restore.
"""

from __future__ import annotations

import argparse
import os
import tempfile
import time
from pathlib import Path

import numpy as np


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--duration", type=float, default=300.0)
    a = ap.parse_args()
    import oceangnc
    from oceangnc.core import checkpoint as ckpt

    print(f"load average {os.getloadavg()}")
    with tempfile.TemporaryDirectory() as d:
        oceangnc.run("usv-turn", duration=5, out=Path(d) / "warm", plots=False)  # compile
        for period, fsync in ((1.0, False), (1.0, True), (3600.0, False)):
            best = []
            for i in range(3):
                t0 = time.perf_counter()
                oceangnc.run(
                    "usv-turn",
                    duration=a.duration,
                    out=Path(d) / f"p{period}-{fsync}-{i}",
                    plots=False,
                    overrides={"log.flush_period": period, "log.fsync": fsync},
                )
                best.append(time.perf_counter() - t0)
            print(
                f"usv-turn {a.duration:g} s, flush every {period:g} s, fsync {fsync}: {min(best):.2f} s wall "
                f"(best of 3), {a.duration / period if period < a.duration else 1:.0f} parts before compaction"
            )
        sc, cfg = oceangnc.resolve_config("combined-survey")
        sim = sc.build(cfg, np.random.default_rng(0))
        sim.run(20.0)
        t0 = time.perf_counter()
        n = 10
        for _ in range(n):
            blob = ckpt.capture(sim, {"t": sim.t, "log": {"parts": 0, "rows": 0}})
            ckpt.save(Path(d) / ckpt.FILE, blob)
        t_save = (time.perf_counter() - t0) / n
        sim2 = sc.build(cfg, np.random.default_rng(0))
        t0 = time.perf_counter()
        ckpt.restore(sim2, blob)
        t_restore = time.perf_counter() - t0
        size = (Path(d) / ckpt.FILE).stat().st_size
        print(
            f"combined-survey checkpoint: {size / 1024:.1f} kB, save {1000 * t_save:.1f} ms, "
            f"restore {1000 * t_restore:.1f} ms"
        )
    print(f"load average {os.getloadavg()}")


if __name__ == "__main__":
    main()
