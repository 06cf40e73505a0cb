"""Benchmark and consistency study of the augmented-state EKF (document 002).

1. Wall time to identify the ten coefficients from 200 s of 100 Hz data (13-state filter, one core),
   per Jacobian mode (analytic, complex step, finite differences); the target is < 5 s.
2. Noise-free accuracy for both zig-zags (worst relative error of the ten).
3. NEES study: 20 noise seeds per maneuver, guesses drawn from the prior N(true, (0.2 true)^2),
   nominal sensor noise; mean final NEES of the ten coefficients against the chi-square interval.

Run: ``NUMBA_NUM_THREADS=1 python benchmarks/bench_ekf.py [--seeds 20]``.
"""

from __future__ import annotations

import argparse
import math
import os
import time

import numpy as np
from scipy.stats import chi2

from oceangnc.identification.ekf import nees, run_ekf, submarine_vertical_model
from oceangnc.identification.maneuvers import zigzag
from oceangnc.models.submarine_vertical import COEFF_NAMES, TRUE_COEFFS, SubmarineVerticalConfig

from record import record

TRUE = np.array([TRUE_COEFFS[k] for k in COEFF_NAMES])
SD = np.array([0.002, math.radians(0.02), math.radians(0.005)])


def timing(data, repeats=3):
    model = submarine_vertical_model()
    a0 = TRUE * (1 + 0.2 * np.array([1, -1] * 5))
    P0 = np.concatenate([(2e-3 * SD) ** 2, (0.3 * a0) ** 2])
    Q = np.concatenate([2.5e-5 * (1e-3 * SD) ** 2, np.zeros(10)])
    R = (1e-3 * SD) ** 2
    out = {}
    for mode in ("analytic", "complex-step", "finite-difference"):
        t0 = time.perf_counter()
        res = run_ekf(
            model, data.t, data.z_meas, data.ds[:, None], COEFF_NAMES, data.z_meas[0], a0, P0, Q, R, jacobian=mode
        )
        first = time.perf_counter() - t0
        best = float("inf")
        for _ in range(repeats):
            t0 = time.perf_counter()
            res = run_ekf(
                model, data.t, data.z_meas, data.ds[:, None], COEFF_NAMES, data.z_meas[0], a0, P0, Q, R, jacobian=mode
            )
            best = min(best, time.perf_counter() - t0)
        worst = float(np.max(np.abs(res.X[-1, 3:] / TRUE - 1)))
        out[mode] = (first, best, worst)
    return out


def nees_study(maneuver, seeds, q_rel=2.5e-5):
    c = SubmarineVerticalConfig()
    d = zigzag(c.params(), c.x0(), maneuver)
    model = submarine_vertical_model()
    vals, inside, nis = [], [], []
    for s in range(seeds):
        rng = np.random.default_rng(1000 + s)
        Z = d.x_true[:, :3] + rng.standard_normal((d.t.size, 3)) * SD
        a0 = TRUE * (1 + 0.2 * rng.standard_normal(10))
        P0 = np.concatenate([(2 * SD) ** 2, (0.2 * TRUE) ** 2])
        Q = np.concatenate([q_rel * SD**2, np.zeros(10)])
        res = run_ekf(model, d.t, Z, d.ds[:, None], COEFF_NAMES, Z[0], a0, P0, Q, SD**2)
        e = res.X[-1, 3:] - TRUE
        vals.append(nees(e, res.P[3:, 3:]))
        inside.append(int(np.sum(np.abs(e) <= 3 * res.sigma[-1, 3:])))
        nis.append(float(np.nanmean(res.nis)))
    lo, hi = chi2.ppf([0.025, 0.975], 10 * seeds) / seeds
    return np.mean(vals), (lo, hi), inside, np.mean(nis), vals


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--seeds", type=int, default=20)
    ap.add_argument("--q-rel", type=float, default=2.5e-5, help="state process noise, units of R per second")
    ap.add_argument("--nees-only", action="store_true")
    args = ap.parse_args()
    print(
        f"machine: {os.cpu_count()} cores, load average {os.getloadavg()[0]:.1f}, NUMBA_NUM_THREADS="
        f"{os.environ.get('NUMBA_NUM_THREADS', '(unset)')}"
    )
    c = SubmarineVerticalConfig()
    for man in () if args.nees_only else ("5-5", "10-5"):
        t0 = time.perf_counter()
        d = zigzag(c.params(), c.x0(), man)
        tg = time.perf_counter() - t0
        print(
            f"\n{man} zig-zag: truth RK4 at 1e-4 s for 200 s + sampling at 100 Hz: {tg:.2f} s "
            f"({d.n_reversals} plane reversals)"
        )
        for mode, (first, best, worst) in timing(d).items():
            record(
                "EKF identification (002)",
                f"{man} zig-zag, 200 s at 100 Hz, 13 states, {mode}: wall",
                best,
                "s",
                "< 5 s",
                f"first call incl. load/compile {first:.1f} s; noise-free worst error {100 * worst:.3f} %",
            )
            print(
                f"  EKF 13 states, 20001 samples, {mode:>17}: {best:6.3f} s (first call incl. load/compile "
                f"{first:6.2f} s), real-time factor {200.0 / best:6.0f}x, noise-free worst error {100 * worst:.3f} %"
            )
    for man in ("5-5", "10-5"):
        m, (lo, hi), inside, nis, vals = nees_study(man, args.seeds, args.q_rel)
        record(
            "EKF identification (002)",
            f"{man} zig-zag, mean NEES over {args.seeds} seeds (10 dof)",
            m,
            "",
            f"95 % interval [{lo:.2f}, {hi:.2f}]",
            f"mean NIS {nis:.3f} (3 dof)",
        )
        print(
            f"\nNEES study {man}, {args.seeds} seeds, q_rel {args.q_rel:g}: mean NEES {m:.2f} (10 dof; 95 % interval "
            f"[{lo:.2f}, {hi:.2f}]), mean NIS {nis:.3f} (3 dof), runs with >= 9/10 inside 3 sigma: "
            f"{sum(i >= 9 for i in inside)}/{len(inside)}; per seed: {np.round(vals, 1).tolist()}"
        )


if __name__ == "__main__":
    main()
