r"""Backstepping leader-follower controller of the UUV (003 ch. 3.3.2, eq. 3.24-3.39, re-derived).

The extracted equations (3.33)-(3.36) are garbled (SPEC.md), so the controller is derived here from
the printed Lyapunov functions and the 3-DOF model (3.32) (with the ``d22 u`` typo read as
``d22 v``, and the bow thruster's side force kept, since the plant has it):

    m11 u' - m22 v r + d11 u = tau_u
    m22 v' + m11 u r + d22 v = tau_r / B_f               (bow thrust T_b = tau_r / B_f also pushes sideways)
    m33 r' + (m22 - m11) u v + d33 r = tau_r

m11 = m - X_udot, m22 = m - Y_vdot, m33 = I_z - N_rdot, d11 = -X_u - X_u|u| |u|, d22 = -Y_v - Y_v|v| |v|,
d33 = -N_r - N_r|r| |r| (003 under eq. 3.32; the coefficients come from the UUV model).

**Errors (3.24)-(3.27).** Leader (USV) at p_l with heading psi_l, body velocities (u_l, v_l, r_l);
follower (UUV) heading psi_f, velocities (u, v, r). The target is the offset c = (c_x, c_y) in the
leader's frame; e_psi = psi_l - psi_f. The position error in the follower's frame is
epsilon = R(psi_f)^T (p_h - p_t) = R(e_psi) e, e = R(psi_l)^T (p_h - p_l) - c (eq. 3.26 with
the rotation R(e_psi)). Differentiating (our derivation; it reproduces the printed 3.27):

    eps1' = u + zeta1 cos e_psi - zeta2 sin e_psi + r eps2            = u + a + r eps2
    eps2' = v + h r + zeta1 sin e_psi + zeta2 cos e_psi - r eps1      = v + h r + b - r eps1
    zeta1 = -u_l + r_l c_y,   zeta2 = -v_l - r_l c_x                  (printed under 3.27)

**Why the printed second step cannot work, and the change we make.** The printed design keeps
p_h = p_f (h = 0), so r does not appear in eps2' and the sway error v_e = v - v^v must be driven
through the heading with V_2 = v_e^2/2 + 2 k_3 sin^2(e_psi/2) (3.35). Its derivative has the form
V_2' = D(x) r + v_e H(x) with D = (m11/m22 - 1) a v_e - k_3 sin e_psi: on the surface D = 0 no
choice of r makes V_2' <= 0 when v_e H != 0 (the sway direction is not actuated), which is why the
printed (3.36) needs the sign-switching bound Theta and cannot certify V' <= 0 everywhere. We
therefore regulate a *control point* at distance h ahead of the UUV's centre (the bow, where the
bow thruster acts), p_h = p_f + R(psi_f) (h, 0), the classical "hand position" of underactuated
formation control. Then r enters eps2' through h r and both position errors are actuated.

**Step 1 (V_1 = (eps1^2 + eps2^2)/2, eq. 3.28).** V_1' = eps1 (u + a) + eps2 (v + h r + b) (the
r eps terms cancel). Virtual controls (the analogue of 3.30):

    alpha_u = -k1 eps1 - a,       alpha_r = (-k2 eps2 - b - v) / h

and with u_e = u - alpha_u, r_e = r - alpha_r:  V_1' = -k1 eps1^2 - k2 eps2^2 + eps1 u_e + h eps2 r_e.

**Step 2 (V_3 = u_e^2/2 (3.37), V_4 = r_e^2/2).** With alpha_u' = -k1 eps1' - a',
a' = zeta1' cos e_psi - zeta2' sin e_psi - b (r_l - r), b' = zeta1' sin e_psi + zeta2' cos e_psi
+ a (r_l - r), alpha_r' = (-k2 eps2' - b' - v')/h and v' from the sway equation,

    tau_u = m11 (alpha_u' - k6 u_e - eps1) - m22 v r + d11 u                      (cf. 3.38)
    tau_r = [alpha_r0' - k7 r_e - h eps2 + ((m22 - m11) u v + d33 r)/m33]
            / (1/m33 + 1/(h B_f m22))                                                 (cf. 3.39)

where alpha_r0' is alpha_r' without the tau_r/(B_f m22) part of v' (solved for tau_r because the bow
thrust enters both v' and r'). This gives u_e' = -k6 u_e - eps1 and r_e' = -k7 r_e - h eps2, so

    V = V_1 + V_3 + V_4,     V' = -k1 eps1^2 - k2 eps2^2 - k6 u_e^2 - k7 r_e^2 <= 0.

**Heading (3.35).** On the zero dynamics (eps = 0, u_e = r_e = 0) behind a leader moving straight at
speed U > 0, r = (U sin e_psi - v)/h and e_psi' = -(U/h) sin e_psi + v/h, so the heading term of
(3.35), 2 k3 sin^2(e_psi/2), decays at the rate U/h: the UUV aligns with the USV (the relative angle
goal of 3.9) as a consequence. The target of the control point is c = (l_x^d + h, l_y^d), so that
once aligned the UUV's centre sits at the leader-follower offset (l_x^d, l_y^d).

The leader's accelerations (zeta') are estimated in the block by a filtered difference of the
leader's velocities (a test may pass them exactly). Saturating the thrusters breaks the proof;
the block clips them anyway and reports V and V' (``uuv_bs.V``, ``uuv_bs.Vdot``).
"""

from __future__ import annotations

import dataclasses
import math
from dataclasses import dataclass

import numpy as np
from numba import njit
from pydantic import Field

from ..core.law import In, LawBlock, Layout, Opt, Out, Signals
from ..core.registry import register_block
from ..core.rotations import wrap
from ..guidance.leader_follower import target_point
from ..io.config import StrictModel
from ..models._hydro import damping_coefficient
from ..models.uuv import UUVConfig
from ..sensors.filters import lowpass_step
from ..units import KGF


class BacksteppingConfig(StrictModel):
    """Gains of the backstepping controller (docs/combined-vehicle.md for the choice)."""

    k1: float = Field(0.4, gt=0, le=100, description="surge position gain, 1/s")
    k2: float = Field(0.4, gt=0, le=100, description="lateral position gain, 1/s")
    k6: float = Field(1.5, gt=0, le=100, description="surge velocity gain, 1/s")
    k7: float = Field(2.0, gt=0, le=100, description="yaw rate gain, 1/s")
    h: float = Field(0.9, gt=0, le=10, description="control point ahead of the UUV's centre (the bow), m")
    bow_side_force: bool = Field(
        True, description="design model includes the bow thruster's side force (False: eq. 3.32 as printed)"
    )
    accel_cutoff_hz: float = Field(
        0.5, gt=0, le=50, description="low-pass cut-off of the leader acceleration estimate, Hz"
    )


class BacksteppingParams(BacksteppingConfig):
    """The gains and what the block takes from its scenario (``build_block(..., given=...)``)."""

    uuv: UUVConfig = Field(..., description="the UUV driven: its 3-DOF model (eq. 3.32) and thrust limits")
    l_d: float = Field(..., ge=0, description="target horizontal range l^d, m")
    lambda_d: float = Field(..., description="target bearing lambda^d from the leader's bow, rad")


@dataclass(frozen=True)
class Model3DOF:
    """The 3-DOF UUV model (003 eq. 3.32) parameters (SI)."""

    m11: float
    m22: float
    m33: float
    Xu: float  # linear damping coefficients (<= 0)
    Yv: float
    Nr: float
    Xuu: float  # quadratic coefficients (<= 0)
    Yvv: float
    Nrr: float
    bow_arm: float  # B_f, m
    sway_from_bow: float = 1.0  # 1: the bow thrust also pushes sideways (Y = T_b); 0: as printed (Y = 0)

    def d11(self, u):
        return damping_coefficient(self.Xu, self.Xuu, u)

    def d22(self, v):
        return damping_coefficient(self.Yv, self.Yvv, v)

    def d33(self, r):
        return damping_coefficient(self.Nr, self.Nrr, r)

    def accel(self, u, v, r, tau_u, tau_r):
        """(u', v', r') of eq. 3.32 (with the bow side force if ``sway_from_bow``)."""
        du = (tau_u + self.m22 * v * r - self.d11(u) * u) / self.m11
        dv = (self.sway_from_bow * tau_r / self.bow_arm - self.m11 * u * r - self.d22(v) * v) / self.m22
        dr = (tau_r - (self.m22 - self.m11) * u * v - self.d33(r) * r) / self.m33
        return du, dv, dr


def model_from_uuv(uuv_cfg) -> Model3DOF:
    """3-DOF parameters of :class:`oceangnc.models.uuv.UUVConfig` (003 under eq. 3.32)."""
    mrb, ma = uuv_cfg.mass_matrices()
    c = uuv_cfg.coefficients()
    return Model3DOF(
        m11=mrb[0, 0] + ma[0, 0],
        m22=mrb[1, 1] + ma[1, 1],
        m33=mrb[5, 5] + ma[5, 5],
        Xu=uuv_cfg.X_u,
        Yv=uuv_cfg.Y_v,
        Nr=uuv_cfg.N_r,
        Xuu=c["X_uu"] * uuv_cfg.drag_scale,
        Yvv=c["Y_vv"] * uuv_cfg.drag_scale,
        Nrr=c["N_rr"] * uuv_cfg.drag_scale,
        bow_arm=uuv_cfg.bow_arm,
    )


@njit(cache=True, inline="always")
def errors(xl, yl, psil, xf, yf, psif, cx, cy, h):
    """(eps1, eps2, e_psi): control-point error in the follower frame (m) and psi_l - psi_f (rad)."""
    tn, te = target_point(xl, yl, psil, cx, cy)  # the target of the control point (003 eq. 3.8)
    cf, sf = math.cos(psif), math.sin(psif)
    hn = xf + h * cf
    he = yf + h * sf
    dn, de = hn - tn, he - te
    e_psi = wrap(psil - psif)
    return cf * dn + sf * de, -sf * dn + cf * de, e_psi


#: parameter layout of the compiled law (and of the block's parameters)
PARAMS = ("period", "a_lp", "cx", "cy", "h", "k1", "k2", "k6", "k7", "m11", "m22", "m33", "Xu", "Yv", "Nr", "Xuu",
          "Yvv", "Nrr", "bow_arm", "sway_from_bow", "hi", "lo")  # fmt: skip
BS_PARAMS = Layout(*PARAMS)
#: state of :func:`update`: the leader's velocities at the last firing (u, v, r), 1 once there are some,
#: the low-passed leader accelerations, and this firing's inputs in the order of :data:`ROLES`
BS_STATE = Layout(("lv", 3), "has", ("acc", 3), ("inp", 12))
_P, _X = BS_PARAMS.at, BS_STATE.at


def law_params(m: Model3DOF, g: BacksteppingConfig, cx=0.0, cy=0.0, period=0.0, a_lp=0.0, hi=0.0, lo=0.0):
    """The flat parameters (layout :data:`PARAMS`) of :func:`law` and :func:`update`."""
    v = {"period": period, "a_lp": a_lp, "cx": cx, "cy": cy, "h": g.h, "k1": g.k1, "k2": g.k2, "k6": g.k6}
    v.update(k7=g.k7, m11=m.m11, m22=m.m22, m33=m.m33, Xu=m.Xu, Yv=m.Yv, Nr=m.Nr, Xuu=m.Xuu, Yvv=m.Yvv, Nrr=m.Nrr)
    v.update(bow_arm=m.bow_arm, sway_from_bow=m.sway_from_bow, hi=hi, lo=lo)
    return BS_PARAMS.pack(v)


@njit(cache=True, inline="always")
def law(pa, eps1, eps2, e_psi, u, v, r, ul, vl, rl, dul, dvl, drl):
    """Backstepping law (module docstring), parameters ``pa`` (:data:`PARAMS`). Returns (tau_u (N),
    tau_r (N m), V, Vdot (the nominal V' = -k1 eps1^2 - k2 eps2^2 - k6 u_e^2 - k7 r_e^2), u_e, r_e,
    alpha_u, alpha_r)."""
    cx, cy, h = pa[_P.cx], pa[_P.cy], pa[_P.h]
    k1, k2, k6, k7 = pa[_P.k1], pa[_P.k2], pa[_P.k6], pa[_P.k7]
    m11, m22, m33 = pa[_P.m11], pa[_P.m22], pa[_P.m33]
    cs, sn = math.cos(e_psi), math.sin(e_psi)
    z1 = -ul + rl * cy
    z2 = -vl - rl * cx
    dz1 = -dul + drl * cy
    dz2 = -dvl - drl * cx
    a = z1 * cs - z2 * sn
    b = z1 * sn + z2 * cs
    de_psi = rl - r
    da = dz1 * cs - dz2 * sn - b * de_psi
    db = dz1 * sn + dz2 * cs + a * de_psi
    deps1 = u + a + r * eps2
    deps2 = v + h * r + b - r * eps1
    alpha_u = -k1 * eps1 - a
    alpha_r = (-k2 * eps2 - b - v) / h
    u_e = u - alpha_u
    r_e = r - alpha_r
    d11 = damping_coefficient(pa[_P.Xu], pa[_P.Xuu], u)  # as Model3DOF.d11 .. d33
    d22 = damping_coefficient(pa[_P.Yv], pa[_P.Yvv], v)
    d33 = damping_coefficient(pa[_P.Nr], pa[_P.Nrr], r)
    dalpha_u = -k1 * deps1 - da
    tau_u = m11 * (dalpha_u - k6 * u_e - eps1) - m22 * v * r + d11 * u
    dv0 = (-m11 * u * r - d22 * v) / m22  # v' without the bow side force
    dalpha_r0 = (-k2 * deps2 - db - dv0) / h
    cb = pa[_P.sway_from_bow] / (h * pa[_P.bow_arm] * m22)  # alpha_r' = dalpha_r0 - cb * tau_r
    tau_r = (dalpha_r0 - k7 * r_e - h * eps2 + ((m22 - m11) * u * v + d33 * r) / m33) / (1.0 / m33 + cb)
    V = 0.5 * (eps1 * eps1 + eps2 * eps2 + u_e * u_e + r_e * r_e)
    Vdot = -k1 * eps1 * eps1 - k2 * eps2 * eps2 - k6 * u_e * u_e - k7 * r_e * r_e
    return tau_u, tau_r, V, Vdot, u_e, r_e, alpha_u, alpha_r


@njit(cache=True, inline="always")
def update(st, pa):
    """One firing of the block on its state ``st`` (19): leader velocities u_l, v_l, r_l of the last
    firing, has them, leader-acceleration estimate (3), then this firing's inputs in the order of
    :data:`ROLES`. Runs the acceleration filter, :func:`errors`, :func:`law` and the thruster split (stern
    T = tau_u / 2, bow T_b = tau_r / B_f, clipped to [lo, hi] N). Returns (T_stern, T_bow, V, Vdot, eps1,
    eps2, tau_u, tau_r)."""
    xl, yl, psil, ul, vl, rl, xf, yf, psif, u, v, r = st[_X.inp : _X.inp + 12]
    lv = (ul, vl, rl)
    for i in range(3):
        if st[_X.has] != 0.0:
            st[_X.acc + i] = lowpass_step(st[_X.acc + i], pa[_P.a_lp], (lv[i] - st[_X.lv + i]) / pa[_P.period])
        st[_X.lv + i] = lv[i]
    st[_X.has] = 1.0
    eps1, eps2, e_psi = errors(xl, yl, psil, xf, yf, psif, pa[_P.cx], pa[_P.cy], pa[_P.h])
    acc = _X.acc
    tau_u, tau_r, V, Vdot, _, _, _, _ = law(
        pa, eps1, eps2, e_psi, u, v, r, ul, vl, rl, st[acc], st[acc + 1], st[acc + 2]
    )
    ts = min(pa[_P.hi], max(pa[_P.lo], 0.5 * tau_u))
    tb = min(pa[_P.hi], max(pa[_P.lo], tau_r / pa[_P.bow_arm]))
    return ts, tb, V, Vdot, eps1, eps2, tau_u, tau_r


def control_law(m: Model3DOF, g: BacksteppingConfig, eps1, eps2, e_psi, u, v, r, ul, vl, rl, dul=0.0, dvl=0.0,
                drl=0.0, cx=0.0, cy=0.0):  # fmt: skip
    """:func:`law` with the model and gains as objects. Returns a dict with tau_u (N), tau_r (N m), V,
    Vdot, u_e, r_e, alpha_u, alpha_r.

    Inputs: errors from :func:`errors`; follower velocities u, v (m/s), r (rad/s); leader
    velocities ul, vl, rl and their time derivatives dul, dvl, drl; c = (cx, cy) the control point's
    target in the leader frame (m).
    """
    out = law(law_params(m, g, cx, cy), eps1, eps2, e_psi, u, v, r, ul, vl, rl, dul, dvl, drl)
    return dict(zip(("tau_u", "tau_r", "V", "Vdot", "u_e", "r_e", "alpha_u", "alpha_r"), out))


#: the block's inputs by role (leader l = USV, follower f = UUV), in the order :func:`update` takes them
ROLES = {"xl": "usv.x", "yl": "usv.y", "psil": "usv.psi", "ul": "usv.u", "vl": "usv.v", "rl": "usv.r",
         "xf": "uuv.x", "yf": "uuv.y", "psif": "uuv.psi", "uf": "uuv.u", "vf": "uuv.v", "rf": "uuv.r"}  # fmt: skip
#: the block's outputs with units, in the order of its compiled form's slots
OUTPUTS = {"uuv.thrust_port_cmd": "N", "uuv.thrust_stbd_cmd": "N", "uuv.thrust_bow_cmd": "N", "uuv_bs.V": "J",
           "uuv_bs.Vdot": "W", "uuv_bs.eps1": "m", "uuv_bs.eps2": "m", "uuv_bs.tau_u": "N", "uuv_bs.tau_r": "N m",
           "uuv_ctrl.psi_d": "rad"}  # fmt: skip


@njit(cache=True)
def backstepping_law(t, sig, sl, st, pa):
    """One firing (003 eq. 3.24-3.41, :func:`update`): the twelve leader/follower inputs (0 for an
    unmeasured one) into the state, then the thrusts T_port = T_stbd = tau_u / 2 and T_bow = tau_r / B_f
    (N, clipped), V, V', eps1, eps2 (m), tau_u (N), tau_r (N m) and the leader's heading as psi_d (rad)."""
    for i in range(12):  # the inputs go to the state's scratch part
        st[_X.inp + i] = sig[sl[i]] if sl[i] >= 0 else 0.0
    out = update(st, pa)
    sig[sl[12]] = out[0]
    sig[sl[13]] = out[0]
    for i in range(1, 8):
        sig[sl[13 + i]] = out[i]
    sig[sl[21]] = st[_X.inp + 2]


@register_block("uuv.backstepping")
class UUVBackstepping(LawBlock):
    """The backstepping law as a block; writes the UUV thruster commands (N); law :func:`backstepping_law`.

    Stern thrusters share tau_u (U_port = U_stbd = tau_u / 2, as eq. 3.13 shares the range command);
    the bow thruster gives the yaw moment, T_b = tau_r / B_f. Reads leader/follower positions,
    headings and body velocities from the bus keys in ``keys`` (in the order of :data:`ROLES`); the
    leader's accelerations are a low-passed difference of its velocities. Publishes ``uuv_bs.V``,
    ``uuv_bs.Vdot``, ``uuv_bs.eps1``, ``uuv_bs.eps2``, ``uuv_bs.tau_u``, ``uuv_bs.tau_r`` and
    ``uuv_ctrl.psi_d`` (the leader's heading, the relative-angle target of eq. 3.9).
    """

    role = "controller"
    name = "uuv_control"
    law = staticmethod(backstepping_law)
    params_model = BacksteppingParams

    def __init__(self, cfg: BacksteppingConfig, uuv_cfg, l_d: float, lambda_d: float, period: float = 0.05, keys=None):
        self.cfg = cfg
        self.period = float(period)
        self.model = dataclasses.replace(model_from_uuv(uuv_cfg), sway_from_bow=1.0 if cfg.bow_side_force else 0.0)
        self.hi = uuv_cfg.max_thrust_kgf * KGF
        self.lo = -uuv_cfg.max_reverse_kgf * KGF
        self.cx = l_d * math.cos(lambda_d) + cfg.h
        self.cy = l_d * math.sin(lambda_d)
        self.keys = {**ROLES, **(keys or {})}
        unit = {"x": "m", "y": "m", "p": "rad", "u": "m/s", "v": "m/s", "r": "rad/s"}
        # an internal key ("_zero": no measurement, read as 0) is an optional input
        roles = {n: (Opt if key.startswith("_") else In)(unit[n[0]]) for n, key in self.keys.items()}
        outs = {f"o{i}": Out(u) for i, u in enumerate(OUTPUTS.values())}
        self.signals = Signals(**roles, **outs)
        self.bind(**self.keys, **{f"o{i}": k for i, k in enumerate(OUTPUTS)})
        self.a_lp = 1.0 - math.exp(-2 * math.pi * cfg.accel_cutoff_hz * self.period)
        self.pa = law_params(self.model, cfg, self.cx, self.cy, self.period, self.a_lp, self.hi, self.lo)
        self.st = np.zeros(BS_STATE.size)

    @classmethod
    def from_context(cls, params: BacksteppingParams, ctx) -> UUVBackstepping:
        """Built from a scenario's ``control.uuv`` slot: its own parameters (the gains, the vehicle
        ``uuv``, the target geometry ``l_d`` (m), ``lambda_d`` (rad)), leader (USV) and follower (UUV)
        signals by role from ``ctx.signal``."""
        keys = {n: ctx.signal(r) for n, r in ROLES.items()}
        return cls(params, params.uuv, params.l_d, params.lambda_d, ctx.period, keys=keys)

    def reset(self, rng) -> None:
        self.st[:] = 0.0
