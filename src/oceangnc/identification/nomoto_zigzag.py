"""Least-squares Nomoto (K, T) from a zig-zag trial (ITTC 10/10, 20/20): separable least squares on the
heading driven by the measured rudder (zero-order hold, exact discretisation), refined by
``scipy.optimize.least_squares``; standard errors from the Jacobian."""

from __future__ import annotations

import math

import numpy as np

from .first_order_checks import T_BOUNDS, assess, equilibrated_condition
from .first_order_results import ZigzagFit


def _nomoto_basis(t, delta, T, r0):
    """Heading increments of the Nomoto model with K = 1 (g) and of the initial rate r0 (q), ZOH on delta."""
    from scipy.signal import lfilter

    h = np.diff(t)
    hm = float(np.mean(h))
    a = math.exp(-hm / T)
    d = delta[:-1]
    r = lfilter([0.0, 1.0 - a], [1.0, -a], d)  # r_k for K = 1, r_0 = 0, length n-1
    inc = d * hm + (r - d) * T * (1.0 - a)
    g = np.concatenate([[0.0], np.cumsum(inc)])
    k = np.arange(t.size - 1)
    q = np.concatenate([[0.0], np.cumsum(r0 * a**k * T * (1.0 - a))])
    return g, q


def fit_nomoto_zigzag(t, delta, psi, r0: float = 0.0, trial: int = 0, speed: float = float("nan")) -> ZigzagFit:
    """Least-squares (K, T) of ``T r' + r = K delta`` to a zig-zag trial's heading (rad) driven by delta (rad)."""
    from scipy.optimize import least_squares

    t = np.asarray(t, float)
    delta = np.asarray(delta, float)
    psi = np.unwrap(np.asarray(psi, float))
    h = np.diff(t)
    if np.any(np.abs(h - h.mean()) > 0.01 * h.mean()):
        tu = np.linspace(t[0], t[-1], t.size)
        idx = np.searchsorted(t, tu, side="right") - 1
        delta = delta[np.clip(idx, 0, t.size - 1)]
        psi = np.interp(tu, t, psi)
        t = tu
    y = psi - psi[0]

    def k_of(T):
        g, q = _nomoto_basis(t, delta, T, r0)
        gg = float(g @ g)
        K = float(g @ (y - q)) / gg if gg > 0 else 0.0
        return K, g, q

    def cost(T):
        K, g, q = k_of(T)
        e = K * g + q - y
        return float(e @ e)

    grid = np.geomspace(0.05, 100.0, 80)
    c = [cost(T) for T in grid]
    T0 = float(grid[int(np.argmin(c))])
    K0, _, _ = k_of(T0)

    def resid(p):
        g, q = _nomoto_basis(t, delta, p[1], r0)
        return p[0] * g + q - y

    lo, hi = T_BOUNDS
    sol = least_squares(resid, [K0, T0], bounds=([-np.inf, lo], [np.inf, hi]), x_scale="jac")
    J = sol.jac
    res = sol.fun
    dof = max(1, res.size - 2)
    s2 = float(res @ res) / dof
    try:
        cov = s2 * np.linalg.inv(J.T @ J)
        ks, ts = math.sqrt(max(cov[0, 0], 0.0)), math.sqrt(max(cov[1, 1], 0.0))
    except np.linalg.LinAlgError:
        ks = ts = float("nan")
    # the zig-zag's heading amplitude: heading change at the rudder reversals (ITTC: equals the rudder angle)
    rev = np.nonzero(np.diff(np.sign(delta)) != 0)[0] + 1
    rev = rev[np.abs(delta[rev - 1]) > 0]
    amp = math.degrees(float(np.mean(np.abs(y[rev])))) if rev.size else float("nan")
    T = float(sol.x[1])
    at_bound = None
    if T <= lo * 1.01 or T >= hi * 0.99:
        side, b = ("lower", lo) if T <= lo * 1.01 else ("upper", hi)
        at_bound = f"T = {T:.4g} s at its {side} bound {b:g} s"
    checks = assess(t, y, res, float(sol.x[0]), T, equilibrated_condition(J), float(np.mean(np.diff(t))), at_bound)
    return ZigzagFit(
        trial,
        speed,
        round(amp, 1),
        float(np.max(np.abs(delta))),
        float(sol.x[0]),
        float(sol.x[1]),
        ks,
        ts,
        math.degrees(math.sqrt(float(np.mean(res**2)))),
        checks,
    )
