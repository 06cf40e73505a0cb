"""Real-time factor of the combined-vehicle scenarios (guidance + control + sensors on the compiled plant).

    NUMBA_NUM_THREADS=1 python benchmarks/bench_combined.py

Prints simulated time, wall time (numba compilation excluded by a warm-up run) and the real-time
factor (simulated / wall seconds) of each scenario, as run by ``oceangnc.run`` without plots.
"""

import time

import numpy as np

from oceangnc.api import resolve_config
from oceangnc.scenarios.combined import build_simulation

CASES = [("combined-survey", {"control.uuv": "pid"}), ("combined-survey", {"control.uuv": "backstepping"}),
         ("waypoints-square", {}), ("field-test", {})]

if __name__ == "__main__":
    sc, cfg = resolve_config("combined-survey", overrides={"sim.duration": 1.0})
    build_simulation(cfg, np.random.default_rng(0)).run(1.0)  # compile
    print("| scenario | overrides | simulated s | wall s | CPU s | real-time factor |")
    print("|---|---|---|---|---|---|")
    for name, over in CASES:
        sc, cfg = resolve_config(name, overrides=over)
        sim = build_simulation(cfg, np.random.default_rng(cfg.sim.seed))
        w0, c0 = time.perf_counter(), time.process_time()
        t = sim.run(cfg.sim.duration)
        w, c = time.perf_counter() - w0, time.process_time() - c0
        print(f"| {name} | {over or ''} | {t:.1f} | {w:.2f} | {c:.2f} | {t / w:.0f} |")
