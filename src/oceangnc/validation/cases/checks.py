"""Physical checks: RK4 order, cable energy conservation and dissipation, the UUV's steady speed, and the
backstepping Lyapunov function (computations in :mod:`oceangnc.validation.physics`)."""

from __future__ import annotations

from functools import partial

import numpy as np

from .. import Case, Measured
from ._common import D003, history, in_group


def rk4(r):
    from ..physics import rk4_order

    errs, orders = rk4_order()
    return Measured(
        min(orders),
        [("|error| at t = 2 s", [0.04, 0.02, 0.01], errs)],
        [("slope 4 reference", [0.04, 0.01], [errs[0], errs[0] / 4**4])],
        xlabel="dt [s]",
        ylabel="error",
        band=False,
        note=f"observed orders {', '.join(f'{o:.3f}' for o in orders)}",
    )


def _energy(r):
    from ..physics import cable_energy_errors

    return cable_energy_errors(uuv_over=r.section("uuv"), cable_over=r.section("cable"))


def energy_conservation(r):
    e = _energy(r)
    (t, ea), (_, eb) = e["history"]
    return history(
        e["errors"][0] / e["scale"],
        [("E - E0, dt = 0.2 limit", t, ea), ("E - E0, dt = 0.1 limit", t, eb)],
        "energy error [J]",
        band=False,
        note=f"max |E - E0| = {e['errors'][0]:.3e} J at 0.2 x limit, {e['errors'][1]:.3e} J at 0.1 x; "
        f"halving ratio {e['errors'][0] / e['errors'][1]:.1f}; scale 12 kgf x 0.6 m = {e['scale']:.1f} J",
    )


def energy_ratio(r):
    e = _energy(r)
    return Measured(
        e["errors"][0] / e["errors"][1],
        [("max |E - E0|", [0.2, 0.1], e["errors"])],
        xlabel="dt / stability limit",
        ylabel="energy error [J]",
        band=False,
    )


def dissipation(integrator, r):
    from ..physics import cable_energy_dissipation

    d = cable_energy_dissipation(integrator, uuv_over=r.section("uuv"), cable_over=r.section("cable"))
    return history(
        d["max_rise"] / abs(d["E"][0]),
        [("mechanical energy", d["t"], d["E"])],
        "E [J]",
        band=False,
        note=f"energy dissipated {d['drop']:.2f} J over {d['t'][-1]:.0f} s",
    )


def uuv_speed(force, r):
    from ..physics import uuv_steady_speed

    u, u_pred, (t, us) = uuv_steady_speed(force, uuv_over=r.section("uuv"))
    return history(
        u,
        [("UUV surge speed", t, us)],
        "u [m/s]",
        published=u_pred,
        note=f"drag balance X_u U + X_u|u| U|U| + F = 0 gives {u_pred:.4f} m/s at F = {force:g} N",
    )


def lyapunov(kind, r):
    """``kind``: "vdot" (largest dV/dt from finite differences of V along the simulated closed loop, over the
    peak |dV/dt|), "agree" (finite-difference dV/dt against the re-derived formula, over the peak |formula|)
    or "conv" (V(end) / V(0)). Interior samples only: the two at each end use second-order one-sided
    differences."""
    from ..physics import backstepping_lyapunov

    L = backstepping_lyapunov(uuv_over=r.section("uuv"))
    t, V, Vdot, num = L["t"], L["V"], L["Vdot"], L["Vdot_num"]
    inner = slice(2, -2)
    peak = float(np.abs(Vdot).max())
    trunc = f"truncation error of the differences ~ {L['trunc_max'] / peak:.1e} of the peak (Richardson, h vs 2h)"
    if kind == "vdot":
        series = [("V", t, V), ("dV/dt from V along the run (finite differences)", t, num)]
        value = float(num[inner].max() / np.abs(num[inner]).max())
        ylabel = "V, dV/dt"
        note = (
            f"largest finite-difference dV/dt {num[inner].max():.2e} (peak |dV/dt| {peak:.3f}); "
            f"V(0) = {V[0]:.3f}, V({t[-1]:.0f} s) = {V[-1]:.2e}; {trunc}"
        )
    elif kind == "agree":
        series = [("dV/dt formula", t, Vdot), ("dV/dt from V along the run", t, num)]
        value = float(np.abs(num - Vdot)[inner].max() / peak)
        ylabel, note = "dV/dt", trunc
    else:
        series = [("V / V(0)", t, V / V[0])]
        value, ylabel, note = float(V[-1] / V[0]), "V / V0", ""
    return history(value, series, ylabel, band=False, note=note)


_PENDULUM = "cable + UUV pendulum, drag and damping off"
_DISSIPATION = ("largest energy rise per 0.05 s / |E0|", "-", 0.0, "≤ 0", ("max", 1e-6), "round-off")
_BACKSTEPPING = "backstepping closed loop, nominal 3-DOF model"

CASES: list[Case] = in_group(
    "physics",
    Case(
        "physics-rk4-order",
        "RK4 convergence order",
        "Runge-Kutta 4 theory (harmonic oscillator, exact cos(w t))",
        "observed order (smallest of two halvings)",
        "-",
        4.0,
        "4",
        ("abs", 0.2),
        "asymptotic order 4; ±0.2 for the pre-asymptotic steps",
        rk4,
        kind="analytic",
    ),
    Case(
        "physics-energy-conservation",
        _PENDULUM,
        "conservation of mechanical energy (003 eq. 2.29 without dissipation)",
        "max |E - E0| / (12 kgf x 0.6 m)",
        "-",
        None,
        "0",
        ("max", 1e-5),
        "RK4 at 0.2 x the stability limit over 10 s",
        energy_conservation,
        kind="law",
    ),
    Case(
        "physics-energy-halving",
        _PENDULUM,
        "RK4 global error O(dt^4)",
        "energy error ratio at dt / (dt/2)",
        "-",
        16.0,
        "16 asymptotically",
        ("min", 8.0),
        "at least 2^3: fourth order with pre-asymptotic slack",
        energy_ratio,
        kind="analytic",
    ),
    Case(
        "physics-energy-dissipation-rk4",
        "cable + UUV with drag and damping, RK4",
        "second law: drag and damping only dissipate",
        *_DISSIPATION,
        partial(dissipation, "rk4"),
        kind="law",
    ),
    Case(
        "physics-energy-dissipation-split",
        "cable + UUV with drag and damping, split integrator",
        "second law",
        *_DISSIPATION,
        partial(dissipation, "rk4-split"),
        kind="law",
    ),
    Case(
        "physics-uuv-steady-speed",
        "UUV steady surge speed under 20 N",
        f"surge balance X_u U + X_u|u| U|U| + F = 0 ({D003} eq. 2.15-2.16, Prestero 2001 coefficients)",
        "steady surge speed",
        "m/s",
        None,
        "analytic (computed)",
        ("rel", 5e-3),
        "120 s leaves e^-k of the transient below 0.5 %",
        partial(uuv_speed, 20.0),
        kind="analytic",
    ),
    Case(
        "physics-lyapunov-vdot",
        _BACKSTEPPING,
        f"{D003} eq. 3.28, 3.35-3.39 (re-derived, docs/combined-vehicle.md): V never increases",
        "largest dV/dt from finite differences of V along the simulated run / peak |dV/dt|",
        "-",
        0.0,
        "≤ 0",
        ("max", 1e-6),
        "V logged every 10 ms along the solve_ivp run (rtol 1e-9), differentiated by fourth-order central "
        "differences: their truncation error is ~1e-7 of the peak rate (estimated in the note from h vs 2h); "
        "1e-6 is ten times that, so any rise of V the discretisation cannot explain fails",
        partial(lyapunov, "vdot"),
        kind="analytic",
        basis="Lyapunov: dV/dt = -k1 e1^2 - k2 e2^2 - k6 u_e^2 - k7 r_e^2 <= 0 on the nominal model",
    ),
    Case(
        "physics-lyapunov-derivative",
        _BACKSTEPPING,
        f"{D003} eq. 3.35-3.39 (re-derived): the formula for dV/dt is the derivative of V along the solution",
        "max |finite-difference dV/dt - formula| / peak |formula|",
        "-",
        0.0,
        "0",
        ("max", 1e-6),
        "the same 10 ms fourth-order differences (truncation ~1e-7 of the peak, note); a wrong derivation or a "
        "plant the formula does not describe (a 20 % model mismatch gives 3e-3 to 0.2) fails",
        partial(lyapunov, "agree"),
        kind="analytic",
        basis="the re-derived dV/dt evaluated on the logged states",
    ),
    Case(
        "physics-lyapunov-convergence",
        _BACKSTEPPING,
        "asymptotic stability",
        "V(60 s) / V(0)",
        "-",
        0.0,
        "→ 0",
        ("max", 1e-6),
        "exponential decay at the slowest gain over 60 s",
        partial(lyapunov, "conv"),
        kind="analytic",
        basis="asymptotic stability: V > 0 and dV/dt < 0 away from the origin on the nominal model",
    ),
)
