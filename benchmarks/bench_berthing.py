"""Speed of the berthing stack: compiled ship right-hand side and a live scenario run.

    python benchmarks/bench_berthing.py

Prints the RK4 step rate of the ship model alone (one compiled call for many steps) and the
real-time factor of one berthing-channel run per controller (plant, joystick filter, controller,
scripted pilot, logging at 1 Hz).
"""

from __future__ import annotations

import time

import numpy as np

import oceangnc
from oceangnc.core.integrators import rk4_advance, rk4_workspace
from oceangnc.models.ship_lowspeed import ShipConfig, ShipPlant, ship_rhs

from record import record


def rhs_rate(n_steps: int = 200_000) -> float:
    cfg = ShipConfig(u0=3.0)
    p = cfg.params()
    x = ShipPlant(cfg).x.copy()
    u = np.array([0.1, 0.5, 1.0, -1.0, 0.1, 0.1, 3.0, 2.0])
    w = rk4_workspace(x.size)
    rk4_advance(ship_rhs, 0.0, x, u, p, 0.05, 10, w)  # compile
    t0 = time.perf_counter()
    rk4_advance(ship_rhs, 0.0, x, u, p, 0.05, n_steps, w)
    return n_steps / (time.perf_counter() - t0)


def main() -> None:
    print(f"ship RK4 steps/s (dt 0.05 s, 4 rhs calls each): {rhs_rate():.3g}")
    for mode in ("open", "pid", "nonlinear"):
        t0 = time.perf_counter()
        r = oceangnc.run(
            "berthing-channel",
            overrides={"control.mode": mode, "runs": 1},
            plots=False,
            out=f"/tmp/bench-berthing-{mode}",
        )
        wall = time.perf_counter() - t0
        sim_t = r.summary["duration_s"]
        record("berthing (001)", f"`berthing-channel` {mode}, end to end with its log", sim_t / wall, "x")
        print(
            f"berthing-channel {mode}: {sim_t:.0f} s simulated in {wall:.1f} s wall -> real-time factor {sim_t / wall:.0f}"
        )


if __name__ == "__main__":
    main()
