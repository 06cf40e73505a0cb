"""Real-time factor, Python clock against the fused loop, of the scenarios fused by the second round
of compiled forms (first-order USV, console USV, berthing modes; issue 19).

    NUMBA_NUM_THREADS=1 python benchmarks/bench_fused_more.py

Same method as ``bench_combined.py``: a warm-up run loads the numba caches, the first tick and the
loop's build are outside the timing, no log is written; RTF = simulated s / wall s.
"""

import time
import warnings

import numpy as np

from oceangnc.api import resolve_config

CASES = [
    ("autopilot-heading", {}),
    ("usv-waypoints-7", {}),
    ("usv-remote", {}),
    ("uuv-profile-plan", {}),
    ("berthing-dock", {"control.mode": "pid"}),
]


def _time(name, over, fused):
    sc, cfg = resolve_config(name, overrides=over)
    sim = sc.build(cfg, np.random.default_rng(cfg.sim.seed))
    sim.use_fused = fused
    sim.run(0.0)  # first tick (Python on both paths) and, fused, the loop's build
    w0, c0 = time.perf_counter(), time.process_time()
    t = sim.run(cfg.sim.duration)
    return sim, t, time.perf_counter() - w0, time.process_time() - c0


if __name__ == "__main__":
    warnings.simplefilter("ignore", RuntimeWarning)
    print("| scenario | overrides | simulated s | path | wall s (python / fused) | RTF wall (python / fused) |")
    print("|---|---|---|---|---|---|")
    for name, over in CASES:
        _time(name, {**over, "sim.duration": 2.0}, True)  # compile / load caches
        sp, tp, wp, cp = _time(name, over, False)
        sf, tf, wf, cf = _time(name, over, True)
        o = ", ".join(f"{k}={v}" for k, v in over.items())
        print(
            f"| {name} | {o} | {tf:.1f} | {sf.path} | {wp:.2f} / {wf:.3f} | {tp / wp:.0f} / {tf / wf:.0f} |", flush=True
        )
