"""Independent references for the physical checks of the validation registry.

* :func:`quasi_static_hang`: the UUV hanging in a uniform current on the continuous cable, solved
  without the lumped-mass model (shooting on the UUV's pitch balance, then the catenary-with-drag
  ODE up the unstretched arc length), 003 eq. 2.22-2.26.
* :func:`rk4_order`: observed order of the shipped RK4 on a harmonic oscillator.
* :func:`cable_energy_errors`: energy drift of the conservative cable + UUV pendulum at two steps.
* :func:`cable_energy_dissipation`: energy history with drag and damping on.
* :func:`uuv_steady_speed`: the UUV's steady surge speed under a constant force against
  ``X_u U + X_u|u| U|U| + F = 0``.
* :func:`backstepping_lyapunov`: V and dV/dt along the closed-loop nominal 3-DOF model behind a
  manoeuvring leader (003 eq. 3.28, 3.35-3.39 as re-derived in docs/combined-vehicle.md).
"""

from __future__ import annotations

import math

import numpy as np

from ..units import G


def quasi_static_hang(
    current: float, theta_hint: float, uuv_over: dict | None = None, cable_over: dict | None = None
) -> dict:
    """Continuous quasi-static equilibrium of the UUV (heading into the current, at rest) on the cable.

    1. The UUV feels its steady hydrodynamic force at pitch theta (drag, lift and the Munk moment
       (X_udot - Z_wdot) u_r w_r, from the config's coefficients), its net weight and the cable force
       at the tow point; theta solves the pitch-moment balance (brentq, root nearest the hint).
    2. The cable force at the tow point starts dT/ds = -(w z_hat + drag(T_hat)),
       dr/ds = T_hat (1 + |T|/EA) (003 eq. 2.22, 2.24-2.26), integrated (adaptive RK45, tol 1e-10)
       over the unstretched length.

    Returns top and bottom tension (N), angle of the end-to-end line from vertical (deg), UUV pitch (deg).
    """
    from scipy.integrate import solve_ivp
    from scipy.optimize import brentq

    from ..models.cable import CableConfig, loading_functions
    from ..models.uuv import UUVConfig

    uc = UUVConfig(**{**(uuv_over or {}), "psi0_deg": 180.0})
    cc = CableConfig(**(cable_over or {}))
    c = uc.coefficients()
    lf = uc.lift_coefficients()
    W, B = uc.weight, uc.buoyancy
    rc = np.array(cc.tow_point)
    vc = np.array([current, 0.0, 0.0])

    def rot(theta):
        ct, st = math.cos(theta), math.sin(theta)
        Ry = np.array([[ct, 0, st], [0, 1, 0], [-st, 0, ct]])
        Rz = np.array([[-1.0, 0, 0], [0, -1.0, 0], [0, 0, 1]])
        return Rz @ Ry

    def loads(theta):
        R = rot(theta)
        ur, vr, wr = R.T @ (-vc)
        au = abs(ur)
        X = uc.X_u * ur + uc.X_uu_total * ur * au
        Z = uc.Z_w * wr + c["Z_ww"] * wr * abs(wr) + lf["Z_uw"] * au * wr
        M = lf["M_uw"] * au * wr + (c["X_udot"] - c["Z_wdot"]) * ur * wr - uc.zg * W * math.sin(theta)
        f_cable_n = -(R @ np.array([X, 0.0, Z]) + np.array([0.0, 0.0, W - B]))
        fb = R.T @ f_cable_n
        return M + rc[2] * fb[0] - rc[0] * fb[2], f_cable_n

    grid = np.radians(np.linspace(-85, 85, 341))
    res = [loads(t)[0] for t in grid]
    roots = [
        brentq(lambda t: loads(t)[0], a, b)
        for a, b, fa, fb in zip(grid[:-1], grid[1:], res[:-1], res[1:])
        if fa * fb < 0
    ]
    theta = min(roots, key=lambda t: abs(t - theta_hint))
    _, T0 = loads(theta)
    w = cc.weight_per_length
    k = 0.5 * cc.rho_water * cc.cd * cc.diameter
    EA = cc.EA

    def f(s, y):
        T = y[:3]
        tn = np.linalg.norm(T)
        t = T / tn
        V = -vc
        vq = V @ t
        Vp = V - vq * t
        vp = np.linalg.norm(Vp)
        eta = math.atan2(vp, abs(vq))
        fp, fq = loading_functions(eta)
        drag = -k * (V @ V) * (fp * (Vp / vp if vp > 0 else 0 * Vp) + fq * np.sign(vq) * t)
        return np.concatenate([-(np.array([0.0, 0.0, w]) + drag), t * (1 + tn / EA)])

    sol = solve_ivp(f, (0.0, cc.length), np.concatenate([T0, np.zeros(3)]), rtol=1e-10, atol=1e-10)
    d = sol.y[3:, -1]
    return {
        "top_tension_N": float(np.linalg.norm(sol.y[:3, -1])),
        "bottom_tension_N": float(np.linalg.norm(T0)),
        "angle_deg": math.degrees(math.atan2(math.hypot(d[0], d[1]), -d[2])),
        "pitch_deg": math.degrees(theta),
    }


def rk4_order(dts=(0.04, 0.02, 0.01)) -> tuple[list[float], list[float]]:
    """Errors of the shipped :func:`oceangnc.core.integrators.rk4_advance` on x'' = -w^2 x (w = 2 rad/s,
    x(0) = 1, 2 s) at each step, and the observed orders log2(e_k / e_k+1)."""
    from numba import njit

    from ..core.integrators import rk4_advance, rk4_workspace

    @njit(cache=False)
    def osc(t, x, u, p, out):
        out[0] = x[1]
        out[1] = -p[0] * p[0] * x[0] + u[0]

    errs = []
    for dt in dts:
        x = np.array([1.0, 0.0])
        rk4_advance(osc, 0.0, x, np.zeros(1), np.array([2.0]), dt, int(round(2.0 / dt)), rk4_workspace(2))
        errs.append(abs(x[0] - math.cos(4.0)))
    return errs, [math.log2(errs[i] / errs[i + 1]) for i in range(len(errs) - 1)]


def _conservative_plant(uuv_over=None, cable_over=None):
    from ..models.cable import CableConfig
    from ..models.combined import CombinedPlant
    from ..models.usv import USVConfig
    from ..models.uuv import UUVConfig

    cc = CableConfig(**{**(cable_over or {}), "drag_on": False, "damping": 0.0, "added_mass_coeff": 0.0})
    uc = UUVConfig(**{**(uuv_over or {}), "damping_on": False, "x0": 0.6, "z0": 3.166})
    return CombinedPlant(USVConfig(), uc, cc, top="fixed")


def cable_energy_errors(fracs=(0.2, 0.1), t_end=10.0, uuv_over=None, cable_over=None) -> dict:
    """Largest |E(t) - E(0)| over ``t_end`` s of the swinging, bouncing cable + UUV with drag, damping
    and cable added mass off, at each step fraction of the stability limit; plus the histories."""
    errs, hist = [], []
    for frac in fracs:
        pl = _conservative_plant(uuv_over, cable_over)
        dt = frac * pl.stability_limit
        e0 = pl.energy()
        t, ts, es = 0.0, [0.0], [0.0]
        for _ in range(int(round(t_end / 0.1))):
            t = pl.advance(t, dt, max(1, int(round(0.1 / dt))))
            ts.append(t)
            es.append(pl.energy() - e0)
        errs.append(float(np.max(np.abs(es))))
        hist.append((np.array(ts), np.array(es)))
    return {"errors": errs, "history": hist, "scale": 12.0 * G * 0.6}


def cable_energy_dissipation(integrator="rk4", t_end=10.0, uuv_over=None, cable_over=None) -> dict:
    """Energy history (J) with drag, axial damping and UUV damping on (cable added mass off)."""
    from ..models.cable import CableConfig
    from ..models.combined import CombinedPlant
    from ..models.usv import USVConfig
    from ..models.uuv import UUVConfig

    cc = CableConfig(**{**(cable_over or {}), "added_mass_coeff": 0.0, "integrator": integrator})
    pl = CombinedPlant(USVConfig(), UUVConfig(**{**(uuv_over or {}), "x0": 0.6, "z0": 2.9}), cc, top="fixed")
    dt = 0.8 * pl.stability_limit
    t, ts, es = 0.0, [0.0], [pl.energy()]
    for _ in range(int(round(t_end / 0.05))):
        t = pl.advance(t, dt, max(1, int(round(0.05 / dt))))
        ts.append(t)
        es.append(pl.energy())
    es = np.array(es)
    return {"t": np.array(ts), "E": es, "max_rise": float(np.max(np.diff(es))), "drop": float(es[0] - es[-1])}


def uuv_steady_speed(force: float, t_end: float = 120.0, uuv_over: dict | None = None) -> tuple[float, float, tuple]:
    """Simulated steady surge speed (m/s) of the neutrally buoyant UUV under a constant force ``force`` (N)
    split on its two stern thrusters, the speed solving ``X_u U + X_u|u| U|U| + F = 0``, and the history."""
    from ..core.integrators import rk4_advance, rk4_workspace
    from ..models.uuv import UUVConfig, uuv_rhs

    cfg = UUVConfig(**{**(uuv_over or {}), "weight_in_water_kgf": 0.0})
    p = cfg.params()
    x = cfg.initial_state()
    w = rk4_workspace(12)
    ts, us = [0.0], [x[6]]
    dt, chunk = 0.01, 1.0
    t = 0.0
    for _ in range(int(round(t_end / chunk))):
        rk4_advance(uuv_rhs, t, x, np.array([force / 2, force / 2, 0.0, 0.0, 0.0]), p, dt, int(round(chunk / dt)), w)
        t += chunk
        ts.append(t)
        us.append(x[6])
    a, b = -cfg.X_uu_total, -cfg.X_u
    u_pred = (-b + math.sqrt(b * b + 4 * a * force)) / (2 * a)
    return float(x[6]), u_pred, (np.array(ts), np.array(us))


def _leader(t):
    return (
        0.6 + 0.1 * math.sin(0.2 * t),
        0.02 * math.sin(0.3 * t),
        0.1 * math.sin(0.1 * t),
        0.02 * math.cos(0.2 * t),
        0.006 * math.cos(0.3 * t),
        0.01 * math.cos(0.1 * t),
    )


def fd_derivative(y: np.ndarray, h: float) -> np.ndarray:
    """dy/dt of a uniformly sampled series by fourth-order central differences (second-order one-sided
    :func:`numpy.gradient` at the two samples at each end). Truncation error h^4 |y^(5)| / 30 inside."""
    d = np.gradient(y, h, edge_order=2)
    d[2:-2] = (y[:-4] - 8 * y[1:-3] + 8 * y[3:-1] - y[4:]) / (12 * h)
    return d


def backstepping_lyapunov(
    s0=(0, 0, 0, -2.0, 1.5, 0.5, 0, 0, 0),
    t_end=60.0,
    uuv_over=None,
    bs_over=None,
    plant_over=None,
    h=0.01,
) -> dict:
    """The closed-loop nominal 3-DOF UUV (eq. 3.32, d22 v read) behind a leader with varying speed and
    yaw rate (solve_ivp, rtol 1e-9), logged every ``h`` s: V(t) along the simulated trajectory, its
    derivative from the log (:func:`fd_derivative`, and the same at 2h for the truncation estimate), and
    the re-derived formula dV/dt = -k1 e1^2 - k2 e2^2 - k6 u_e^2 - k7 r_e^2 evaluated on the logged states.

    ``plant_over`` changes the plant's UUV config only (the controller keeps the model of ``uuv_over``):
    with a mismatch the formula no longer describes the trajectory, which the checks must then show.
    """
    from scipy.integrate import solve_ivp

    from ..control.backstepping import (
        BacksteppingConfig,
        control_law,
        errors,
        model_from_uuv,
    )
    from ..models.uuv import UUVConfig

    g = BacksteppingConfig(**(bs_over or {}))
    m = model_from_uuv(UUVConfig(**(uuv_over or {})))
    mp = model_from_uuv(UUVConfig(**{**(uuv_over or {}), **(plant_over or {})})) if plant_over else m
    cx, cy = -0.5 + g.h, 0.0

    def law(t, s):
        xl, yl, psil, xf, yf, psif, u, v, r = s
        ul, vl, rl, dul, dvl, drl = _leader(t)
        e1, e2, ep = errors(xl, yl, psil, xf, yf, psif, cx, cy, g.h)
        return control_law(m, g, e1, e2, ep, u, v, r, ul, vl, rl, dul, dvl, drl, cx, cy)

    def rhs(t, s):
        xl, yl, psil, xf, yf, psif, u, v, r = s
        ul, vl, rl = _leader(t)[:3]
        o = law(t, s)
        du, dv, dr = mp.accel(u, v, r, o["tau_u"], o["tau_r"])
        cl, sl, cf, sf = math.cos(psil), math.sin(psil), math.cos(psif), math.sin(psif)
        return [ul * cl - vl * sl, ul * sl + vl * cl, rl, u * cf - v * sf, u * sf + v * cf, r, du, dv, dr]

    n = int(round(t_end / h))
    t = np.linspace(0.0, n * h, n + 1)
    sol = solve_ivp(rhs, (0.0, t[-1]), list(s0), t_eval=t, rtol=1e-9, atol=1e-11, max_step=0.05)
    out = [law(t[k], sol.y[:, k]) for k in range(len(t))]
    V = np.array([o["V"] for o in out])
    Vd = np.array([o["Vdot"] for o in out])
    num = fd_derivative(V, h)
    num2 = np.full_like(num, np.nan)
    num2[::2] = fd_derivative(V[::2], 2 * h)
    # fourth order: D(2h) - D(h) = 15 x the error of D(h) (Richardson); interior points of both grids
    trunc = np.abs(num2 - num)[4:-4:2] / 15.0
    return {"t": t, "V": V, "Vdot": Vd, "Vdot_num": num, "trunc_max": float(np.nanmax(trunc))}
