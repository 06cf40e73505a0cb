"""Real-time factor of the closed-loop scenarios, Python clock against the fused compiled loop.

    NUMBA_NUM_THREADS=1 python benchmarks/bench_combined.py [NAME_PART ...]

(with arguments: only the cases whose scenario name contains one of them, e.g. ``tow``).

For each case: simulated time, wall and CPU time of the Python clock and of the fused loop
(:mod:`oceangnc.core.fused`; numba compilation and the first tick excluded by a warm-up run and by
building the loop before timing), the real-time factors (simulated / wall s), and the physics alone
(the plant's compiled stepper over the same number of steps), which bounds what any loop can reach.
No log is written (the log costs the same on both paths: one row per log period).
"""

import time

import numpy as np
from record import record

from oceangnc.api import resolve_config

CASES = [
    ("combined-survey", {"control.uuv": "pid"}),
    ("combined-survey", {"control.uuv": "backstepping"}),
    ("combined-survey", {"control.uuv": "pid", "sim.dt": 0.0025}),
    ("combined-survey", {"control.uuv": "pid", "cable.integrator": "imex", "sim.dt": 0.01}),
    ("combined-survey", {"control.uuv": "backstepping", "cable.integrator": "imex", "sim.dt": 0.01}),
    ("field-test", {"cable.integrator": "imex", "sim.dt": 0.01}),
    ("waypoints-square", {}),
    ("field-test", {}),
    ("cable-current", {}),
    ("usv-turn", {"sim.duration": 300.0}),
    ("berthing-channel", {}),
    # the tow scenarios (winch: variable node count; seabed), their default horizons
    ("tow-straight", {}),
    ("tow-deploy", {}),
    ("tow-survey-depth", {}),
    # vehicles of a file (issue 30): the generic 6-DOF plant, 8 thrusters, allocation and 6-DOF PID
    ("rov-station-keeping", {"sim.duration": 1800.0}),
    ("rov-station-keeping", {"sim.duration": 1800.0, "vehicle": "bluerov2-heavy+redistribute"}),
    ("otter-waypoints", {}),
]


#: what each case's figure is held against (default: the one-law conversions kept the speed, issue 25)
TARGETS = {
    "rov-station-keeping": ">= 1000x (issue 30)",
    # since 2026-11-26 on the three-point bridle (a junction solved by Newton in every right-hand side,
    # issue 27): 2023x on the single tow point before
    "field-test": ">= 1000x (bridle, issue 27)",
}

def _vehicle_file(over):
    """``vehicle = "<shipped>+redistribute"``: the shipped file with ``control.allocator = "redistribute"``,
    written to a temporary file (the label keeps the short name)."""
    v = over.get("vehicle", "")
    if not v.endswith("+redistribute"):
        return over
    import tempfile
    from importlib import resources
    from pathlib import Path

    base = v.removesuffix("+redistribute")
    text = resources.files("oceangnc.models").joinpath("vehicles", base + ".toml").read_text()
    path = Path(tempfile.mkdtemp()) / f"{base}-redistribute.toml"
    path.write_text(
        text.replace(f'name = "{base}"', f'name = "{base}-redistribute"') + '\nallocator = "redistribute"\n'
    )
    return {**over, "vehicle": str(path)}


def _sim(name, over, fused):
    sc, cfg = resolve_config(name, overrides=over)
    sim = sc.build(cfg, np.random.default_rng(cfg.sim.seed))
    sim.use_fused = fused
    sim.run(0.0)  # first tick (Python on both paths) and, fused, the loop's build
    return sim, cfg


def _time(name, over, fused):
    sim, cfg = _sim(name, over, fused)
    w0, c0 = time.perf_counter(), time.process_time()
    t = sim.run(cfg.sim.duration)
    return sim, t, time.perf_counter() - w0, time.process_time() - c0


def _physics(sim, steps):
    pl = sim.plants[0]
    n = max(1, steps // 100)
    c0 = time.process_time()
    for _ in range(100):
        pl.advance(0.0, sim.dt, n)
    return (time.process_time() - c0) * steps / (100 * n)


if __name__ == "__main__":
    import sys

    if sys.argv[1:]:
        CASES = [c for c in CASES if any(a in c[0] for a in sys.argv[1:])]
    print(
        "| scenario | overrides | simulated s | path | wall s (python / fused) | CPU s (python / fused) "
        "| RTF wall (python / fused) | RTF CPU fused | physics alone CPU s |"
    )
    print("|---|---|---|---|---|---|---|---|---|")
    for name, label_over in CASES:
        over = _vehicle_file(label_over)
        _time(name, {**over, "sim.duration": 2.0}, True)  # compile / load caches
        sp, tp, wp, cp = _time(name, over, False)
        sf, tf, wf, cf = _time(name, over, True)
        phys = _physics(sf, int(round(tf / sf.dt)))
        o = ", ".join(f"{k}={v}" for k, v in label_over.items())
        record(
            "closed loop (real-time factor, one core)",
            f"`{name}` {o}".strip() + f", {sf.path}",
            tf / wf,
            "x",
            TARGETS.get(name, "within 10 % of before (issue 25)"),
            f"Python clock {tp / wp:.0f}x; physics alone {tf / phys:.0f}x CPU",
        )
        print(
            f"| {name} | {o} | {tf:.1f} | {sf.path} | {wp:.2f} / {wf:.2f} | {cp:.2f} / {cf:.2f} | "
            f"{tp / wp:.0f} / {tf / wf:.0f} | {tf / cf:.0f} | {phys:.2f} |",
            flush=True,
        )
