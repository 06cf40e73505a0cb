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
from pydantic import Field

from ..core.blocks import Block, Plant
from ..core.csmath import cabs, ccos, csin
from ..core.model import Model, Param, ParamLayout
from ..core.rotations import rzyx_entries
from ..core.signals import CALM
from ..errors import InputError
from ..io.config import StrictModel
from ..units import KGF, RHO_WATER, G
from .actuators import UUV_T_FWD_N, UUV_T_REV_N

STATE_NAMES = ("x", "y", "z", "phi", "theta", "psi", "u", "v", "w", "p", "q", "r")
INPUT_NAMES = ("uuv.thrust_port", "uuv.thrust_stbd", "uuv.thrust_bow", "env.current_n", "env.current_e")

#: REMUS-100 coefficients of Prestero (2001) (SI, SNAME names; "uu" = u|u|), and the exponents
#: (a, b) of the length and diameter scale factors used to carry them to this vehicle.
REMUS_PRESTERO = {
    # added mass
    "X_udot": (-0.93, 1, 2),
    "Y_vdot": (-35.5, 1, 2),
    "Z_wdot": (-35.5, 1, 2),
    "K_pdot": (-0.0704, 1, 4),
    "M_qdot": (-4.88, 3, 2),
    "N_rdot": (-4.88, 3, 2),
    "Y_rdot": (1.93, 2, 2),
    "Z_qdot": (-1.93, 2, 2),
    "M_wdot": (-1.93, 2, 2),
    "N_vdot": (1.93, 2, 2),
    # quadratic (cross-flow and axial) drag
    "X_uu": (-1.62, 0, 2),
    "Y_vv": (-131.0, 1, 1),
    "Z_ww": (-131.0, 1, 1),
    "K_pp": (-0.130, 1, 4),
    "M_qq": (-188.0, 4, 1),
    "N_rr": (-94.0, 4, 1),
    # totals of body lift, fin lift and added-mass cross terms (Munk moment etc.)
    "Y_uv": (-28.6, 0, 2),
    "Z_uw": (-28.6, 0, 2),
    "M_uw": (24.0, 1, 2),
    "N_uv": (-24.0, 1, 2),
    "Y_ur": (5.22, 1, 2),
    "Z_uq": (-5.22, 1, 2),
    "M_uq": (-2.0, 2, 2),
    "N_ur": (-2.0, 2, 2),
}
REMUS_LENGTH = 1.33  # m, Prestero 2001 table 2-1 (1.33 m)
REMUS_DIAMETER = 0.191  # m

STATES = (
    ("x", "m"),
    ("y", "m"),
    ("z", "m"),
    ("phi", "rad"),
    ("theta", "rad"),
    ("psi", "rad"),
    ("u", "m/s"),
    ("v", "m/s"),
    ("w", "m/s"),
    ("p", "rad/s"),
    ("q", "rad/s"),
    ("r", "rad/s"),
)
INPUTS = (("thrust_port", "N"), ("thrust_stbd", "N"), ("thrust_bow", "N"), ("current_n", "m/s"), ("current_e", "m/s"))
DLIN_NAMES = ("X_u", "Y_v", "Z_w", "K_p", "M_q", "N_r")
DQUAD_NAMES = ("X_uu", "Y_vv", "Z_ww", "K_pp", "M_qq", "N_rr")
LIFT_NAMES = ("Y_uv", "Y_ur", "Z_uw", "Z_uq", "M_uw", "M_uq", "N_uv", "N_ur")
_DLIN_UNITS = ("N s/m", "N s/m", "N s/m", "N m s", "N m s", "N m s")
_DQUAD_UNITS = ("kg/m", "kg/m", "kg/m", "kg m^2", "kg m^2", "kg m^2")
_LIFT_UNITS = ("kg/m", "kg", "kg/m", "kg", "kg", "kg m", "kg", "kg m")

#: parameter layout (003 appendix A), generated from the declared names
LAYOUT = ParamLayout(
    [
        Param("W", "N", description="weight m g"),
        Param("B", "N", description="buoyancy"),
        Param("r_g", "m", 3, description="centre of gravity (body axes, from the CB)"),
        Param("r_b", "m", 3, description="centre of buoyancy"),
        Param("M_RB", "kg, kg m, kg m^2", 36, description="rigid-body mass matrix, row-major (A-7)"),
        Param("M_A", "kg, kg m, kg m^2", 36, description="added-mass matrix, row-major (A-9)"),
        Param("M_inv", "1/kg ...", 36, derived=True, description="(M_RB + M_A)^-1, row-major"),
        *[Param(k, u, description="linear damping (A-11)") for k, u in zip(DLIN_NAMES, _DLIN_UNITS)],
        *[Param(k, u, description="quadratic damping (A-12)") for k, u in zip(DQUAD_NAMES, _DQUAD_UNITS)],
        *[Param(k, u, description="body/fin lift (Prestero) times |u_r|") for k, u in zip(LIFT_NAMES, _LIFT_UNITS)],
        Param("stern_half", "m", description="half the stern thruster spacing"),
        Param("bow_x", "m", description="bow thruster position ahead of the CB"),
        Param("r_c", "m", 3, description="tow point (body axes)"),
    ]
)
P_W, P_B, P_RG, P_RB, P_MRB, P_MA, P_MINV = LAYOUT.indices("W", "B", "r_g", "r_b", "M_RB", "M_A", "M_inv")
P_DLIN = LAYOUT.index(DLIN_NAMES[0])  # the six linear terms, consecutive
P_DQUAD = LAYOUT.index(DQUAD_NAMES[0])  # the six quadratic terms
P_LIFT = LAYOUT.index(LIFT_NAMES[0])  # the eight lift terms
P_STERN_HALF, P_BOW_X, P_RC = LAYOUT.indices("stern_half", "bow_x", "r_c")
NP = LAYOUT.size


def scaled_coefficients(length: float, diameter: float) -> dict[str, float]:
    """Prestero's REMUS-100 coefficients carried to a vehicle of ``length`` x ``diameter`` (m)."""
    sl = length / REMUS_LENGTH
    sd = diameter / REMUS_DIAMETER
    return {k: v * sl**a * sd**b for k, (v, a, b) in REMUS_PRESTERO.items()}


class UUVConfig(StrictModel):
    """UUV parameters (003 ch. 2.2, table 2-5) and initial state."""

    length: float = Field(1.79, gt=0, le=20, description="hull length (003 table 2-5), m")
    diameter: float = Field(0.25, gt=0, le=5, description="hull diameter (003 table 2-5), m")
    mass: float = Field(30.0, gt=0, le=1e4, description="mass in air (003 table 2-5), kg")
    weight_in_water_kgf: float = Field(
        12.0, ge=-1e3, le=1e4, description="submerged weight W - B (003 table 2-5; > 0 sinks), kgf"
    )
    zg: float = Field(0.02, ge=0.0, le=1.0, description="centre of gravity below the centre of buoyancy, m")
    Ixx: float | None = Field(
        None, gt=0, le=1e4, description="roll inertia about the CG (default: uniform cylinder), kg m2"
    )
    Iyy: float | None = Field(
        None, gt=0, le=1e5, description="pitch inertia about the CG (default: uniform cylinder), kg m2"
    )
    Izz: float | None = Field(
        None, gt=0, le=1e5, description="yaw inertia about the CG (default: uniform cylinder), kg m2"
    )
    X_u: float = Field(-1.0, ge=-1e4, le=0, description="linear surge damping X_u, N s/m")
    Y_v: float = Field(-10.0, ge=-1e4, le=0, description="linear sway damping Y_v, N s/m")
    Z_w: float = Field(-10.0, ge=-1e4, le=0, description="linear heave damping Z_w, N s/m")
    K_p: float = Field(-0.5, ge=-1e4, le=0, description="linear roll damping K_p, N m s")
    M_q: float = Field(-5.0, ge=-1e4, le=0, description="linear pitch damping M_q, N m s")
    N_r: float = Field(-5.0, ge=-1e4, le=0, description="linear yaw damping N_r, N m s")
    appendage_drag_area: float = Field(
        0.03,
        ge=0.0,
        le=10.0,
        description="C_d A of the external thrusters and fittings, added to X_u|u| as -rho C_d A / 2, m2",
    )
    drag_scale: float = Field(
        1.0, ge=0.0, le=100.0, description="multiplier on the quadratic drag and lift coefficients, -"
    )
    damping_on: bool = Field(True, description="hydrodynamic damping and lift (off only for energy checks)")
    stern_spacing: float = Field(0.3, ge=0, le=5, description="lateral spacing of the two stern thrusters, m")
    bow_arm: float = Field(0.7, ge=0, le=10, description="bow thruster position ahead of the CB, B_f, m")
    max_thrust_kgf: float = Field(UUV_T_FWD_N / KGF, gt=0, le=100, description="forward thrust limit, kgf")
    max_reverse_kgf: float = Field(-UUV_T_REV_N / KGF, ge=0, le=100, description="reverse thrust limit, kgf")
    rho_water: float = Field(RHO_WATER, gt=900, le=1100, description="water density, kg/m3")
    x0: float = Field(0.0, ge=-1e6, le=1e6, description="initial north position of the CB, m")
    y0: float = Field(0.0, ge=-1e6, le=1e6, description="initial east position of the CB, m")
    z0: float = Field(3.0, ge=-1.0, le=1e4, description="initial depth of the CB (003 ch. 4: 3 m), m")
    psi0_deg: float = Field(0.0, ge=-360, le=360, description="initial heading, deg")
    u0: float = Field(0.0, ge=-5, le=10, description="initial surge speed, m/s")

    def inertias(self) -> tuple[float, float, float]:
        """(Ixx, Iyy, Izz) in kg m2: given, else those of a uniform solid cylinder."""
        r = 0.5 * self.diameter
        ixx = self.Ixx if self.Ixx is not None else 0.5 * self.mass * r * r
        iyy = self.Iyy if self.Iyy is not None else self.mass * (3 * r * r + self.length**2) / 12.0
        izz = self.Izz if self.Izz is not None else iyy
        return ixx, iyy, izz

    def coefficients(self) -> dict[str, float]:
        """Scaled Prestero coefficients (see :func:`scaled_coefficients`), rho-corrected."""
        c = scaled_coefficients(self.length, self.diameter)
        k = self.rho_water / 1030.0  # Prestero used rho = 1030 kg/m3
        return {n: v * k for n, v in c.items()}

    def mass_matrices(self):
        """(M_RB, M_A) 6x6 (003 A-7, A-9); the inertias are taken about the CG and moved to the CB
        (the origin) by the parallel-axis theorem, I_b = I_g - m S(r_g)^2."""
        m = self.mass
        zg = self.zg
        ixx, iyy, izz = self.inertias()
        mrb = np.diag([m, m, m, ixx + m * zg * zg, iyy + m * zg * zg, izz]).astype(float)
        mrb[0, 4] = mrb[4, 0] = m * zg
        mrb[1, 3] = mrb[3, 1] = -m * zg
        c = self.coefficients()
        ma = np.diag([-c["X_udot"], -c["Y_vdot"], -c["Z_wdot"], -c["K_pdot"], -c["M_qdot"], -c["N_rdot"]])
        # symmetric coupling (Prestero: Y_rdot = N_vdot, Z_qdot = M_wdot)
        ma[1, 5] = ma[5, 1] = -c["Y_rdot"]
        ma[2, 4] = ma[4, 2] = -c["Z_qdot"]
        return mrb, ma

    def lift_coefficients(self) -> dict[str, float]:
        """Body/fin lift terms: Prestero's totals minus the added-mass (Munk) parts already in C_A."""
        c = self.coefficients()
        return {
            "Y_uv": c["Y_uv"],
            "Z_uw": c["Z_uw"],
            "Y_ur": c["Y_ur"] - c["X_udot"],
            "Z_uq": c["Z_uq"] + c["X_udot"],
            "M_uw": c["M_uw"] - (c["X_udot"] - c["Z_wdot"]),
            "N_uv": c["N_uv"] - (c["Y_vdot"] - c["X_udot"]),
            "M_uq": c["M_uq"] + c["Z_qdot"],
            "N_ur": c["N_ur"] - c["Y_rdot"],
        }

    @property
    def X_uu_total(self) -> float:
        """Axial quadratic drag X_u|u| (kg/m): scaled Prestero hull value plus the appendages."""
        return self.coefficients()["X_uu"] - 0.5 * self.rho_water * self.appendage_drag_area

    @property
    def weight(self) -> float:
        """W = m g (N)."""
        return self.mass * G

    @property
    def buoyancy(self) -> float:
        """B = W - submerged weight (N)."""
        return self.mass * G - self.weight_in_water_kgf * KGF

    def params(self, tow_point=(0.0, 0.0, 0.0)) -> np.ndarray:
        """Flat parameter array (layout :data:`LAYOUT`); ``tow_point`` is r_c in body axes (m)."""
        mrb, ma = self.mass_matrices()
        on = 1.0 if self.damping_on else 0.0
        c = self.coefficients()
        sc = self.drag_scale * on
        lf = self.lift_coefficients()
        v = {
            "W": self.weight,
            "B": self.buoyancy,
            "r_g": (0.0, 0.0, self.zg),
            "r_b": (0.0, 0.0, 0.0),
            "M_RB": mrb,
            "M_A": ma,
            "M_inv": np.linalg.inv(mrb + ma),
            "stern_half": 0.5 * self.stern_spacing,
            "bow_x": self.bow_arm,
            "r_c": tow_point,
        }
        v.update({k: getattr(self, k) * on for k in DLIN_NAMES})
        v.update(
            {
                k: q * sc
                for k, q in zip(DQUAD_NAMES, (self.X_uu_total, c["Y_vv"], c["Z_ww"], c["K_pp"], c["M_qq"], c["N_rr"]))
            }
        )
        v.update({k: lf[k] * sc for k in LIFT_NAMES})
        return LAYOUT.pack(v)

    def initial_state(self) -> np.ndarray:
        """x0 (12 states)."""
        return np.array(
            [self.x0, self.y0, self.z0, 0.0, 0.0, math.radians(self.psi0_deg), self.u0, 0.0, 0.0, 0.0, 0.0, 0.0]
        )


@njit(cache=True)
def _row(p, k, n0, n1, n2, n3, n4, n5):
    """Row product sum_j p[k + j] nu_j."""
    return p[k] * n0 + p[k + 1] * n1 + p[k + 2] * n2 + p[k + 3] * n3 + p[k + 4] * n4 + p[k + 5] * n5


@njit(cache=True)
def _kirchhoff(p, off, nu0, nu1, nu2, nu3, nu4, nu5):
    """Generalised Coriolis force -C(nu) nu = -[w x p1; v x p1 + w x p2], p = M nu (M at p[off:off+36]).

    Fossen 2011 eq. 6.43/6.44 (003 A-8, A-10): skew-symmetric, so it does no work.
    """
    m0 = _row(p, off, nu0, nu1, nu2, nu3, nu4, nu5)
    m1 = _row(p, off + 6, nu0, nu1, nu2, nu3, nu4, nu5)
    m2 = _row(p, off + 12, nu0, nu1, nu2, nu3, nu4, nu5)
    m3 = _row(p, off + 18, nu0, nu1, nu2, nu3, nu4, nu5)
    m4 = _row(p, off + 24, nu0, nu1, nu2, nu3, nu4, nu5)
    m5 = _row(p, off + 30, nu0, nu1, nu2, nu3, nu4, nu5)
    # omega = (nu3, nu4, nu5), v = (nu0, nu1, nu2)
    f0 = -(nu4 * m2 - nu5 * m1)
    f1 = -(nu5 * m0 - nu3 * m2)
    f2 = -(nu3 * m1 - nu4 * m0)
    f3 = -(nu1 * m2 - nu2 * m1) - (nu4 * m5 - nu5 * m4)
    f4 = -(nu2 * m0 - nu0 * m2) - (nu5 * m3 - nu3 * m5)
    f5 = -(nu0 * m1 - nu1 * m0) - (nu3 * m4 - nu4 * m3)
    return f0, f1, f2, f3, f4, f5


@njit(cache=True)
def uuv_deriv(x, out, p, tp, ts, tb, vcn, vce, fn_x, fn_y, fn_z):
    """Write d/dt of the 12 UUV states ``x`` into ``out``.

    ``tp, ts, tb``: port, starboard and bow thrust (N); ``vcn, vce``: current (m/s, NED, toward);
    ``fn_*``: earth-frame force (N) acting at the tow point p[P_RC:P_RC+3] (the cable, 003 eq. 2.32).
    """
    phi = x[3]
    th = x[4]
    psi = x[5]
    u = x[6]
    v = x[7]
    w = x[8]
    pp = x[9]
    q = x[10]
    r = x[11]
    cf = ccos(phi)
    sf = csin(phi)
    ct = ccos(th)
    st = csin(th)
    # R_b^n (Fossen eq. 2.18)
    r00, r01, r02, r10, r11, r12, r20, r21, r22 = rzyx_entries(phi, th, psi)
    # kinematics (003 eq. 2.13, A-1, A-2)
    out[0] = r00 * u + r01 * v + r02 * w
    out[1] = r10 * u + r11 * v + r12 * w
    out[2] = r20 * u + r21 * v + r22 * w
    out[3] = pp + (sf * q + cf * r) * st / ct
    out[4] = cf * q - sf * r
    out[5] = (sf * q + cf * r) / ct
    # current in body axes (R^T v_c), relative velocity
    ucb = r00 * vcn + r10 * vce
    vcb = r01 * vcn + r11 * vce
    wcb = r02 * vcn + r12 * vce
    ur = u - ucb
    vr = v - vcb
    wr = w - wcb
    # generalised forces
    f0, f1, f2, f3, f4, f5 = _kirchhoff(p, P_MRB, u, v, w, pp, q, r)
    a0, a1, a2, a3, a4, a5 = _kirchhoff(p, P_MA, ur, vr, wr, pp, q, r)
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
    W = p[P_W]
    B = p[P_B]
    xg = p[P_RG]
    yg = p[P_RG + 1]
    zg = p[P_RG + 2]
    xb = p[P_RB]
    yb = p[P_RB + 1]
    zb = p[P_RB + 2]
    wb = W - B
    t0 -= wb * st
    t1 += wb * ct * sf
    t2 += wb * ct * cf
    t3 -= -(yg * W - yb * B) * ct * cf + (zg * W - zb * B) * ct * sf
    t4 -= (zg * W - zb * B) * st + (xg * W - xb * B) * ct * cf
    t5 -= -(xg * W - xb * B) * ct * sf - (yg * W - yb * B) * st
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
        x = self.x
        bus[f"{self.name}.psi"] = float((x[5] + math.pi) % (2 * math.pi) - math.pi)
        bus[f"{self.name}.speed"] = float(math.sqrt(x[6] ** 2 + x[7] ** 2 + x[8] ** 2))


class UUVThrusters(Block):
    """Thruster block: commanded thrusts (N) -> saturated thrusts (N) of the three UUV thrusters.

    Reads ``uuv.thrust_port_cmd``, ``uuv.thrust_stbd_cmd``, ``uuv.thrust_bow_cmd`` (N) and writes
    ``uuv.thrust_port``, ``uuv.thrust_stbd``, ``uuv.thrust_bow`` (N) limited to
    [-max_reverse, +max_thrust] (Tecnadyne 300: 7.7 kgf forward, 3.2 kgf reverse; curve 003 eq. 2.18
    in :func:`oceangnc.models.actuators.uuv_thrust_from_voltage`). An emergency stop (``_estop``)
    zeroes all three.
    """

    name = "uuv_thrusters"

    def __init__(self, cfg: UUVConfig, period: float = 0.01, body: str = "uuv"):
        self.period = float(period)
        self.body = body
        self.hi = cfg.max_thrust_kgf * KGF
        self.lo = -cfg.max_reverse_kgf * KGF

    def compiled(self):
        """Compiled form for the fused loop (:func:`oceangnc.models._compiled.thrusters_step`)."""
        from ..core.fused import CompiledBlock
        from ._compiled import thrusters_step

        b = self.body
        sig = [
            "_estop",
            *(f"{b}.thrust_{s}_cmd" for s in ("port", "stbd", "bow")),
            *(f"{b}.thrust_{s}" for s in ("port", "stbd", "bow")),
        ]
        return CompiledBlock(thrusters_step, sig, params=np.array([3.0, self.hi, self.lo]))

    def step(self, t: float, bus: dict) -> None:
        b = self.body
        stop = bus.get("_estop", False)
        for side in ("port", "stbd", "bow"):
            thrust = 0.0 if stop else float(bus.get(f"{b}.thrust_{side}_cmd", 0.0))
            bus[f"{b}.thrust_{side}"] = min(self.hi, max(self.lo, thrust))


def uuv_steady_planar(cfg: UUVConfig, t_port: float, t_stbd: float, t_bow: float):
    """Steady (u, v, r) of the UUV in the horizontal plane for constant thrusts (N), calm water.

    Solves the surge, sway and yaw rows of the 6-DOF model with w = p = q = 0 and level attitude
    (roll/pitch held: :func:`uuv_planar_rhs`) by :func:`oceangnc.core.linearize.trim` (Newton, exact Jacobian).
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
    hi = cfg.max_thrust_kgf * KGF
    lo = cfg.max_reverse_kgf * KGF
    u, v, r = uuv_steady_planar(cfg, hi, -lo, hi)
    return float(math.hypot(u, v) / abs(r))
