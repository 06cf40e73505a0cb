"""3-DOF low-speed manoeuvring model of a container ship with rudder, propeller and bow/stern thrusters.

Model structure: document 001 (``001_7b3de4f47de6bfb9.txt``) eq. 1-25. Coefficients: the S-175
container ship (L = 175 m, B = 25.4 m, T = 8.5 m, displacement 21 222 m^3) of Son & Nomoto (1981,
J. Soc. Nav. Arch. Japan 150; also Son & Nomoto 1982, Naval Arch. Ocean Eng. 20:73-83), whose
hydrodynamic derivatives, rudder and propeller constants are tabulated in the paper (and in Fossen's
MSS ``container.m``). Cross-coupling added masses Y_rdot, N_vdot from Clarke, Gedling & Hine (1983)
empirical formulas; cross-flow drag, thrusters, lags and windage are chosen (docs/berthing.md).

Velocities relative to the water nu_r = nu - R(psi)^T v_c (uniform current, earth-fixed); for such a
current the rigid-body terms can be written in nu_r (Fossen 2011, Prop. 8.1), so with
u_r = u - u_c, v_r = v - v_c:

    (m - X_udot) u_r'              = m (v_r r + x_G r^2) + X_h + X_R + X_P + X_W          (4), (27)
    M1 [v_r', r']^T = [-m u_r r + Y_h + Y_R + Y_T + Y_W, -m x_G u_r r + N_h + N_R + N_T + N_W]^T  (5, 6, 28)
    M1 = [[m - Y_vdot, m x_G - Y_rdot], [m x_G - N_vdot, I_zz - N_rdot]]                      (35)
    u' = u_r' + r v_c,   v' = v_r' - r u_c;   x' = u cos psi - v sin psi, y' = u sin psi + v cos psi, psi' = r  (1-3)

(eq. 5 printed ``x_G r``, read ``x_G r'``; SPEC.md 001 notes).

Hull forces (7-11), our reading (the printed forms omit the dynamic pressure; the drift-angle terms
are written with U^2 = u_r^2 + v_r^2 so that they vanish at rest), with the drift angle
beta = atan2(-v_r, u_r) (10) over all quadrants and the modified drift angle
alpha = beta - sgn(beta) alpha_0 (11), alpha_0 the drift angle of zero hull yaw moment:

    X_h = X_|u|u u_r|u_r| + X_vr v_r r + X_vv v_r^2 cos^2(beta) + X_rr r^2
    Y_h = Y_v |u_r| v_r + Y_r |u_r| r - m_x u_r r
          - rho/2 T C_D int_{-L/2}^{L/2} (v_r + C_Yr r x)|v_r + C_Yr r x| dx                    (8)
    N_h = rho/2 L^3 U^2 (-N'_v) (alpha_0/pi) sgn(beta) sin(2 phi(alpha)) + N_r |u_r| r
          - rho/2 T C_D int_{-L/2}^{L/2} (v_r + C_Nr r x)|v_r + C_Nr r x| x dx                  (9)

The drift resistance X_vv v^2 is given the factor cos^2(beta) (1 for small drift, as in Son &
Nomoto) so that pure sway, beta = +-90 deg, gives no surge force on the fore-aft symmetric model.
``Y_v |u_r| v_r`` is the lift (Y'_v v'U^2 with the forward speed |u_r|, so it keeps its sign astern,
which is what the modified drift angle does in 001). The drift moment is the Son-Nomoto N'_v v' U^2
for small beta, and over the whole circle a shape that is zero at beta = 0, +-alpha_0 and 180 deg:
phi maps |beta| in [0, alpha_0] to [0, pi/2] and [alpha_0, pi] to [pi/2, pi] linearly (so phi is
linear in alpha on each side). The cross-flow integrals (8, 9) are evaluated in closed form
(:func:`crossflow_integrals`), with the small-yaw limit where the closed form would cancel; 001
subtracts the pure-sway part ``L|v|v`` in (8) because its Y_|beta| term carries it; here the cubic
sway terms are not used and the whole integral is kept (Fossen 2011 sec. 6.4 cross-flow drag).

Rudder (12-15): F_N = rho/2 A_R f_alpha U_R^2 sin(alpha_R), f_alpha = 6.13 Lambda / (Lambda + 2.25),
alpha_R = delta + atan2(v_R, u_R) (001 prints delta + v_R/u_R, the small-angle form; atan2 also
covers astern flow), u_R^2 = eps^2 (u_P^2 + 8 kappa K_T n^2 D^2 / pi) ahead (the propeller race,
Son & Nomoto; 0 race for n <= 0), v_R = gamma_R v_r + c_Rr L r, and

    X_R = -(1 - t_R) F_N sin delta,  Y_R = -(1 + a_H) F_N cos delta,  N_R = -(x_R + a_H x_H) F_N cos delta.

Positive delta turns the ship to starboard (r > 0). Propeller (16, 17):
X_P = (1 - t_p) rho n|n| D^4 K_T(J), K_T = a1 + a2 J + a3 J^2, J = u_P / (|n| D),
u_P = (1 - w_p) u_r, expanded as rho (1-t_p)(a1 n|n| D^4 + a2 n u_P D^3 + a3 sgn(n) u_P^2 D^2) so it
is defined at n = 0. Thrusters (18-21): Y_Tb = b_B n_B|n_B|, Y_Ts = b_S n_S|n_S|,
N_T = x_TB Y_Tb + x_TS Y_Ts. Actuators (22-25): first-order lags of the clipped commands; the
rudder rate is also limited. Wind: relative wind loads (003 eq. 2.6-2.9 form,
:func:`oceangnc.models.usv.wind_load`) with container-ship windage areas.

State ``[x, y, psi, u, v, r, delta, n, n_B, n_S]`` (m, m, rad, m/s, m/s, rad/s, rad, rev/s x3);
inputs ``[delta_c, n_c, n_Bc, n_Sc, Vc_n, Vc_e, Vw_n, Vw_e]`` (rad, rev/s x3, m/s x4).
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit

from ..core.blocks import Plant
from ..core.fused import advance_and_publish, plant_bus_keys, rk4_stepper_imports
from ..core.signals import CALM
from ..core.csmath import cabs, catan2, ccos, csin, csqrt
from ..core.model import Model
from ..core.rotations import wrap
from .actuators import saturate
from ._hydro import relative_velocity, wind_load
from ._ship_params import *  # noqa: F403  (re-exported: the old import paths keep working)
from ._ship_params import INPUTS, INPUT_NAMES, LAYOUT, P, STATES, STATE_NAMES, ShipConfig, P_NAMES


# the parameter offsets compiled code uses, from the generated layout
# fmt: off
(
    _L, _T, _RHO, _M, _XG, _M11, _M1_11, _M1_12, _M1_21, _M1_22, _X_UU, _X_VR, _X_VV, _X_RR, _Y_V, _Y_R, _M_X,
    _NV_DRIFT, _N_R, _ALPHA0, _C_D, _C_YR, _C_NR, _A_R, _F_ALPHA, _T_R, _A_H, _X_H, _X_R, _GAMMA_R, _C_RR, _EPS, _KAPPA,
    _D, _T_P, _W_P, _A1, _A2, _A3, _B_B, _B_S, _X_TB, _X_TS, _TAU_P, _TAU_D, _TAU_TB, _TAU_TS, _N_MAX, _DELTA_MAX,
    _DELTA_RATE, _NB_MAX, _NS_MAX, _RHO_AIR, _A_F, _A_L, _L_OA, _C_X, _C_Y, _C_N
) = LAYOUT.indices(*P_NAMES)
# fmt: on


@njit(cache=True)
def _g3(w):
    return w * w * cabs(w) / 3.0


@njit(cache=True)
def _g4(w):
    return w * w * w * cabs(w) / 4.0


@njit(cache=True)
def crossflow_integrals(a, b, L):
    """Closed-form I0 = int (a + b x)|a + b x| dx and I1 = int x (a + b x)|a + b x| dx over [-L/2, L/2].

    With w = a + b x: I0 = [w^2|w|/3] / b and I1 = [w^3|w|/4 - a w^2|w|/3] / b^2 between the ends.
    For |b| L tiny against |a| the differences cancel; then the first-order limits
    I0 = L a|a|, I1 = |a| b L^3 / 6 are exact to O((bL/a)^2) (switch at |b| L/2 < 1e-4 |a|).
    """
    h = 0.5 * L
    if abs(b.real) * h.real <= 1e-4 * abs(a.real) or b == 0.0:
        return L * a * cabs(a), cabs(a) * b * L**3 / 6.0
    w1 = a + b * h
    w0 = a - b * h
    i0 = (_g3(w1) - _g3(w0)) / b
    i1 = ((_g4(w1) - _g4(w0)) - a * (_g3(w1) - _g3(w0))) / (b * b)
    return i0, i1


@njit(cache=True)
def _drift_shape(beta, alpha0):
    """sgn(beta) sin(2 phi): zero at beta = 0, +-alpha0, +-pi; slope pi/alpha0 at beta = 0."""
    ab = cabs(beta)
    if ab.real <= alpha0.real:
        phi = 0.5 * math.pi * ab / alpha0
    else:
        phi = 0.5 * math.pi + 0.5 * math.pi * (ab - alpha0) / (math.pi - alpha0)
    s = csin(2.0 * phi)
    return s if beta.real >= 0.0 else -s


@njit(cache=True)
def hull_forces(ur, vr, r, p):
    """Hull forces without added-mass terms (X_h, Y_h, N_h) of 001 eq. 7-11 (our reading), N, N, N m."""
    L = p[_L]
    T = p[_T]
    rho = p[_RHO]
    U2 = ur * ur + vr * vr
    X = p[_X_UU] * ur * cabs(ur) + p[_X_VR] * vr * r + p[_X_RR] * r * r
    if U2.real > 0.0:
        X += p[_X_VV] * vr * vr * ur * ur / U2  # X_vv v^2 cos^2(beta): zero in pure sway
    i0, _ = crossflow_integrals(vr, p[_C_YR] * r, L)
    _, i1 = crossflow_integrals(vr, p[_C_NR] * r, L)
    qcd = 0.5 * rho * T * p[_C_D]
    Y = p[_Y_V] * cabs(ur) * vr + p[_Y_R] * cabs(ur) * r - p[_M_X] * ur * r - qcd * i0
    N = p[_N_R] * cabs(ur) * r - qcd * i1
    if U2.real > 0.0:
        beta = catan2(-vr, ur)  # (10) over all quadrants
        alpha0 = p[_ALPHA0]
        N += -p[_NV_DRIFT] * U2 * (alpha0 / math.pi) * _drift_shape(beta, alpha0)
    return X, Y, N


@njit(cache=True)
def prop_thrust_coef(n, up, p):
    """n|n| D^4 K_T(J) expanded (defined at n = 0), with J = u_P/(|n| D): rev^2/s^2 m^4."""
    D = p[_D]
    sg = 1.0 if n.real > 0.0 else (-1.0 if n.real < 0.0 else 0.0)
    return p[_A1] * n * cabs(n) * D**4 + p[_A2] * n * up * D**3 + p[_A3] * sg * up * up * D * D


@njit(cache=True)
def propeller_thrust(n, ur, p):
    """X_P = (1 - t_p) rho n|n| D^4 K_T(J) (001 eq. 16, 17), N."""
    up = (1.0 - p[_W_P]) * ur
    return (1.0 - p[_T_P]) * p[_RHO] * prop_thrust_coef(n, up, p)


@njit(cache=True)
def rps_for_thrust(x_pd, ur, p, n_lim):
    """Shaft speed n (rev/s, |n| <= n_lim) whose thrust X_P(n) (001 eq. 16) equals x_pd (N), by bisection.

    X_P is monotonic in n except in a tiny band near n = 0 when K_T(J) < 0; bisection on the sign
    change from -n_lim to +n_lim always returns a root when one exists, else the nearer limit.
    """
    up = (1.0 - p[_W_P]) * ur
    k = (1.0 - p[_T_P]) * p[_RHO]
    target = x_pd / k
    lo = -n_lim
    hi = n_lim
    flo = prop_thrust_coef(lo, up, p) - target
    fhi = prop_thrust_coef(hi, up, p) - target
    if flo >= 0.0:
        return lo
    if fhi <= 0.0:
        return hi
    for _ in range(60):
        mid = 0.5 * (lo + hi)
        fm = prop_thrust_coef(mid, up, p) - target
        if fm > 0.0:
            hi = mid
        else:
            lo = mid
    return 0.5 * (lo + hi)


@njit(cache=True)
def rudder_inflow(ur, vr, r, n, p):
    """Rudder inflow (u_R, v_R) in m/s: propeller race ahead (Son & Nomoto), flow straightening."""
    up = (1.0 - p[_W_P]) * ur
    D = p[_D]
    eps = p[_EPS]
    race = 0.0
    if n.real > 0.0:
        kt2 = prop_thrust_coef(n, up, p) / D**4  # K_T n^2
        if kt2.real > 0.0:
            race = 8.0 * p[_KAPPA] * kt2 * D * D / math.pi
    uR2 = eps * eps * (up * up + race)
    uR = csqrt(uR2)
    if up.real < 0.0 and race.real < (up * up).real:
        uR = -uR
    vR = p[_GAMMA_R] * vr + p[_C_RR] * p[_L] * r
    return uR, vR


@njit(cache=True)
def rudder_normal_force(delta, ur, vr, r, n, p):
    """F_N = rho/2 A_R f_alpha U_R^2 sin(alpha_R), alpha_R = delta + atan2(v_R, u_R) (001 eq. 15), N."""
    uR, vR = rudder_inflow(ur, vr, r, n, p)
    UR2 = uR * uR + vR * vR
    if UR2 == 0.0:
        return 0.0
    return 0.5 * p[_RHO] * p[_A_R] * p[_F_ALPHA] * UR2 * csin(delta + catan2(vR, uR))


@njit(cache=True)
def rudder_forces(delta, ur, vr, r, n, p):
    """(X_R, Y_R, N_R) of 001 eq. 12-14, N and N m."""
    fn = rudder_normal_force(delta, ur, vr, r, n, p)
    c = ccos(delta)
    return (-(1.0 - p[_T_R]) * fn * csin(delta), -(1.0 + p[_A_H]) * fn * c, -(p[_X_R] + p[_A_H] * p[_X_H]) * fn * c)


@njit(cache=True)
def thruster_forces(nb, ns, p):
    """(Y_T, N_T) of 001 eq. 18-21, N and N m."""
    yb = p[_B_B] * nb * cabs(nb)
    ys = p[_B_S] * ns * cabs(ns)
    return yb + ys, p[_X_TB] * yb + p[_X_TS] * ys


@njit(cache=True)
def ship_rhs(t, x, u, p, out):
    """dx/dt of the ship (layouts in the module docstring)."""
    psi = x[2]
    uu = x[3]
    vv = x[4]
    r = x[5]
    delta = x[6]
    n = x[7]
    nb = x[8]
    ns = x[9]
    c = ccos(psi)
    s = csin(psi)
    ur, vr, uc, vc = relative_velocity(c, s, uu, vv, u[4], u[5])
    m = p[_M]
    xg = p[_XG]
    Xh, Yh, Nh = hull_forces(ur, vr, r, p)
    XR, YR, NR = rudder_forces(delta, ur, vr, r, n, p)
    XP = propeller_thrust(n, ur, p)
    YT, NT = thruster_forces(nb, ns, p)
    XW, YW, NW = wind_load(uu, vv, psi, u[6], u[7], p[_RHO_AIR], p[_A_F], p[_A_L], p[_L_OA], p[_C_X], p[_C_Y], p[_C_N])
    FX = m * (vr * r + xg * r * r) + Xh + XR + XP + XW
    FY = -m * ur * r + Yh + YR + YT + YW
    FN = -m * xg * ur * r + Nh + NR + NT + NW
    a11 = p[_M1_11]
    a12 = p[_M1_12]
    a21 = p[_M1_21]
    a22 = p[_M1_22]
    det = a11 * a22 - a12 * a21
    dvr = (a22 * FY - a12 * FN) / det
    dr = (-a21 * FY + a11 * FN) / det
    out[0] = c * uu - s * vv
    out[1] = s * uu + c * vv
    out[2] = r
    out[3] = FX / p[_M11] + r * vc
    out[4] = dvr - r * uc
    out[5] = dr
    dmax = p[_DELTA_MAX]
    rate = p[_DELTA_RATE]
    dd = (saturate(u[0], -dmax, dmax) - delta) / p[_TAU_D]
    out[6] = saturate(dd, -rate, rate)
    out[7] = (saturate(u[1], -p[_N_MAX], p[_N_MAX]) - n) / p[_TAU_P]
    out[8] = (saturate(u[2], -p[_NB_MAX], p[_NB_MAX]) - nb) / p[_TAU_TB]
    out[9] = (saturate(u[3], -p[_NS_MAX], p[_NS_MAX]) - ns) / p[_TAU_TS]


def inverse_mass(p) -> tuple[float, float, float, float]:
    """Entries (a, b, c, d) of M1^{-1} (001 eq. 35); c, d are the (2,1), (2,2) entries used in (34)."""
    a11, a12, a21, a22 = p[P["M1_11"]], p[P["M1_12"]], p[P["M1_21"]], p[P["M1_22"]]
    det = a11 * a22 - a12 * a21
    return a22 / det, -a12 / det, -a21 / det, a11 / det


def ship_model(cfg: ShipConfig | None = None, params=None) -> Model:
    """The S-175 low-speed ship (001 eq. 1-25) as a :class:`~oceangnc.core.model.Model` (outputs = states)."""
    p = (cfg or ShipConfig()).params() if params is None else np.asarray(params, dtype=np.float64)
    return Model(
        "ship",
        ship_rhs,
        STATES,
        INPUTS,
        LAYOUT,
        p,
        bound=1e8,
        description="S-175 container ship at low speed with rudder, propeller and tunnel thrusters",
    )


class ShipPlant(Plant):
    """The ship as a continuous plant.

    Publishes ``ship.x, ship.y`` (m, NED), ``ship.psi`` (rad, wrapped), ``ship.u, ship.v`` (m/s, over
    ground, body axes), ``ship.r`` (rad/s), ``ship.rudder`` (rad), ``ship.rpm_prop``,
    ``ship.rpm_bow``, ``ship.rpm_stern`` (rpm), ``ship.speed`` (m/s over ground) and
    ``ship.u_r, ship.v_r`` (m/s through the water).
    """

    def __init__(self, cfg: ShipConfig, name: str = "ship"):
        x0 = np.zeros(len(STATE_NAMES))
        x0[:] = [cfg.x0, cfg.y0, math.radians(cfg.psi0_deg), cfg.u0, 0.0, 0.0, 0.0, cfg.n0_rpm / 60.0, 0.0, 0.0]
        inputs = [k.replace("ship.", f"{name}.") for k in INPUT_NAMES]
        tau_min = min(cfg.tau_prop, cfg.tau_rudder, cfg.tau_thruster)
        super().__init__(
            **ship_model(cfg).plant_args(name, x0, inputs, declare=True),
            state_bound=1e8,
            max_dt=min(1.0, 2.5 * tau_min),
            input_defaults=CALM,
            outputs={
                **{
                    f"{name}.{k}": u
                    for k, u in (
                        *STATES[:6],  # x, y, psi, u, v, r
                        ("rudder", "rad"),
                        ("rpm_prop", "rpm"),
                        ("rpm_bow", "rpm"),
                        ("rpm_stern", "rpm"),
                        ("speed", "m/s"),
                        ("u_r", "m/s"),
                        ("v_r", "m/s"),
                    )
                }
            },
        )
        self.cfg = cfg
        self._out_keys = list(self.output_units)

    def publish(self, bus: dict) -> None:
        x = self.x
        out = ship_outputs(x, bus.get("env.current_n", 0.0), bus.get("env.current_e", 0.0))
        bus.update(zip(self._out_keys, out))

    def compiled_form(self, slot_of):
        """The fused loop's form: the RK4 stepper, then :func:`ship_publish` (the same
        :func:`ship_outputs` as :meth:`publish`; the current's slots -1 when nobody writes it)."""
        form = advance_and_publish(self, slot_of, rk4_stepper_imports(self.rhs), self._out_keys, ship_publish)
        bus = plant_bus_keys(slot_of)
        cur = [slot_of(k) if k in bus else -1 for k in ("env.current_n", "env.current_e")]
        form.args["oslots"] = np.append(form.args["oslots"], np.array(cur, dtype=np.int64))
        return form


@njit(cache=True)
def ship_outputs(x, cn, ce):
    """The signals :class:`ShipPlant` publishes, in the order of its outputs: x, y, psi (wrapped), u, v, r,
    rudder angle, shaft speeds (rpm), speed over ground and the velocity (u_r, v_r) relative to the
    current (cn, ce) (NED, m/s)."""
    ur, vr, _, _ = relative_velocity(math.cos(x[2]), math.sin(x[2]), x[3], x[4], cn, ce)
    return (x[0], x[1], wrap(x[2]), x[3], x[4], x[5], x[6], x[7] * 60.0, x[8] * 60.0, x[9] * 60.0,
            math.hypot(x[3], x[4]), ur, vr)  # fmt: skip


def simulate_open(
    cfg: ShipConfig, duration: float, cmds, dt: float = 0.1, env=(0.0, 0.0, 0.0, 0.0), x0=None
) -> np.ndarray:
    """Integrate the ship alone with constant commands ``cmds = (delta_c rad, n_c, n_Bc, n_Sc rev/s)``.

    Returns the state history (k+1, 10) at every ``dt``; one compiled call per sample (for checks and
    tests; the scenarios run the plant through the Simulation clock).
    """
    from ..core.integrators import rk4_advance, rk4_workspace

    p = cfg.params()
    x = np.array(x0, float) if x0 is not None else ShipPlant(cfg).x.copy()
    u = np.array([*cmds, *env], float)
    work = rk4_workspace(x.size)
    k = int(round(duration / dt))
    out = np.empty((k + 1, x.size))
    out[0] = x
    t = 0.0
    for i in range(k):
        t = rk4_advance(ship_rhs, t, x, u, p, dt, 1, work)
        out[i + 1] = x
    return out


@njit(cache=True)
def ship_publish(x, sig, slots):
    """:meth:`ShipPlant.publish` in the fused loop; slots 13, 14: the current (or -1)."""
    cn = sig[slots[13]] if slots[13] >= 0 else 0.0
    ce = sig[slots[14]] if slots[14] >= 0 else 0.0
    out = ship_outputs(x, cn, ce)
    for i in range(13):
        sig[slots[i]] = out[i]
