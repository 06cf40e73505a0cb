"""USV of document 003 ch. 2.1: a 3 m rubber boat with two stern thrusters, 3-DOF maneuvering model.

Equations (003 eq. 2.3, with the printed ``d22 u`` typo read as ``d22 v``), written on the velocity
relative to the water nu_r = (u_r, v_r, r), nu_r = nu - R(psi)^T v_c (003 eq. 2.12):

    m11 u_r' - m22 v_r r + (d11 + d11_rr r^2) u_r = X
    m22 v_r' + m11 u_r r + d22 v_r               = Y
    m33 r'   + (m22 - m11) u_r v_r + d33 r       = N

and the kinematics x' = u cos psi - v sin psi, y' = u sin psi + v cos psi, psi' = r (NED). For a
uniform current fixed in the earth frame, u_c' = r v_c and v_c' = -r u_c, so the ground-frame body
velocities obey u' = u_r' + r v_c, v' = v_r' - r u_c.

Forces (003 eq. 2.4, 2.6-2.9): X = T_p + T_s + X_wind, Y = Y_wind, N = (T_p - T_s) B/2 + N_wind, with
the relative wind u_rw = u - u_w, v_rw = v - v_w (u_w, v_w the wind's velocity in body axes), angle
gamma = -atan2(v_rw, u_rw), V_rw = |(u_rw, v_rw)|, and

    X_wind = -1/2 rho_a V_rw^2 c_x cos(gamma) A_T
    Y_wind =  1/2 rho_a V_rw^2 c_y sin(gamma) A_L
    N_wind =  1/2 rho_a V_rw^2 c_n sin(2 gamma) A_L L_OA.

Choice of coefficients (003 prints none; see docs/parameters.md). m11, m22, m33 are the boat's
200 kg and a rigid-body yaw inertia m (L^2 + B^2)/12 plus typical added mass (5 % in surge, 50 % in
sway, 20 % in yaw). The damping is *calibrated* by :func:`calibrate` to reproduce 003 figs 2-7/2-8:
0.8 m/s straight ahead at 30 + 30 kgf, and a 1.75 m turning circle at 16 deg/s with 30 / 15 kgf. The
paper's linear model cannot lose the 20 % of speed that the turn needs with any physical sway mass,
so a turning resistance d11_rr r^2 u_r (the X_rr / X_vr terms of MMG-type models) is added; the drift
angle in the turn is set to 15 deg, typical of tight turns, which fixes d22.

State layout ``x = [x_n, y_e, psi, u, v, r]`` (m, m, rad, m/s, m/s, rad/s); inputs
``u = [T_port, T_stbd, Vc_n, Vc_e, Vw_n, Vw_e]`` (N, N, m/s x4); parameter layout :data:`LAYOUT`
(generated from the declared names). :func:`usv_model` is the :class:`~oceangnc.core.model.Model`
(the plant, :func:`steady_turn` (trim) and the EKF all use it); the right-hand side is written with
:mod:`oceangnc.core.csmath`, so its Jacobians are exact by complex step.
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit
from pydantic import Field

from ..core.blocks import Plant, scatter
from ..core.fused import advance_and_publish, rk4_stepper_imports
from ..core.signals import CALM
from ..core.csmath import ccos, csin
from ..core.model import Model, Param, ParamLayout
from ..core.rotations import heading_speed
from ..io.config import StrictModel
from ._hydro import relative_velocity, wind_load
from .actuators import ThrusterBank
from ..units import KGF, RHO_AIR

STATES = (("x", "m"), ("y", "m"), ("psi", "rad"), ("u", "m/s"), ("v", "m/s"), ("r", "rad/s"))
INPUTS = (
    ("thrust_port", "N"),
    ("thrust_stbd", "N"),
    ("current_n", "m/s"),
    ("current_e", "m/s"),
    ("wind_n", "m/s"),
    ("wind_e", "m/s"),
)
STATE_NAMES = tuple(k for k, _ in STATES)
#: bus signals of the inputs (``usv.`` is replaced by the plant's name)
INPUT_NAMES = ("usv.thrust_port", "usv.thrust_stbd", "env.current_n", "env.current_e", "env.wind_n", "env.wind_e")
#: parameters (003 eq. 2.3-2.9), in this order in ``p``
LAYOUT = ParamLayout(
    [
        Param("m11", "kg", description="surge mass incl. added mass"),
        Param("m22", "kg", description="sway mass"),
        Param("m33", "kg m^2", description="yaw inertia incl. added inertia"),
        Param("d11", "N s/m", description="linear surge damping"),
        Param("d22", "N s/m", description="linear sway damping"),
        Param("d33", "N m s", description="linear yaw damping"),
        Param("d11_rr", "N s^3/m", description="surge resistance due to turning"),
        Param("thruster_spacing", "m"),
        Param("rho_air", "kg/m^3"),
        Param("area_front", "m^2"),
        Param("area_side", "m^2"),
        Param("length_oa", "m"),
        Param("c_x", "1"),
        Param("c_y", "1"),
        Param("c_n", "1"),
    ]
)
P_NAMES = LAYOUT.names
(_M11, _M22, _M33, _D11, _D22, _D33, _D11RR, _SPACING, _RHOA, _AF, _AL, _LOA, _CX, _CY, _CN) = LAYOUT.indices(*P_NAMES)


class USVConfig(StrictModel):
    """USV parameters (003 ch. 2.1, tables 2-2 and 2-3) and initial state."""

    mass: float = Field(200.0, gt=0, le=1e5, description="mass in air, kg")
    m11: float = Field(210.0, gt=0, le=1e6, description="surge mass incl. added mass m - X_udot, kg")
    m22: float = Field(300.0, gt=0, le=1e6, description="sway mass incl. added mass m - Y_vdot, kg")
    m33: float = Field(247.0, gt=0, le=1e7, description="yaw inertia incl. added inertia Iz - N_rdot, kg m2")
    d11: float = Field(735.5, gt=0, le=1e6, description="linear surge damping, N s/m")
    d22: float = Field(218.9, gt=0, le=1e6, description="linear sway damping, N s/m")
    d33: float = Field(335.3, gt=0, le=1e6, description="linear yaw damping, N m s")
    d11_rr: float = Field(2268.8, ge=0, le=1e7, description="surge resistance due to turning, N s3/m")
    thruster_spacing: float = Field(1.2, gt=0, le=10, description="distance B between the stern thrusters, m")
    length_oa: float = Field(3.0, gt=0, le=100, description="length overall, m")
    beam: float = Field(1.82, gt=0, le=50, description="beam (table 2-2), m")
    area_front: float = Field(0.87, gt=0, le=100, description="frontal projected wind area A_T, m2")
    area_side: float = Field(1.44, gt=0, le=500, description="lateral projected wind area A_L, m2")
    c_x: float = Field(0.7, ge=0.5, le=0.9, description="wind surge coefficient (003: 0.5-0.9)")
    c_y: float = Field(0.825, ge=0.7, le=0.95, description="wind sway coefficient (003: 0.7-0.95)")
    c_n: float = Field(0.125, ge=0.05, le=0.2, description="wind yaw coefficient (003: 0.05-0.2)")
    rho_air: float = Field(RHO_AIR, gt=0, le=2, description="air density, kg/m3")
    max_thrust_kgf: float = Field(36.2, gt=0, le=1000, description="forward thrust limit per thruster, kgf")
    max_reverse_kgf: float = Field(13.83, ge=0, le=1000, description="reverse thrust limit per thruster, kgf")
    x0: float = Field(0.0, ge=-1e6, le=1e6, description="initial north position, m")
    y0: float = Field(0.0, ge=-1e6, le=1e6, description="initial east position, m")
    psi0_deg: float = Field(0.0, ge=-360, le=360, description="initial heading, deg")
    u0: float = Field(0.0, ge=-5, le=10, description="initial surge speed, m/s")

    def params(self) -> np.ndarray:
        """Flat parameter array in the layout :data:`LAYOUT`."""
        return LAYOUT.pack({k: getattr(self, k) for k in P_NAMES})


@njit(cache=True)
def usv_rhs(t, x, u, p, out):
    """dx/dt of the USV (see module docstring for the layouts)."""
    psi = x[2]
    uu = x[3]
    vv = x[4]
    r = x[5]
    c = ccos(psi)
    s = csin(psi)
    ur, vr, uc, vc = relative_velocity(c, s, uu, vv, u[2], u[3])
    m11 = p[_M11]
    m22 = p[_M22]
    m33 = p[_M33]
    xw, yw, nw = wind_load(uu, vv, psi, u[4], u[5], p[_RHOA], p[_AF], p[_AL], p[_LOA], p[_CX], p[_CY], p[_CN])
    X = u[0] + u[1] + xw
    Y = yw
    N = (u[0] - u[1]) * 0.5 * p[_SPACING] + nw
    dur = (X + m22 * vr * r - (p[_D11] + p[_D11RR] * r * r) * ur) / m11
    dvr = (Y - m11 * ur * r - p[_D22] * vr) / m22
    dr = (N - (m22 - m11) * ur * vr - p[_D33] * r) / m33
    out[0] = c * uu - s * vv
    out[1] = s * uu + c * vv
    out[2] = r
    out[3] = dur + r * vc
    out[4] = dvr - r * uc
    out[5] = dr


def usv_model(cfg: USVConfig | None = None, params=None) -> Model:
    """The USV of 003 ch. 2.1 as a :class:`~oceangnc.core.model.Model` (outputs = states)."""
    p = (cfg or USVConfig()).params() if params is None else np.asarray(params, dtype=np.float64)
    return Model(
        "usv",
        usv_rhs,
        STATES,
        INPUTS,
        LAYOUT,
        p,
        bound=1e7,
        description="003 3 m USV, 3-DOF (eq. 2.3-2.12): states x, y, psi, u, v, r",
    )


class USVPlant(Plant):
    """The USV as a continuous plant; publishes ``usv.<x,y,psi,u,v,r>`` and ``usv.speed`` (m/s)."""

    def __init__(self, cfg: USVConfig, name: str = "usv"):
        x0 = np.array([cfg.x0, cfg.y0, math.radians(cfg.psi0_deg), cfg.u0, 0.0, 0.0])
        inputs = [k.replace("usv.", f"{name}.") for k in INPUT_NAMES]
        super().__init__(
            **usv_model(cfg).plant_args(name, x0, inputs, declare=True),
            state_bound=1e7,
            input_defaults=CALM,
            extra_outputs={f"{name}.speed": "m/s"},
        )
        self.cfg = cfg
        self._out_keys = [f"{name}.{k}" for k in (*self.state_names, "speed")]
        self._out = np.zeros(len(self._out_keys))
        self._out_slots = np.arange(len(self._out_keys), dtype=np.int64)

    def publish(self, bus: dict) -> None:
        """The states, psi wrapped, and the speed (m/s): :func:`usv_publish`, as the fused loop."""
        usv_publish(self.x, self._out, self._out_slots)
        bus.update(zip(self._out_keys, self._out.tolist()))

    def compiled_form(self, slot_of):
        """The fused loop's form: the RK4 stepper of the model, then :func:`usv_publish`."""
        return advance_and_publish(self, slot_of, rk4_stepper_imports(self.rhs), self._out_keys, usv_publish)


@njit(cache=True)
def usv_publish(x, sig, slots):
    """The USV plant's outputs: the six states, then psi wrapped to [-pi, pi) and the speed (m/s)."""
    scatter(x[:6], sig, slots[:6])
    sig[slots[2]], sig[slots[6]] = heading_speed(x, 2, 3, 2)


class USVThrusters(ThrusterBank):
    """The USV's two thrusters: commanded thrust (N) or DAC voltage (V) -> saturated thrust (N).

    Reads ``usv.thrust_port_cmd`` / ``usv.thrust_stbd_cmd`` (N) when ``mode == "thrust"``, or
    ``usv.volt_port_cmd`` / ``usv.volt_stbd_cmd`` (V, 0.05-4.68) through the thrust-voltage curve
    (003 eq. 2.5, :func:`oceangnc.models.actuators.usv_thrust_from_voltage`) when ``mode ==
    "voltage"``; writes ``usv.thrust_port`` / ``usv.thrust_stbd`` (N) limited to
    [-max_reverse, +max_thrust]. An emergency stop (``_estop`` on the bus) zeroes both at once; the
    thrust ramps back over 2 s after it (:func:`oceangnc.models.actuators.thrusters_law`).
    """

    name = "usv_thrusters"

    def __init__(self, cfg: USVConfig, period: float = 0.01, mode: str = "thrust", body: str = "usv"):
        hi, lo = cfg.max_thrust_kgf * KGF, -cfg.max_reverse_kgf * KGF
        super().__init__(body, ("port", "stbd"), hi, lo, period, voltage=mode == "voltage")


def steady_turn(cfg: USVConfig, t_port: float, t_stbd: float, jacobian: str | None = None, interpreted: bool = False):
    """Steady-state (u, v, r) of the USV in calm water for constant thrusts (N): :func:`oceangnc.core.linearize.trim`
    of the surge, sway and yaw equations (Newton with the exact complex-step Jacobian, or ``jacobian``,
    one of :data:`oceangnc.core.jacobians.JACOBIAN_MODES`; ``interpreted``: the model's Python body,
    compiling nothing, with ``jacobian="finite-difference"``)."""
    from ..core.linearize import trim

    res = trim(
        usv_model(cfg),
        [0.0, 0.0, 0.0, 0.5, 0.0, 0.1],
        [t_port, t_stbd, 0.0, 0.0, 0.0, 0.0],
        free=("u", "v", "r"),
        zero=("u", "v", "r"),
        tol=1e-13,
        jacobian=jacobian,
        interpreted=interpreted,
    )
    return float(res.x[3]), float(res.x[4]), float(res.x[5])


def calibrate(
    m11=210.0,
    m22=300.0,
    m33=247.0,
    spacing=1.2,
    straight_kgf=30.0,
    straight_speed=0.8,
    turn_kgf=(30.0, 15.0),
    radius=1.75,
    yaw_rate_degps=16.0,
    drift_deg=15.0,
) -> dict:
    """Damping that makes the model reproduce 003 figs 2-7/2-8 (see module docstring).

    Straight: d11 U = 2 T. Turn, with U = R r, u = U cos(beta), v = -U sin(beta):
    the sway equation gives d22, the yaw equation d33 and the surge equation d11_rr.
    """
    T = straight_kgf * KGF
    d11 = 2 * T / straight_speed
    r = math.radians(yaw_rate_degps)
    U = radius * r
    beta = math.radians(drift_deg)
    uu, vv = U * math.cos(beta), -U * math.sin(beta)
    tp, ts = turn_kgf[0] * KGF, turn_kgf[1] * KGF
    d22 = -m11 * uu * r / vv
    d33 = ((tp - ts) * spacing / 2 - (m22 - m11) * uu * vv) / r
    d11_rr = (tp + ts + m22 * vv * r - d11 * uu) / (r * r * uu)
    return {"d11": d11, "d22": d22, "d33": d33, "d11_rr": d11_rr}
