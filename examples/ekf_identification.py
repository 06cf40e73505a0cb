"""Identify hydrodynamic coefficients with the augmented-state EKF (document 002), three ways.

1. The packaged scenario: a 10-5 zig-zag of the 002 submarine, noise-free, ten coefficients.
2. The same from a log on disk, as a user with trial data would do (``oceangnc identify ekf``).
3. Your own model: any ``f(x, p, u)`` and ``h(x)`` compiled with numba; here a pendulum-spring whose
   stiffness and damping are identified from its angle alone (Jacobians by complex step).

Run: ``python examples/ekf_identification.py`` (about a minute the first time: numba compiles).
"""

import tempfile
from pathlib import Path

import numpy as np
from numba import njit

import oceangnc
from oceangnc.identification.ekf import EKFModel, run_ekf
from oceangnc.identification.ekf_cli import identify_log

out = Path(tempfile.mkdtemp()) / "ekf-zigzag"

# 1. scenario: noise-free 10-5 zig-zag, 200 s at 100 Hz
res = oceangnc.run("ekf-zigzag", overrides={"maneuver": "10-5", "noise": 0.0}, out=out)
print(f"scenario: max relative error {100 * res.summary['max_rel_error']:.3f} %  (plots in {out})")
for k in ("Zw", "Zqdot", "Mw", "Mds"):
    s = res.summary
    print(f"  {k:6s} true {s[k + '.true']: .6g}  estimate {s[k + '.estimate']: .6g}  1-sigma {s[k + '.sigma']:.2g}")

# 2. from the log: pitch-moment coefficients only, guesses 20 % high
table = identify_log(out / "log.parquet", "submarine-vertical", "Mw,Mq,Mds", initial_scale=1.2)
for k, v in table["parameters"].items():
    print(f"  log -> {k:4s} {v['estimate']: .6g} +/- {v['sigma']:.2g}")


# 3. a user model
@njit(cache=True)
def f(x, p, u, out):  # x = [angle, rate], p = [k, c, J]
    out[0] = x[1]
    out[1] = (u[0] - p[1] * x[1] - p[0] * np.sin(x[0])) / p[2]


@njit(cache=True)
def h(x, p, out):
    out[0] = x[0]


model = EKFModel(name="pendulum", f=f, h=h, state_names=("angle", "rate"), param_names=("k", "c", "J"),
                 input_names=("torque",), measurement_names=("angle",), params=np.array([2.0, 0.3, 1.0]))
t = np.arange(0.0, 40.0, 0.02)
U = np.where((t // 5) % 2 == 0, 1.0, -1.0)[:, None]
x, X = np.zeros(2), np.zeros((t.size, 2))
k1, k2, k3, k4 = (np.zeros(2) for _ in range(4))
h = 0.001
for i in range(t.size):  # truth: RK4 at 1 ms, input held over each 20 ms sample
    X[i] = x
    for _ in range(20):
        f(x, model.params, U[i], k1)
        f(x + 0.5 * h * k1, model.params, U[i], k2)
        f(x + 0.5 * h * k2, model.params, U[i], k3)
        f(x + h * k3, model.params, U[i], k4)
        x = x + h / 6 * (k1 + 2 * k2 + 2 * k3 + k4)
rng = np.random.default_rng(0)
Z = X[:, :1] + 0.002 * rng.standard_normal((t.size, 1))
r = run_ekf(model, t, Z, U, "k,c", x0=[0.0, 0.0], alpha0=[1.0, 0.5], P0=[1e-4, 1e-2, 1.0, 0.25],
            Q=[1e-8, 1e-6, 0.0, 0.0], R=[0.002 ** 2])
for name, (v, s) in r.final().items():
    print(f"  pendulum {name}: {v:.4f} +/- {s:.4f}  (true {model.params[model.param_names.index(name)]})")
