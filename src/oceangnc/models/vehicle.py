"""Your own vehicle: a 6-DOF marine craft in Fossen's matrix-vector form, defined in a TOML file.

Equations of motion (Fossen 2011 eq. 7.190 / Fossen 2021 ch. 6-7), origin CO, body axes x forward /
y starboard / z down, on the velocity relative to a uniform, irrotational current
nu_r = nu - [R^T v_c; 0]:

    M_RB nu' + C_RB(nu) nu + M_A nu_r' + C_A(nu_r) nu_r + D(nu_r) nu_r + g(eta) = tau

    eta' = J(eta) nu                                   (zyx Euler angles, Fossen eq. 2.40)

* M_RB: rigid-body mass matrix about CO with the centre of gravity at r_g (M_RB = H(r_g)^T M_CG
  H(r_g), Fossen eq. 3.44); M_A: added mass, diagonal or full 6 x 6 (positive: -X_udot, ...). Both
  must be symmetric and M_RB + M_A positive definite (checked; a file that is not is refused).
* C_RB, C_A: Kirchhoff's momentum form C(nu) nu = [w x p1; v x p1 + w x p2], p = M nu (Fossen eq.
  6.43-6.44, :func:`oceangnc.models.rigid_body.kirchhoff`): skew-symmetric, so with damping and
  thrust off and no restoring work the model conserves 1/2 nu^T M nu (tested). A file may neglect the
  Munk moment in yaw of C_A (``added_mass.munk_yaw_moment = false``, as Fossen's Otter model does:
  destabilising, balanced in reality by lift the model lacks). It is dropped with its partners, the
  surge and sway terms of the same translational added momentum m = M_A [nu_r; 0]: -(u_r m_1 - v_r m_0)
  in yaw, r m_1 in surge and -r m_0 in sway (C_A's entries (6, 1-2) and (1-2, 6) as a skew pair, as
  Fossen's otter.py zeroes them), so C_A stays skew-symmetric and kinetic energy is still conserved (tested).
* D(nu_r) nu_r = D_L nu_r + D_Q |nu_r| nu_r (diagonal) + |u_r| D_U nu_r + cross-flow drag: linear damping
  (full or diagonal), quadratic drag, a speed-proportional matrix for body lift and fins (the Prestero
  terms of the 003 UUV). Positive matrices oppose the motion (Fossen's sign convention: D > 0; the
  hydrodynamic derivatives are X_u = -D_L[0, 0] ...). The optional cross-flow drag (``[damping.crossflow]``)
  is the strip integral of the cross-flow drag principle (Fossen 2021, ch. 6, nonlinear damping; his
  Otter model uses it) over the hull length L with 2-D drag coefficient C_d (Hoerner 1965's curve of C_d against B / (2 T), or
  given):

      Y = -1/2 rho T C_d  int_L (v_r + x r)|v_r + x r| dx,    N = -1/2 rho T C_d  int_L x (v_r + x r)|v_r + x r| dx

  evaluated by the midpoint rule on n strips of width L / n (a fixed n; pure sway is then exact,
  Y = -1/2 rho T C_d L v_r|v_r|, and pure yaw of a hull centred on CO with n even is -1/2 rho T C_d
  (L^4 / 32)(1 - 2 / n^2) r|r| against the integral's L^4 / 32; both tested). It couples sway and yaw rate, which a diagonal
  D_Q cannot.
* g(eta): ``restoring = "submerged"``: weight W at r_g and buoyancy B at r_b (Fossen eq. 4.6, 003
  A-13); ``restoring = "linear"``: G eta with a 6 x 6 spring matrix (a surface craft: heave, roll,
  pitch stiffness rho g A_wp, rho g nabla GM_T, rho g nabla GM_L, Fossen eq. 4.50), eta's heave
  counted from the floating equilibrium; optionally plus a weight fixed to the vertical at r_p
  (``hydrostatics.body_axis_weight``, Fossen's Otter payload force g_0; ``apply = false`` by default).
* M_RB may be given by parts (``[[rigid_body.parts]]``, :mod:`oceangnc.models._mass_parts`): exact
  parallel-axis sum (default) or ``parallel_axis = "otter.py"``. The cross-flow sum may take Fossen's
  n + 1 stations of weight L / n instead of the midpoint rule (``damping.crossflow.rule = "stations"``).
* tau: thrusters i at positions r_i with unit directions d_i: F_i = T_i d_i, M_i = r_i x F_i. Each
  thrust T_i follows its command through saturation to [-max_reverse, max_forward] and, when its
  ``time_constant`` > 0, a first-order lag (an extra state); ``time_constant = 0`` applies it at once (its
  state then stays 0 and :class:`~oceangnc.models.vehicle_plant.VehiclePlant` publishes the applied thrust).

  A thruster with a ``[thrusters.shaft]`` table is driven by shaft speed instead: its state is n (rad/s),
  the thrust k n|n| (forward and reverse coefficients) with the lag on n (:mod:`oceangnc.models._shaft`).

State ``x = [x, y, z, phi, theta, psi, u, v, w, p, q, r, T_1 ... T_n]``; inputs ``[T_1_cmd ...
T_n_cmd (N), current_n, current_e (m/s)]``. The parameter vector has a fixed head (offsets are
compile-time constants of one right-hand side for every vehicle) and the thruster table at its end.
A vehicle file is read by :func:`load_vehicle` (a shipped name such as ``"bluerov2-heavy"`` or a path)
into :class:`VehicleFile` (units and ranges checked); :func:`vehicle_model` gives the
:class:`~oceangnc.core.model.Model` every tool takes (plant and fused loop, trim and linearisation,
the EKF by parameter name). docs/vehicles.md shows how to write one.
"""

from __future__ import annotations

import math
import tomllib
from importlib import resources
from pathlib import Path
from typing import Literal

import numpy as np
from numba import njit
from pydantic import Field, ValidationError, field_validator

from ..core.config import StrictModel, format_validation_error
from ..core.csmath import cabs
from ..core.model import Model, Param, ParamLayout
from ..errors import ConfigError
from ..units import G
from ._fins import F_X, F_Y, F_Z, FIN_FIELDS, NFIN, Fin, fin_force, fin_step
from ._surface import immersed_fraction, lost_buoyancy
from ._crossflow import HOERNER_B_2T, HOERNER_CD, CrossFlow, hoerner_cd  # noqa: F401 (re-exported)
from ._mass_parts import RigidBody
from ._shaft import SHAFT_FIELDS, Shaft, shaft_thrust
from .rigid_body import euler_kinematics, kirchhoff, restoring, row6

DOF_NAMES = ("surge", "sway", "heave", "roll", "pitch", "yaw")
THR_FIELDS = ("x", "y", "z", "dx", "dy", "dz", "max_forward", "max_reverse", "time_constant", *SHAFT_FIELDS)
NT = len(THR_FIELDS)  #: values per thruster in the parameter table

LAYOUT_HEAD = ParamLayout(
    [
        Param("W", "N", description="weight m g"),
        Param("B", "N", description="buoyancy rho g nabla"),
        Param("r_g", "m", 3, description="centre of gravity from CO (body axes)"),
        Param("r_b", "m", 3, description="centre of buoyancy from CO"),
        Param("linear_restoring", "1", description="1: g = G eta (surface craft), 0: W and B (submerged)"),
        Param("G_lin", "N/m, N, N m", 36, description="spring matrix of the linear restoring, row-major"),
        Param("M_RB", "kg, kg m, kg m^2", 36, description="rigid-body mass matrix about CO, row-major"),
        Param("M_A", "kg, kg m, kg m^2", 36, description="added-mass matrix, row-major"),
        Param("M_inv", "1/kg ...", 36, derived=True, description="(M_RB + M_A)^-1, row-major"),
        Param("D_L", "N s/m ...", 36, description="linear damping matrix (positive opposes motion)"),
        Param("D_Q", "kg/m, kg m^2", 6, description="quadratic drag, diagonal"),
        Param("D_U", "kg/m ...", 36, description="speed-proportional damping, times |u_r|"),
        Param(
            "munk_yaw",
            "1",
            description="1: keep the Munk moment in yaw of C_A, 0: neglect it with its surge/sway partners (Fossen's Otter)",
        ),
        Param("cf_coeff", "kg/m^2", description="cross-flow drag per unit length and U|U|: 1/2 rho C_d T (0: none)"),
        Param("cf_x0", "m", description="x of the first (aftmost) strip's centre from CO"),
        Param("cf_dx", "m", description="strip width L / n"),
        Param("cf_strips", "1", derived=True, description="number of cross-flow strips n (0: no cross-flow drag)"),
        Param("n_thrusters", "1", derived=True, description="number of thrusters in the table"),
        Param("hull_height", "m", description="height of the buoyancy ramp at the surface (0: no free surface)"),
        Param("thr_immersion", "m", description="height of a thruster's thrust ramp at the surface (0: none)"),
        Param(
            "W_p", "N", description="weight added as a body-axis force on top of G eta (otter.py's payload; 0: none)"
        ),
        Param("r_p", "m", 3, description="where W_p acts, from CO"),
        Param("n_fins", "1", derived=True, description="number of fins in the table after the thrusters"),
        Param("rho", "kg/m^3", description="water density of the fins' lift (hydrostatics.rho)"),
    ]
)
P_W, P_B, P_RG, P_RB, P_LINR, P_GLIN = LAYOUT_HEAD.indices("W", "B", "r_g", "r_b", "linear_restoring", "G_lin")
P_MRB, P_MA, P_MINV, P_DL, P_DQ, P_DU, P_MUNK, P_NTHR = LAYOUT_HEAD.indices(
    "M_RB", "M_A", "M_inv", "D_L", "D_Q", "D_U", "munk_yaw", "n_thrusters"
)
P_CFK, P_CFX0, P_CFDX, P_CFN = LAYOUT_HEAD.indices("cf_coeff", "cf_x0", "cf_dx", "cf_strips")
P_HH, P_TIMM = LAYOUT_HEAD.indices("hull_height", "thr_immersion")
P_WP, P_RP = LAYOUT_HEAD.indices("W_p", "r_p")
P_NFIN, P_RHO = LAYOUT_HEAD.indices("n_fins", "rho")
P_THR = LAYOUT_HEAD.size  #: the thruster table starts here: NT values per thruster (THR_FIELDS)
T_X, T_Y, T_Z, T_DX, T_DY, T_DZ, T_FWD, T_REV, T_TAU, T_SHAFT = range(10)


@njit(cache=True)
def vehicle_deriv(t, x, u, p, out):
    """dx/dt of the generic vehicle (module docstring) for state ``x`` and inputs ``u`` (thrust commands
    (N), then the earth-fixed current north, east (m/s))."""
    n = int(p[P_NTHR].real)
    uu = x[6]
    v = x[7]
    w = x[8]
    pp = x[9]
    q = x[10]
    r = x[11]
    r00, r01, r02, r10, r11, r12, r20, r21, r22, cf, sf, ct, st = euler_kinematics(x, out)
    nf = int(p[P_NFIN].real)
    vcn = u[n + nf]
    vce = u[n + nf + 1]
    ucb = r00 * vcn + r10 * vce
    vcb = r01 * vcn + r11 * vce
    wcb = r02 * vcn + r12 * vce
    ur = uu - ucb
    vr = v - vcb
    wr = w - wcb
    f0, f1, f2, f3, f4, f5 = kirchhoff(p, P_MRB, uu, v, w, pp, q, r)
    a0, a1, a2, a3, a4, a5 = kirchhoff(p, P_MA, ur, vr, wr, pp, q, r)
    if p[P_MUNK].real == 0.0:
        # neglect the Munk moment in yaw, -(u_r m1 - v_r m0), with its partners in surge and sway, r m1 and
        # -r m0 (m = M_A [nu_r; 0], the translational added momentum): the pair of C_A entries (5, 0-1) and
        # (0-1, 5) goes together, so C_A stays skew-symmetric and does no work (Fossen 2021, the Otter model)
        m0 = row6(p, P_MA, ur, vr, wr, 0.0, 0.0, 0.0)
        m1 = row6(p, P_MA + 6, ur, vr, wr, 0.0, 0.0, 0.0)
        a0 -= r * m1
        a1 += r * m0
        a5 += ur * m1 - vr * m0
    tau = out[6:12]  # the generalised force is summed in place, then M^-1 is applied
    tau[0] = f0 + a0
    tau[1] = f1 + a1
    tau[2] = f2 + a2
    tau[3] = f3 + a3
    tau[4] = f4 + a4
    tau[5] = f5 + a5
    # -M_A [omega x v_cb; 0]: relative acceleration of a current fixed in the earth frame
    oc0 = q * wcb - r * vcb
    oc1 = r * ucb - pp * wcb
    oc2 = pp * vcb - q * ucb
    au = cabs(ur)
    nr = (ur, vr, wr, pp, q, r)
    for i in range(6):
        k = P_MA + 6 * i
        tau[i] -= p[k] * oc0 + p[k + 1] * oc1 + p[k + 2] * oc2
        tau[i] -= row6(p, P_DL + 6 * i, ur, vr, wr, pp, q, r)
        tau[i] -= p[P_DQ + i] * nr[i] * cabs(nr[i])
        tau[i] -= au * row6(p, P_DU + 6 * i, ur, vr, wr, pp, q, r)
    ns = int(p[P_CFN].real)
    if ns > 0:  # cross-flow drag by strip theory (module docstring), midpoint rule on ns strips
        kdx = p[P_CFK] * p[P_CFDX]
        yh = 0.0 * vr
        nh = 0.0 * vr
        for i in range(ns):
            xi = p[P_CFX0] + i * p[P_CFDX]
            vx = vr + xi * r
            f = kdx * vx * cabs(vx)
            yh -= f
            nh -= xi * f
        tau[1] += yh
        tau[5] += nh
    if p[P_LINR].real != 0.0:
        for i in range(6):
            tau[i] -= row6(p, P_GLIN + 6 * i, x[0], x[1], x[2], x[3], x[4], x[5])
        wp = p[P_WP]  # a weight fixed to the vertical at r_p on top of G eta: R^T (0, 0, W_p) and r_p x it
        fx = wp * r20
        fy = wp * r21
        fz = wp * r22
        tau[0] += fx
        tau[1] += fy
        tau[2] += fz
        tau[3] += p[P_RP + 1] * fz - p[P_RP + 2] * fy
        tau[4] += p[P_RP + 2] * fx - p[P_RP] * fz
        tau[5] += p[P_RP] * fy - p[P_RP + 1] * fx
    else:
        g0, g1, g2, g3, g4, g5 = restoring(p, P_W, P_B, P_RG, P_RB, cf, sf, ct, st)
        if p[P_HH].real > 0.0:  # the buoyancy of the emerged volume is lost (models._surface)
            xb, yb, zb = p[P_RB], p[P_RB + 1], p[P_RB + 2]
            lost = (1.0 - immersed_fraction(x[2] + r20 * xb + r21 * yb + r22 * zb, p[P_HH])) * p[P_B]
            l0, l1, l2, l3, l4, l5 = lost_buoyancy(lost, xb, yb, zb, cf, sf, ct, st)
            g0, g1, g2, g3, g4, g5 = g0 + l0, g1 + l1, g2 + l2, g3 + l3, g4 + l4, g5 + l5
        tau[0] -= g0
        tau[1] -= g1
        tau[2] -= g2
        tau[3] -= g3
        tau[4] -= g4
        tau[5] -= g5
    for i in range(n):
        k = P_THR + NT * i
        cmd = u[i]
        hi = p[k + T_FWD]
        lo = -p[k + T_REV]
        if cmd.real > hi.real:
            cmd = hi
        elif cmd.real < lo.real:
            cmd = lo
        torque = 0.0 * cmd
        if p[k + T_SHAFT].real > 0.0:  # shaft-speed thruster (oceangnc.models._shaft): the state is n, rad/s
            dn, thrust, torque = shaft_thrust(p, k + T_SHAFT, cmd, x[12 + i], p[k + T_TAU], ur, vr, wr)
            out[12 + i] = dn
        elif p[k + T_TAU].real > 0.0:
            thrust = x[12 + i]
            out[12 + i] = (cmd - thrust) / p[k + T_TAU]
        else:
            thrust = cmd
            out[12 + i] = 0.0
        rx = p[k + T_X]
        ry = p[k + T_Y]
        rz = p[k + T_Z]
        if p[P_TIMM].real > 0.0:  # no thrust out of the water (models._surface)
            thrust = thrust * immersed_fraction(x[2] + r20 * rx + r21 * ry + r22 * rz, p[P_TIMM])
        fx = thrust * p[k + T_DX]
        fy = thrust * p[k + T_DY]
        fz = thrust * p[k + T_DZ]
        tau[0] += fx
        tau[1] += fy
        tau[2] += fz
        tau[3] += ry * fz - rz * fy + torque * p[k + T_DX]
        tau[4] += rz * fx - rx * fz + torque * p[k + T_DY]
        tau[5] += rx * fy - ry * fx + torque * p[k + T_DZ]
    for j in range(nf):  # control surfaces (models._fins): the angle is a state after the thrusters'
        kf = P_THR + NT * n + NFIN * j
        out[12 + n + j], delta = fin_step(p, kf, u[n + j], x[12 + n + j])
        fx, fy, fz = fin_force(p, kf, delta, p[P_RHO], ur, vr, wr)
        rx, ry, rz = p[kf + F_X], p[kf + F_Y], p[kf + F_Z]
        tau[0] += fx
        tau[1] += fy
        tau[2] += fz
        tau[3] += ry * fz - rz * fy
        tau[4] += rz * fx - rx * fz
        tau[5] += rx * fy - ry * fx
    t0, t1, t2, t3, t4, t5 = tau[0], tau[1], tau[2], tau[3], tau[4], tau[5]
    for i in range(6):
        out[6 + i] = row6(p, P_MINV + 6 * i, t0, t1, t2, t3, t4, t5)


@njit(cache=True)
def vehicle_rhs(t, x, u, p, out):
    """The plant's right-hand side (:func:`vehicle_deriv`), the signature every Model has."""
    vehicle_deriv(t, x, u, p, out)


# -- the vehicle file ---------------------------------------------------------------------------------

Vec3 = tuple[float, float, float]
Vec6 = tuple[float, float, float, float, float, float]


def _matrix6(v, key: str) -> np.ndarray:
    a = np.asarray(v, dtype=float)
    if a.shape == (6,):
        return np.diag(a)
    if a.shape != (6, 6):
        raise ValueError(f"{key}: 6 values (a diagonal) or a 6 x 6 matrix")
    return a


class Hydrostatics(StrictModel):
    restoring: Literal["submerged", "linear"] = Field(
        "submerged", description="submerged: weight and buoyancy at r_g, r_b; linear: G eta (surface craft)"
    )
    rho: float = Field(1025.0, gt=900, le=1100, description="water density, kg/m^3")
    volume: float | None = Field(None, gt=0, le=1e6, description="displaced volume (submerged), m^3")
    r_b: Vec3 = Field((0.0, 0.0, 0.0), description="centre of buoyancy from CO, m")
    height: float | None = Field(
        None,
        gt=0,
        le=100,
        description="submerged: hull height over which the buoyancy ramps to zero as the hull emerges, m "
        "(none: no free surface; oceangnc.models._surface)",
    )
    thruster_immersion: float | None = Field(
        None,
        gt=0,
        le=10,
        description="submerged: height over which a thruster's thrust ramps to zero out of the water, m",
    )
    G: Vec6 | tuple[Vec6, Vec6, Vec6, Vec6, Vec6, Vec6] | None = Field(
        None, description="linear restoring: spring matrix on eta (diagonal or 6 x 6), N/m, N, N m"
    )
    body_axis_weight: BodyAxisWeight | None = Field(None, description="linear restoring: otter.py's payload force")


class BodyAxisWeight(StrictModel):
    """A weight m g at r from CO added as a force fixed to the earth's vertical, on top of G eta (``otter.py``'s
    payload term g_0 = [R^T (0, 0, m_p g); r_p x R^T (0, 0, m_p g)]); ``apply = false`` keeps it out (ours)."""

    mass: float = Field(gt=0, le=1e8, description="mass, kg")
    r: Vec3 = Field(description="where it acts, from CO, m")
    apply: bool = Field(False, description="add it (otter.py) or not (ours: the weight is in G eta already)")


class AddedMass(StrictModel):
    M_A: Vec6 | tuple[Vec6, Vec6, Vec6, Vec6, Vec6, Vec6] = Field(
        description="added mass (positive: -X_udot, -Y_vdot, ...), diagonal or 6 x 6, kg, kg m, kg m^2"
    )
    munk_yaw_moment: bool = Field(
        True,
        description="keep the destabilising Munk moment in yaw (false: neglected with its surge and sway partners, "
        "C_A stays skew-symmetric, as Fossen's Otter model)",
    )


class Damping(StrictModel):
    linear: Vec6 | tuple[Vec6, Vec6, Vec6, Vec6, Vec6, Vec6] = Field(
        (0.0,) * 6, description="D_L (diagonal or 6 x 6), N s/m and N m s; positive opposes motion"
    )
    quadratic: Vec6 = Field((0.0,) * 6, description="D_Q diagonal, kg/m and kg m^2")
    speed: tuple[Vec6, Vec6, Vec6, Vec6, Vec6, Vec6] | None = Field(
        None, description="D_U, 6 x 6, multiplied by |u_r| (body lift, fins)"
    )
    crossflow: CrossFlow | None = Field(None, description="cross-flow drag of the hull by strip theory (optional)")


class Thruster(StrictModel):
    name: str = Field(min_length=1, max_length=40)
    position: Vec3 = Field(description="from CO, body axes, m")
    direction: Vec3 = Field(description="thrust direction (normalised when read)")
    max_forward: float = Field(gt=0, le=1e7, description="largest forward thrust, N")
    max_reverse: float = Field(ge=0, le=1e7, description="largest reverse thrust (a positive number), N")
    time_constant: float = Field(
        0.0, ge=0, le=100, description="first-order lag of the thrust (of the shaft speed with [shaft]), s (0: none)"
    )
    shaft: Shaft | None = Field(None, description="driven by shaft speed: thrust k n|n| (oceangnc.models._shaft)")

    @field_validator("direction")
    @classmethod
    def _nonzero(cls, v):
        if math.hypot(*v) < 1e-9:
            raise ValueError("a thrust direction of zero length")
        return v


class Control(StrictModel):
    dofs: list[Literal["surge", "sway", "heave", "roll", "pitch", "yaw"]] = Field(
        min_length=1, description="the degrees of freedom the allocation controls"
    )
    weights: list[float] | None = Field(None, description="thruster weights of the allocation (default 1)")
    allocator: Literal["pinv", "redistribute"] = Field(
        "pinv",
        description="pinv: weighted pseudo-inverse scaled into the limits; redistribute: saturated thrusters "
        "fixed at their limits and the rest re-allocated (oceangnc.control.thrust_allocation)",
    )
    priority: list[list[Literal["surge", "sway", "heave", "roll", "pitch", "yaw"]]] | None = Field(
        None,
        min_length=1,
        max_length=6,
        description="pinv: tiers of DOFs served first to last past a thrust limit (oceangnc.control."
        "priority_allocation); none: one tier, uniform scaling",
    )


class VehicleFile(StrictModel):
    """A vehicle file (TOML): the matrix-vector form of the module docstring, SI units."""

    name: str = Field(min_length=1, max_length=60)
    description: str = ""
    kind: Literal["underwater", "surface"]
    length: float = Field(gt=0, le=500, description="overall length, m (plots and the 3D view)")
    sources: dict[str, str] = Field(default_factory=dict, description="where each group of numbers comes from")
    rigid_body: RigidBody
    hydrostatics: Hydrostatics
    added_mass: AddedMass
    damping: Damping
    thrusters: list[Thruster] = Field(min_length=1, max_length=32)
    fins: list[Fin] = Field(default_factory=list, max_length=8, description="control surfaces (models._fins)")
    control: Control


def _skew(a) -> np.ndarray:
    return np.array([[0.0, -a[2], a[1]], [a[2], 0.0, -a[0]], [-a[1], a[0], 0.0]])


def rigid_body_matrix(rb: RigidBody) -> np.ndarray:
    """M_RB about CO (Fossen 2021 eq. 3.44): [[m I, -m S(r_g)], [m S(r_g), I_g - m S(r_g)^2]]."""
    m, ig, r_g = rb.resolved()
    s = _skew(r_g)
    M = np.zeros((6, 6))
    M[:3, :3] = m * np.eye(3)
    M[:3, 3:] = -m * s
    M[3:, :3] = m * s
    M[3:, 3:] = ig - m * s @ s
    return M


def thruster_matrix(vf: VehicleFile) -> np.ndarray:
    """The 6 x n configuration matrix: column i = [d_i; r_i x d_i] (thrust to generalised force)."""
    cols = []
    for t in vf.thrusters:
        d = np.asarray(t.direction, float)
        d = d / np.linalg.norm(d)
        cols.append(np.concatenate([d, np.cross(np.asarray(t.position, float), d)]))
    return np.array(cols).T


def _check(vf: VehicleFile, where: str) -> None:
    """Refuse a vehicle no simulation can run: a mass matrix that is not symmetric positive definite,
    a submerged vehicle without its volume, a controlled DOF the thrusters cannot reach."""
    mrb = rigid_body_matrix(vf.rigid_body)
    ma = _matrix6(vf.added_mass.M_A, "added_mass.M_A")
    for label, M in (("M_RB", mrb), ("M_RB + M_A", mrb + ma)):
        if not np.allclose(M, M.T, rtol=0, atol=1e-9 * max(1.0, np.abs(M).max())):
            raise ConfigError(f"{where}: the mass matrix {label} is not symmetric")
        lo = float(np.linalg.eigvalsh(M).min())
        if lo <= 0:
            raise ConfigError(
                f"{where}: the mass matrix {label} is not positive definite (smallest eigenvalue {lo:.4g}); "
                "check rigid_body.inertia, rigid_body.r_g and added_mass"
            )
    h = vf.hydrostatics
    if h.restoring == "submerged" and h.volume is None:
        raise ConfigError(f"{where}: hydrostatics.volume is required with restoring = 'submerged'")
    if h.restoring == "linear" and h.G is None:
        raise ConfigError(f"{where}: hydrostatics.G is required with restoring = 'linear'")
    for i, t in enumerate(vf.thrusters):  # a thruster farther from CO than the whole hull is long is off the hull
        dist = math.hypot(*t.position)
        if dist > vf.length:
            raise ConfigError(
                f"{where}: thrusters[{i}].position ('{t.name}') is {dist:.4g} m from the origin, outside the "
                f"{vf.length:g} m vehicle (length); allowed: within length = {vf.length:g} m of CO"
            )
    B = thruster_matrix(vf)
    rows = [DOF_NAMES.index(d) for d in vf.control.dofs]
    rank = 0
    for k in range(1, len(rows) + 1):
        r = int(np.linalg.matrix_rank(B[rows[:k]], tol=1e-9))
        if r == rank:
            dof = vf.control.dofs[k - 1]
            raise ConfigError(
                f"{where}: control.dofs: '{dof}' cannot be controlled by the {len(vf.thrusters)} thrusters "
                f"independently of {', '.join(vf.control.dofs[: k - 1]) or 'nothing'} (rank {rank}); "
                "add a thruster or remove the DOF"
            )
        rank = r
    if vf.control.weights is not None and (
        len(vf.control.weights) != len(vf.thrusters) or min(vf.control.weights) <= 0
    ):
        raise ConfigError(f"{where}: control.weights: one positive weight per thruster ({len(vf.thrusters)})")


def shipped_vehicles() -> list[str]:
    """Names of the vehicle files shipped in ``oceangnc/models/vehicles/``."""
    files = resources.files("oceangnc.models").joinpath("vehicles")
    return sorted(p.name[: -len(".toml")] for p in files.iterdir() if p.name.endswith(".toml"))


def load_vehicle(name_or_path: str | Path) -> VehicleFile:
    """Read and check a vehicle file: a shipped name (``"bluerov2-heavy"``, ``"otter"``, ``"uuv-003"``) or
    a path to a TOML file. Errors are one line (:class:`~oceangnc.errors.ConfigError`) naming the key."""
    s = str(name_or_path)
    if s in shipped_vehicles():
        text = resources.files("oceangnc.models").joinpath("vehicles", s + ".toml").read_text()
        where = f"vehicle '{s}'"
    else:
        from ..core.files import LIMIT_TOML, read_text_bounded

        path = Path(s)
        if not path.exists():
            raise ConfigError(f"vehicle {s!r}: neither a shipped vehicle ({', '.join(shipped_vehicles())}) nor a file")
        text = read_text_bounded(path, LIMIT_TOML, "vehicle file")  # a regular file, bounded, UTF-8
        where = f"vehicle file {path}"
    try:
        data = tomllib.loads(text)
    except tomllib.TOMLDecodeError as e:
        raise ConfigError(f"{where}: not valid TOML: {e}") from None
    except RecursionError:
        raise ConfigError(f"{where}: not valid TOML: nested too deeply") from None
    try:
        vf = VehicleFile.model_validate(data)
    except ValidationError as e:  # one line naming the key and the allowed range
        raise ConfigError(
            f"{where}: {format_validation_error(VehicleFile, e).removeprefix('config error: ')}"
        ) from None
    _check(vf, where)
    return vf


def vehicle_params(vf: VehicleFile) -> np.ndarray:
    """The parameter vector: :data:`LAYOUT_HEAD`, then the thruster table (``NT`` values per thruster)."""
    h = vf.hydrostatics
    mass, _, r_g = vf.rigid_body.resolved()
    W = mass * G
    B = h.rho * G * h.volume if h.volume is not None else W
    mrb = rigid_body_matrix(vf.rigid_body)
    ma = _matrix6(vf.added_mass.M_A, "added_mass.M_A")
    cf = vf.damping.crossflow
    bw = h.body_axis_weight
    head = LAYOUT_HEAD.pack(
        {
            "W": W,
            "B": B,
            "r_g": r_g,
            "r_b": h.r_b,
            "linear_restoring": 1.0 if h.restoring == "linear" else 0.0,
            "G_lin": _matrix6(h.G, "hydrostatics.G") if h.G is not None else np.zeros((6, 6)),
            "M_RB": mrb,
            "M_A": ma,
            "M_inv": np.linalg.inv(mrb + ma),
            "D_L": _matrix6(vf.damping.linear, "damping.linear"),
            "D_Q": vf.damping.quadratic,
            "D_U": np.asarray(vf.damping.speed, float) if vf.damping.speed is not None else np.zeros((6, 6)),
            "munk_yaw": 1.0 if vf.added_mass.munk_yaw_moment else 0.0,
            "cf_coeff": cf.coefficient(h.rho) if cf is not None else 0.0,
            "cf_x0": cf.stations()[0] if cf is not None else 0.0,
            "cf_dx": cf.stations()[1] if cf is not None else 0.0,
            "cf_strips": cf.stations()[2] if cf is not None else 0,
            "W_p": bw.mass * G if bw is not None and bw.apply else 0.0,
            "r_p": bw.r if bw is not None else (0.0, 0.0, 0.0),
            "n_thrusters": len(vf.thrusters),
            "hull_height": h.height or 0.0,
            "thr_immersion": h.thruster_immersion or 0.0,
            "n_fins": len(vf.fins),
            "rho": h.rho,
        }
    )
    rows = []
    for t in vf.thrusters:
        d = np.asarray(t.direction, float)
        d = d / np.linalg.norm(d)
        shaft = t.shaft.row(t.max_forward, t.max_reverse) if t.shaft is not None else [0.0] * len(SHAFT_FIELDS)
        rows.append([*t.position, *d, t.max_forward, t.max_reverse, t.time_constant, *shaft])
    fins = [f.row() for f in vf.fins]
    return np.concatenate([head, np.asarray(rows, float).ravel(), np.asarray(fins, float).ravel()])


def vehicle_layout(vf: VehicleFile) -> ParamLayout:
    """The full parameter layout: the head, then ``<thruster>.<field>`` for each thruster."""
    units = ("m",) * 3 + ("1",) * 3 + ("N", "N", "s", "N s^2", "N s^2", "N s", "N m s^2", "N m s^2", "N m s", "1")
    units += ("rad/s", "rad/s")
    extra = [Param(f"{t.name}.{f}", units[i]) for t in vf.thrusters for i, f in enumerate(THR_FIELDS)]
    fin_units = ("m", "m", "m", "1", "m^2", "1/rad", "rad", "s")
    extra += [Param(f"{f.name}.{n}", fin_units[i]) for f in vf.fins for i, n in enumerate(FIN_FIELDS)]
    return ParamLayout([*LAYOUT_HEAD.params, *extra])


STATE_NAMES = ("x", "y", "z", "phi", "theta", "psi", "u", "v", "w", "p", "q", "r")
STATE_UNITS = ("m", "m", "m", "rad", "rad", "rad", "m/s", "m/s", "m/s", "rad/s", "rad/s", "rad/s")


def thruster_state(t: Thruster) -> tuple[str, str]:
    """Name and unit of a thruster's state: its thrust ``thrust_<name>`` (N), or the shaft speed
    ``shaft_<name>`` (rad/s) of a shaft-speed thruster."""
    return (f"shaft_{t.name}", "rad/s") if t.shaft is not None else (f"thrust_{t.name}", "N")


def vehicle_model(vf: VehicleFile | str | Path, params=None) -> Model:
    """The :class:`~oceangnc.core.model.Model` of a vehicle file (or shipped name): states
    :data:`STATE_NAMES` then ``thrust_<name>`` (N), ``fin_<name>`` (rad), inputs ``thrust_<name>_cmd`` (N),
    ``fin_<name>_cmd`` (rad), ``current_n``, ``current_e`` (m/s)."""
    if not isinstance(vf, VehicleFile):
        vf = load_vehicle(vf)
    states = [*zip(STATE_NAMES, STATE_UNITS), *(thruster_state(t) for t in vf.thrusters)]
    states += [(f"fin_{f.name}", "rad") for f in vf.fins]
    inputs = [*((f"thrust_{t.name}_cmd", "N") for t in vf.thrusters), *((f"fin_{f.name}_cmd", "rad") for f in vf.fins)]
    inputs += [("current_n", "m/s"), ("current_e", "m/s")]
    p = vehicle_params(vf) if params is None else np.asarray(params, dtype=np.float64)
    return Model(vf.name, vehicle_rhs, states, inputs, vehicle_layout(vf), p, bound=1e6, description=vf.description)


def vehicle_energy(x, p) -> float:
    """Kinetic energy 1/2 nu^T (M_RB + M_A) nu (J) of a vehicle at rest in the water (no current)."""
    nu = np.asarray(x[6:12], float)
    M = p[P_MRB : P_MRB + 36].reshape(6, 6) + p[P_MA : P_MA + 36].reshape(6, 6)
    return float(0.5 * nu @ M @ nu)


def _model_factory(name: str):
    def factory(params=None) -> Model:
        return vehicle_model(name, params)

    factory.__doc__ = f"The shipped vehicle '{name}' as a Model (oceangnc.models entry point)."
    return factory


bluerov2_heavy_model = _model_factory("bluerov2-heavy")
otter_model = _model_factory("otter")
uuv_003_model = _model_factory("uuv-003")
