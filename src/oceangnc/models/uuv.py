"""UUV of document 003 ch. 2.2: a 1.79 m x 0.25 m torpedo, Fossen 6-DOF model with REMUS-100 coefficients.

Equations of motion (003 eq. 2.15 and appendix A; Fossen 2011 ch. 6-8), origin at the centre of
buoyancy (CB), body axes x forward / y starboard / z down, written on the velocity relative to a
uniform, irrotational current nu_r = nu - [R^T v_c; 0] (003 eq. 2.12):

    M_RB nu' + C_RB(nu) nu + M_A nu_r' + C_A(nu_r) nu_r + D(nu_r) nu_r + g(eta) = tau + tau_cable

with eta' = J(eta) nu (003 eq. 2.13, A-1, A-2; zyx Euler angles). For a current fixed in the earth
frame nu_r' = nu' + [omega x v_cb; 0], so the mass matrix M = M_RB + M_A (A-3, A-7, A-9) is constant
and its inverse is computed once (in :meth:`UUVConfig.params`).

* **Coriolis** (A-8, A-10): both C_RB and C_A are taken in the skew-symmetric momentum form of
  Fossen 2011 eq. 6.43/6.44, C(nu) nu = [omega x p1; v x p1 + omega x p2] with p = M nu; for the
  diagonal M_A this is exactly A-10 and it produces the Munk moments, so the ideal-fluid part of the
  model conserves kinetic energy (tested).
* **Damping** D(nu_r) (A-11, A-12): diagonal linear terms (design values, small: all of Prestero's
  terms vanish at zero speed), diagonal quadratic cross-flow drag X_u|u|, Y_v|v|, Z_w|w|, K_p|p|,
  M_q|q|, N_r|r|, and the speed-proportional body-lift and fin terms of Prestero (Y_uv, Y_ur, Z_uw,
  Z_uq, M_uw, M_uq, N_uv, N_ur) with their added-mass parts removed (they are already in C_A):
  Prestero's totals minus Munk/added-mass cross terms, e.g. N_uv,lift = N_uv - (Y_vdot - X_udot).
  These lift terms are multiplied by |u_r| (not u_r), which keeps them dissipative in reverse;
  their quadratic form is negative definite for the coefficients below (checked in the tests).
* **Restoring** g(eta) (A-13) with weight W = m g and buoyancy B = W - (submerged weight).
* **Thrusters** (003 eq. 2.17, thrust curve 2.18 in :mod:`oceangnc.models.actuators`): two stern
  thrusters X = T_p + T_s and a lateral bow thruster at x = +B_f: Y = T_b, N = T_b B_f. Eq. 2.17
  prints Y = 0 and no stern differential moment; a lateral thruster does push sideways, and the
  stern thrusters sit on pods half a spacing off the centre line, so here also
  N += (T_p - T_s) b_s / 2 (b_s = stern thruster spacing, design value).
* **Cable** (003 eq. 2.32-2.33): an earth-frame force F_n at the tow point r_c (body frame) adds
  F_b = R^T F_n and r_c x F_b.

Coefficients: Prestero 2001 (T. Prestero, *Verification of a six-degree of freedom simulation model
for the REMUS autonomous underwater vehicle*, MIT/WHOI MSc thesis, table 4-? "summary of
hydrodynamic coefficients" as re-tabulated by Hall & Anstee 2011, DSTO-TR-2576) for REMUS-100
(L = 1.33 m, d = 0.191 m, m = 30.48 kg), scaled to this vehicle by geometric similarity with
s_L = 1.79 / 1.33 and s_d = 0.25 / 0.191: each coefficient is multiplied by s_L^a s_d^b with (a, b)
taken from its physical form (added mass ~ rho d^2 L, cross-flow drag ~ rho d L, axial drag ~
rho d^2, moment arms one more power of L each); see :data:`REMUS_PRESTERO` and :func:`scaled_coefficients`.
Mass properties (003 table 2-5): 30 kg in air, 12 kg in water (negatively buoyant); inertias of a
uniform cylinder; the centre of gravity 2 cm below the CB (REMUS-100: z_g = 1.96 cm).

State layout ``x = [x, y, z, phi, theta, psi, u, v, w, p, q, r]`` (m, rad, m/s, rad/s; NED
position of the CB and zyx Euler angles); the parameter layout :data:`LAYOUT` is generated from the
declared names (the ``P_*`` offsets used by compiled code are taken from it). :func:`uuv_model` is the
:class:`~oceangnc.core.model.Model` (plant, trim, linearisation and EKF); the right-hand side is
written with :mod:`oceangnc.core.csmath`, so complex-step Jacobians are exact.
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit

from ..core.blocks import Plant
from .actuators import ThrusterBank
from ..core.csmath import cabs
from ..core.model import Model
from ..core.rotations import heading_speed
from ..core.signals import CALM
from ..errors import InputError
from ..units import KGF
from .rigid_body import euler_kinematics, restoring
from .rigid_body import kirchhoff as _kirchhoff
from .rigid_body import row6 as _row
from ._uuv_params import *  # noqa: F403  (re-exported: the old import paths keep working)
from ._uuv_params import (
    INPUTS,
    INPUT_NAMES,
    LAYOUT,
    P_B,
    P_BOW_X,
    P_DLIN,
    P_DQUAD,
    P_LIFT,
    P_MA,
    P_MINV,
    P_MRB,
    P_RB,
    P_RC,
    P_RG,
    P_STERN_HALF,
    P_W,
    STATES,
    UUVConfig,
)

# constants as numpy scalars, not Python literals: numba compiles a callee once per *literal* argument value
_FALSE, _MRB, _MA = np.bool_(False), np.int64(P_MRB), np.int64(P_MA)


@njit(cache=True)
def uuv_deriv(x, out, p, tp, ts, tb, vcn, vce, fn_x, fn_y, fn_z):
    """Write d/dt of the 12 UUV states ``x`` into ``out``.

    ``tp, ts, tb``: port, starboard and bow thrust (N); ``vcn, vce``: current (m/s, NED, toward);
    ``fn_*``: earth-frame force (N) acting at the tow point p[P_RC:P_RC+3] (the cable, 003 eq. 2.32).
    """
    uuv_deriv_flow(x, out, p, tp, ts, tb, vcn, vce, 0.0, 0.0, 0.0, 0.0, 0.0, fn_x, fn_y, fn_z, _FALSE)


@njit(cache=True)
def uuv_deriv_flow(x, out, p, tp, ts, tb, vcn, vce, vcd, awn, awe, awd, mdisp, fn_x, fn_y, fn_z, waves):
    """:func:`uuv_deriv` in a flow that varies in time (issue 29): with ``waves``, the flow velocity
    (``vcn, vce, vcd``: current plus wave orbital velocity at the centre of buoyancy, NED, m/s) has a
    vertical part too, and its acceleration ``a_w = (awn, awe, awd)`` (m/s^2, NED) adds the long-wave
    Morison force of a body small against the wave length (DNV-RP-C205 eq. 6.2.1 for a small volume;
    Fossen 2011 sec. 10.3 for the relative-velocity form):

        tau_w = (rho V [I 0] + M_A) [R^T a_w; 0]

    i.e. the Froude-Krylov force rho V a_w (``mdisp`` = rho V = B/g, kg) plus the added-mass reaction to
    the water's acceleration (diffraction neglected: the hull is 1.79 m against waves of 10 m and more).
    Without ``waves`` the arithmetic is exactly that of :func:`uuv_deriv` (the extra terms are skipped).
    """
    u = x[6]
    v = x[7]
    w = x[8]
    pp = x[9]
    q = x[10]
    r = x[11]
    # kinematics (003 eq. 2.13, A-1, A-2) and R_b^n (Fossen eq. 2.18)
    r00, r01, r02, r10, r11, r12, r20, r21, r22, cf, sf, ct, st = euler_kinematics(x, out)
    # current in body axes (R^T v_c), relative velocity
    ucb = r00 * vcn + r10 * vce
    vcb = r01 * vcn + r11 * vce
    wcb = r02 * vcn + r12 * vce
    if waves:  # the vertical part of the flow
        ucb += r20 * vcd
        vcb += r21 * vcd
        wcb += r22 * vcd
    ur = u - ucb
    vr = v - vcb
    wr = w - wcb
    # generalised forces
    f0, f1, f2, f3, f4, f5 = _kirchhoff(p, _MRB, u, v, w, pp, q, r)
    a0, a1, a2, a3, a4, a5 = _kirchhoff(p, _MA, ur, vr, wr, pp, q, r)
    t0 = f0 + a0
    t1 = f1 + a1
    t2 = f2 + a2
    t3 = f3 + a3
    t4 = f4 + a4
    t5 = f5 + a5
    # -M_A [omega x v_cb; 0]  (relative acceleration of a current fixed in the earth frame)
    oc0 = q * wcb - r * vcb
    oc1 = r * ucb - pp * wcb
    oc2 = pp * vcb - q * ucb
    if oc0 != 0.0 or oc1 != 0.0 or oc2 != 0.0:
        b = P_MA
        t0 -= p[b + 0] * oc0 + p[b + 1] * oc1 + p[b + 2] * oc2
        t1 -= p[b + 6] * oc0 + p[b + 7] * oc1 + p[b + 8] * oc2
        t2 -= p[b + 12] * oc0 + p[b + 13] * oc1 + p[b + 14] * oc2
        t3 -= p[b + 18] * oc0 + p[b + 19] * oc1 + p[b + 20] * oc2
        t4 -= p[b + 24] * oc0 + p[b + 25] * oc1 + p[b + 26] * oc2
        t5 -= p[b + 30] * oc0 + p[b + 31] * oc1 + p[b + 32] * oc2
    if waves:  # (rho V [I 0] + M_A) [R^T a_w; 0]: Froude-Krylov and added mass in the accelerating flow
        ab0 = r00 * awn + r10 * awe + r20 * awd
        ab1 = r01 * awn + r11 * awe + r21 * awd
        ab2 = r02 * awn + r12 * awe + r22 * awd
        b = P_MA
        t0 += mdisp * ab0 + p[b + 0] * ab0 + p[b + 1] * ab1 + p[b + 2] * ab2
        t1 += mdisp * ab1 + p[b + 6] * ab0 + p[b + 7] * ab1 + p[b + 8] * ab2
        t2 += mdisp * ab2 + p[b + 12] * ab0 + p[b + 13] * ab1 + p[b + 14] * ab2
        t3 += p[b + 18] * ab0 + p[b + 19] * ab1 + p[b + 20] * ab2
        t4 += p[b + 24] * ab0 + p[b + 25] * ab1 + p[b + 26] * ab2
        t5 += p[b + 30] * ab0 + p[b + 31] * ab1 + p[b + 32] * ab2
    # damping and lift (Prestero), on the relative velocity
    d = P_DLIN
    e = P_DQUAD
    lf = P_LIFT
    au = cabs(ur)
    t0 += p[d] * ur + p[e] * ur * au
    t1 += p[d + 1] * vr + p[e + 1] * vr * cabs(vr) + (p[lf] * vr + p[lf + 1] * r) * au
    t2 += p[d + 2] * wr + p[e + 2] * wr * cabs(wr) + (p[lf + 2] * wr + p[lf + 3] * q) * au
    t3 += p[d + 3] * pp + p[e + 3] * pp * cabs(pp)
    t4 += p[d + 4] * q + p[e + 4] * q * cabs(q) + (p[lf + 4] * wr + p[lf + 5] * q) * au
    t5 += p[d + 5] * r + p[e + 5] * r * cabs(r) + (p[lf + 6] * vr + p[lf + 7] * r) * au
    # restoring forces
    g0, g1, g2, g3, g4, g5 = restoring(p, P_W, P_B, P_RG, P_RB, cf, sf, ct, st)
    t0 -= g0
    t1 -= g1
    t2 -= g2
    t3 -= g3
    t4 -= g4
    t5 -= g5
    # thrusters (003 eq. 2.17)
    t0 += tp + ts
    t1 += tb
    t5 += (tp - ts) * p[P_STERN_HALF] + tb * p[P_BOW_X]
    # cable force at the tow point (003 eq. 2.32): F_b = R^T F_n, M_b = r_c x F_b
    if fn_x != 0.0 or fn_y != 0.0 or fn_z != 0.0:
        fbx = r00 * fn_x + r10 * fn_y + r20 * fn_z
        fby = r01 * fn_x + r11 * fn_y + r21 * fn_z
        fbz = r02 * fn_x + r12 * fn_y + r22 * fn_z
        cx = p[P_RC]
        cy = p[P_RC + 1]
        cz = p[P_RC + 2]
        t0 += fbx
        t1 += fby
        t2 += fbz
        t3 += cy * fbz - cz * fby
        t4 += cz * fbx - cx * fbz
        t5 += cx * fby - cy * fbx
    for i in range(6):
        out[6 + i] = _row(p, P_MINV + 6 * i, t0, t1, t2, t3, t4, t5)


@njit(cache=True)
def uuv_rhs(t, x, u, p, out):
    """dx/dt of the UUV alone; inputs ``u = [T_port, T_stbd, T_bow, Vc_n, Vc_e]`` (N, m/s)."""
    uuv_deriv(x, out, p, u[0], u[1], u[2], u[3], u[4], 0.0, 0.0, 0.0)


def uuv_energy(x, p) -> float:
    """Mechanical energy (J) of the UUV in still water: 1/2 nu^T M nu plus the potential of W and B.

    The potential is -W z_G + B z_B (z down); conserved by the model when damping is off.
    """
    nu = np.asarray(x[6:12], float)
    M = p[P_MRB : P_MRB + 36].reshape(6, 6) + p[P_MA : P_MA + 36].reshape(6, 6)
    ke = 0.5 * nu @ M @ nu
    phi, th = x[3], x[4]
    # z-component of R r for r = (rx, ry, rz): -sin(th) rx + cos(th) sin(phi) ry + cos(th) cos(phi) rz
    rg = p[P_RG : P_RG + 3]
    rb = p[P_RB : P_RB + 3]
    zg = x[2] - math.sin(th) * rg[0] + math.cos(th) * math.sin(phi) * rg[1] + math.cos(th) * math.cos(phi) * rg[2]
    zb = x[2] - math.sin(th) * rb[0] + math.cos(th) * math.sin(phi) * rb[1] + math.cos(th) * math.cos(phi) * rb[2]
    return float(ke - p[P_W] * zg + p[P_B] * zb)


def uuv_model(cfg: UUVConfig | None = None, params=None, tow_point=(0.0, 0.0, 0.0)) -> Model:
    """The 6-DOF UUV of 003 ch. 2.2 as a :class:`~oceangnc.core.model.Model` (outputs = states)."""
    p = (cfg or UUVConfig()).params(tow_point) if params is None else np.asarray(params, dtype=np.float64)
    return Model(
        "uuv",
        uuv_rhs,
        STATES,
        INPUTS,
        LAYOUT,
        p,
        bound=1e6,
        description="003 1.79 m UUV, Fossen 6-DOF with scaled REMUS-100 coefficients",
    )


@njit(cache=True)
def uuv_planar_rhs(t, x, u, p, out):
    """d/dt [u, v, r] of the UUV in the horizontal plane with roll, pitch and heave held (level attitude).

    The held degrees of freedom take whatever constraint force keeps them at rest, so the surge, sway
    and yaw rows of M nu' = tau (M = M_RB + M_A, tau the 6-DOF generalised force of :func:`uuv_deriv`
    at w = p = q = 0, phi = theta = 0) give [u', v', r'] = M_sub^-1 tau_sub. Restoring terms are left to
    the caller's parameters (set W = B = 0 for the planar problem). Inputs as :func:`uuv_rhs`.
    """
    x12 = np.zeros(12, dtype=out.dtype)
    x12[6] = x[0]
    x12[7] = x[1]
    x12[11] = x[2]
    a = np.zeros(12, dtype=out.dtype)
    uuv_deriv(x12, a, p, u[0], u[1], u[2], u[3], u[4], 0.0, 0.0, 0.0)
    # tau = M a (rows 0, 1, 5), M_sub the (0, 1, 5) block of M
    rows = (0, 1, 5)
    tau = np.zeros(3, dtype=out.dtype)
    msub = np.zeros((3, 3), dtype=p.dtype)
    for i in range(3):
        ri = rows[i]
        s = a[6] * 0.0
        for j in range(6):
            s += (p[P_MRB + 6 * ri + j] + p[P_MA + 6 * ri + j]) * a[6 + j]
        tau[i] = s
        for j in range(3):
            msub[i, j] = p[P_MRB + 6 * ri + rows[j]] + p[P_MA + 6 * ri + rows[j]]
    inv = np.linalg.inv(msub)
    for i in range(3):
        out[i] = inv[i, 0] * tau[0] + inv[i, 1] * tau[1] + inv[i, 2] * tau[2]


def uuv_planar_model(cfg: UUVConfig | None = None) -> Model:
    """The UUV held level in the horizontal plane (states u, v, r), :func:`uuv_planar_rhs`; W = B = 0."""
    p = (cfg or UUVConfig()).params()
    p[P_W] = p[P_B] = 0.0  # level attitude held: no restoring terms in the planar problem
    return Model(
        "uuv-planar",
        uuv_planar_rhs,
        STATES[6:8] + STATES[11:],
        INPUTS,
        LAYOUT,
        p,
        description="UUV in the horizontal plane, roll, pitch and heave held",
    )


class UUVPlant(Plant):
    """The UUV alone (no cable) as a plant; publishes ``uuv.<states>``, ``uuv.speed`` (m/s)."""

    def __init__(self, cfg: UUVConfig, name: str = "uuv"):
        inputs = [k.replace("uuv.", f"{name}.") for k in INPUT_NAMES]
        super().__init__(
            **uuv_model(cfg).plant_args(name, cfg.initial_state(), inputs, declare=True),
            input_defaults=CALM,
            extra_outputs={f"{name}.speed": "m/s"},
        )
        self.cfg = cfg

    def publish(self, bus: dict) -> None:
        super().publish(bus)
        psi, speed = heading_speed(self.x, 5, 6, 3)
        bus[f"{self.name}.psi"] = psi
        bus[f"{self.name}.speed"] = speed


class UUVThrusters(ThrusterBank):
    """The UUV's three thrusters: commanded thrusts (N) -> saturated thrusts (N).

    Reads ``uuv.thrust_port_cmd``, ``uuv.thrust_stbd_cmd``, ``uuv.thrust_bow_cmd`` (N) and writes
    ``uuv.thrust_port``, ``uuv.thrust_stbd``, ``uuv.thrust_bow`` (N) limited to
    [-max_reverse, +max_thrust] (Tecnadyne 300: 7.7 kgf forward, 3.2 kgf reverse; curve 003 eq. 2.18
    in :func:`oceangnc.models.actuators.uuv_thrust_from_voltage`). An emergency stop (``_estop``)
    zeroes all three; the thrust ramps back over 2 s after it (:func:`oceangnc.models.actuators.thrusters_law`).
    """

    name = "uuv_thrusters"

    def __init__(self, cfg: UUVConfig, period: float = 0.01, body: str = "uuv"):
        hi, lo = cfg.max_thrust_kgf * KGF, -cfg.max_reverse_kgf * KGF
        super().__init__(body, ("port", "stbd", "bow"), hi, lo, period)


def uuv_steady_planar(
    cfg: UUVConfig, t_port: float, t_stbd: float, t_bow: float, jacobian: str | None = None, interpreted: bool = False
):
    """Steady (u, v, r) of the UUV in the horizontal plane for constant thrusts (N), calm water.

    Solves the surge, sway and yaw rows of the 6-DOF model with w = p = q = 0 and level attitude
    (roll/pitch held: :func:`uuv_planar_rhs`) by :func:`oceangnc.core.linearize.trim` (Newton, exact
    Jacobian, or ``jacobian``, one of :data:`oceangnc.core.jacobians.JACOBIAN_MODES`; ``interpreted``:
    the model's Python body, compiling nothing, with ``jacobian="finite-difference"``).
    """
    from ..core.linearize import trim

    u_guess = math.sqrt(max(abs(t_port + t_stbd), 1e-3) / max(1e-6, -cfg.X_uu_total))
    moment = (t_port - t_stbd) * 0.5 * cfg.stern_spacing + t_bow * cfg.bow_arm
    # no yaw moment: start on the straight-ahead branch (the vehicle is directionally unstable, so
    # spurious spiral equilibria exist; the symmetric start keeps Newton on v = r = 0)
    r_guess = 0.0 if moment == 0.0 else math.copysign(0.1, moment)
    try:
        res = trim(
            uuv_planar_model(cfg),
            [u_guess, 0.0, r_guess],
            [t_port, t_stbd, t_bow, 0.0, 0.0],
            free=("u", "v", "r"),
            zero=("u", "v", "r"),
            tol=1e-12,
            jacobian=jacobian,
            interpreted=interpreted,
        )
    except InputError as e:
        raise RuntimeError(f"uuv_steady_planar: no steady turn found ({e})") from None
    return float(res.x[0]), float(res.x[1]), float(res.x[2])


def uuv_min_turning_radius(cfg: UUVConfig) -> float:
    """Minimum turning radius (m) of the UUV: steady turn at full differential stern and full bow thrust.

    Port stern thruster at +max forward, starboard at -max reverse, bow thruster at +max (all turning
    to starboard); radius = U / |r| of the steady turn in the horizontal plane with roll and pitch
    held level (:func:`uuv_steady_planar`). The level attitude is what the cable and the low centre
    of gravity give in operation; the free, neutrally buoyant 6-DOF vehicle at full thrust is
    pitch-unstable (the Munk moment exceeds W z_G) and spirals down, which is no turning circle.
    Used by the pure-pursuit look-ahead l = 2 R_min (003 eq. 3.6).
    """
    hi, lo = cfg.max_thrust_kgf * KGF, cfg.max_reverse_kgf * KGF
    u, v, r = uuv_steady_planar(cfg, hi, -lo, hi)
    return float(math.hypot(u, v) / abs(r))
