"""Joystick berthing controllers of document 001: open loop, PID (39-42) and nonlinear MIMO (27-38).

All three read the joystick block's outputs (``cmd.u_d`` m/s, ``cmd.r_d`` rad/s, or for the open
loop the filtered stick after the dead band ``joystick.surge_db``, ``joystick.yaw_db``) and the ship's signals
(``ship.u, ship.v, ship.r, ship.psi, ship.rudder, ship.rpm_prop``), and write the actuator commands
``ship.rudder_cmd`` (rad), ``ship.n_prop_cmd``, ``ship.n_bow_cmd``, ``ship.n_stern_cmd`` (rev/s),
plus ``ctrl.e_u`` (m/s) and ``ctrl.e_r`` (rad/s). An emergency stop (``_estop``) zeroes all commands.

* **Open loop** (001 fig. 3): the stick goes straight to the actuators,
  n_c = s_u n_open, delta_c = sat(s_y / s_R) delta_open, n_Bc = s_y n_B,max, n_Sc = -n_Bc. 001 gives
  no map; the rudder must also follow the stick since 001 reports a rudder index for the open loop:
  we chose the yaw axis to drive the rudder and both thrusters together, the rudder reaching its
  35 deg at half stick (s_R = 0.5: at berthing speeds the rudder is weak and only large angles do
  anything, the thrusters take the whole stick travel), and the surge axis as a throttle (full
  stick = ``n_open_rpm``).
* **PID** (001 eq. 39-42), e_u = u - u_d (29), e_r = r - r_d (32):
  n_c = -k_P,P e_u - k_P,I int e_u - k_P,D e_u',  delta_c = -k_r,P e_r - ..., n_Bc = -k_t,P e_r - ...,
  n_Sc = -n_Bc; the integrators have back-calculation anti-windup (:class:`oceangnc.control.pid.PID`).
* **Nonlinear** (001 eq. 27-38 with the SPEC corrections): surge by feedback linearisation with the
  scalar m0 = m - X_udot,
  X_Pd = m0 (u_d' - lambda1 e_u - r v_c) - [m (v_r r + x_G r^2) + X_h + X_R + X_W]      (31)
  and n_c from inverting X_P(n) (16) at the present inflow; yaw through the (2,1), (2,2) entries c, d of
  M1^-1 (35): u_rd = r_d' - lambda2 e_r - c F_Y0 - d F_N0 (34), F_Y0 = -m u_r r + Y_h + Y_W,
  F_N0 = -m x_G u_r r + N_h + N_W, allocated to rudder and thrusters by
  :func:`oceangnc.control.allocation.allocate` (36-38). u_d(s), r_d(s) are the joystick commands
  through a first-order setpoint filter (time constant ``t_ref``), which also gives the rates
  u_d', r_d' the laws need (a stepping stick has no derivative). The rudder turns at 2.3 deg/s
  (IMO) while 001's allocation would swing it from stop to stop at every sign change of u_rd, so
  by default (``rate_aware_rudder``) the optimisation (38) is done over the angles the rudder can
  reach by the next update and the thrusters make up the rest from the rudder angle actually there.
  With ideal actuators the closed loops obey
  e_u' + lambda1 e_u = 0 (30) and e_r' + lambda2 e_r = 0 (33). The model terms use the velocity
  through the water and the wind load, from the measured current and wind (``env.*``) when
  ``use_disturbance = True`` (what makes it better than the PID in current and wind; 001 only
  claims it "can" be); the -r v_c term converts the through-water dynamics to the ground-referenced
  speed the pilot commands (u = u_r + u_c, u' = u_r' + r v_c).
"""

from __future__ import annotations

import math
from typing import Literal

import numpy as np
from numba import njit
from pydantic import Field

from ..core.blocks import Block
from ..core.config import StrictModel
from ..core.estop import RESUME_RAMP_S, resume_weight
from ..core.law import In, LawBlock, Layout, Opt, Out, Signals
from ..core.registry import register_block
from ..models.ship_lowspeed import (
    LAYOUT,
    ShipConfig,
    hull_forces,
    inverse_mass,
    rps_for_thrust,
    rudder_forces,
    thruster_forces,
)
from ..models.usv import wind_load
from .allocation import allocate
from .pid import PID, PID_PARAMS, PID_STATE, pid_params, pid_run

#: offsets of the ship parameters used here, from the model's generated layout
(
    _RHO,
    _M,
    _XG,
    _M11,
    _T_P,
    _W_P,
    _TAU_D,
    _DELTA_MAX,
    _DELTA_RATE,
    _NB_MAX,
    _RHO_AIR,
    _A_F,
    _A_L,
    _L_OA,
    _C_X,
    _C_Y,
    _C_N,
) = LAYOUT.indices(
    "rho",
    "m",
    "xG",
    "m11",
    "t_p",
    "w_p",
    "tau_d",
    "delta_max",
    "delta_rate",
    "nB_max",
    "rho_air",
    "A_F",
    "A_L",
    "L_oa",
    "c_x",
    "c_y",
    "c_n",
)

CMD_KEYS = ("ship.rudder_cmd", "ship.n_prop_cmd", "ship.n_bow_cmd", "ship.n_stern_cmd")


class ControlConfig(StrictModel):
    """Controller choice and gains (none printed in 001; see docs/berthing.md for the reasoning)."""

    mode: Literal["open", "pid", "nonlinear"] = "nonlinear"
    period: float = Field(0.1, gt=0, le=5, description="controller period (001: 100 ms joystick cycle), s")
    # open loop
    n_open_rpm: float = Field(40.0, gt=0, le=1000, description="open loop: propeller rpm at full surge stick, rpm")
    delta_open_deg: float = Field(35.0, ge=0, le=45, description="open loop: rudder reached at rudder_open_stick, deg")
    rudder_open_stick: float = Field(
        0.5, gt=0, le=1, description="open loop: yaw stick giving the full open-loop rudder, stick units"
    )
    thruster_open: float = Field(1.0, ge=0, le=1, description="open loop: thruster fraction at full yaw stick, -")
    # PID gains, SI: rev/s per m/s, rad per rad/s, rev/s per rad/s (and per s / times s)
    kp_prop: float = Field(4.0, ge=0, le=1e4, description="k_P,P, rev/s per m/s")
    ki_prop: float = Field(0.08, ge=0, le=1e4, description="k_P,I, rev/s per m")
    kd_prop: float = Field(0.0, ge=0, le=1e4, description="k_P,D, rev/s per m/s^2")
    kp_rudder: float = Field(150.0, ge=0, le=1e6, description="k_r,P, rad per rad/s")
    ki_rudder: float = Field(3.0, ge=0, le=1e6, description="k_r,I, rad per rad")
    kd_rudder: float = Field(0.0, ge=0, le=1e6, description="k_r,D, rad per rad/s^2")
    kp_thruster: float = Field(1500.0, ge=0, le=1e7, description="k_t,P, rev/s per rad/s")
    ki_thruster: float = Field(40.0, ge=0, le=1e7, description="k_t,I, rev/s per rad")
    kd_thruster: float = Field(0.0, ge=0, le=1e7, description="k_t,D, rev/s per rad/s^2")
    # nonlinear
    lambda1: float = Field(0.1, gt=0, le=10, description="surge error decay rate lambda1 (30), 1/s")
    lambda2: float = Field(0.1, gt=0, le=10, description="yaw-rate error decay rate lambda2 (33), 1/s")
    u_switch: float = Field(0.4, ge=0, le=5, description="allocation switch speed (001: 0.4 m/s), m/s")
    t_ref: float = Field(
        10.0, ge=0, le=100, description="nonlinear: setpoint filter time constant for u_d(s), r_d(s) and rates, s"
    )
    rate_aware_rudder: bool = Field(
        True, description="nonlinear: search the rudder angle only within its rate-limited reach by the next update"
    )
    use_disturbance: bool = Field(True, description="nonlinear: use the measured current and wind in the model")
    n_limit_rpm: float = Field(100.0, gt=0, le=1000, description="closed loop: propeller command limit, rpm")


#: the commands every berthing controller writes, after its inputs and ``_estop``, in this order
_CMD_ROLES = {"rudder": Out("rad"), "n_prop": Out("Hz"), "n_bow": Out("Hz"), "n_stern": Out("Hz"),
              "e_u": Out("m/s"), "e_r": Out("rad/s")}  # fmt: skip
_CMD_KEYS = {"rudder": "ship.rudder_cmd", "n_prop": "ship.n_prop_cmd", "n_bow": "ship.n_bow_cmd",
             "n_stern": "ship.n_stern_cmd", "e_u": "ctrl.e_u", "e_r": "ctrl.e_r"}  # fmt: skip
_BASE_ROLES = {"u": In("m/s"), "r": In("rad/s"), "u_d": In("m/s"), "r_d": In("rad/s")}
_BASE_KEYS = {"u": "ship.u", "r": "ship.r", "u_d": "cmd.u_d", "r_d": "cmd.r_d", "estop": "_estop"}


@njit(cache=True)
def write_commands(sig, sl, o, stop, delta, n, nb, e_u, e_r, w=1.0):
    """Write the commands from slot ``o`` on: rudder (rad), propeller, bow and stern thrusters (rev/s,
    n_S = -n_B), all zero while ``stop``, the shaft speeds times the resume weight ``w``
    (:func:`oceangnc.core.estop.resume_weight`: no shaft step after an e-stop); then the errors e_u
    (m/s), e_r (rad/s)."""
    if stop:
        delta = 0.0
        n = 0.0
        nb = 0.0
    n *= w
    nb *= w
    sig[sl[o]] = delta
    sig[sl[o + 1]] = n
    sig[sl[o + 2]] = nb
    sig[sl[o + 3]] = -nb
    sig[sl[o + 4]] = e_u
    sig[sl[o + 5]] = e_r


class _Base(LawBlock):
    name = "controller"

    def _setup(self, cfg: ControlConfig, ship: ShipConfig, **extra_keys: str) -> None:
        self.cfg = cfg
        self.ship = ship
        self.p = ship.params()
        self.period = float(cfg.period)
        self.bind(**_BASE_KEYS, **_CMD_KEYS, **extra_keys)


@njit(cache=True)
def open_loop_control(su, sy, n_open_rpm, rudder_open_stick, delta_open, thruster_open, thruster_rpm_max):
    """(rudder rad, propeller rev/s, bow thruster rev/s) from the dead-banded stick (001 fig. 3);
    ``delta_open`` (rad) is reached at ``rudder_open_stick``, the stern thruster runs at minus the bow's."""
    n = su * n_open_rpm / 60.0
    delta = max(-1.0, min(1.0, sy / rudder_open_stick)) * delta_open
    nb = sy * thruster_open * thruster_rpm_max / 60.0
    return delta, n, nb


OPEN_SIGNALS = Signals(**_BASE_ROLES, surge=In("1"), yaw=In("1"), estop=Opt("bool"), **_CMD_ROLES)
OPEN_PARAMS = Layout("n_open_rpm", "rudder_open_stick", "delta_open", "thruster_open", "thruster_rpm_max", "h")
OPEN_STATE = Layout("w")
_OS, _OP, _OX = OPEN_SIGNALS.at, OPEN_PARAMS.at, OPEN_STATE.at


@njit(cache=True)
def open_loop_law(t, sig, sl, st, pa):
    """Stick straight to propeller, rudder and thrusters (001 fig. 3, :func:`open_loop_control`); zero
    on ``_estop`` and the shaft speeds ramped back after it (:mod:`oceangnc.core.estop`)."""
    delta, n, nb = open_loop_control(sig[sl[_OS.surge]], sig[sl[_OS.yaw]], pa[_OP.n_open_rpm],
                                     pa[_OP.rudder_open_stick], pa[_OP.delta_open], pa[_OP.thruster_open],
                                     pa[_OP.thruster_rpm_max])  # fmt: skip
    stop = sl[_OS.estop] >= 0 and sig[sl[_OS.estop]] != 0.0
    st[_OX.w] = resume_weight(st[_OX.w], stop, pa[_OP.h], RESUME_RAMP_S)
    e_u = sig[sl[_OS.u]] - sig[sl[_OS.u_d]]
    e_r = sig[sl[_OS.r]] - sig[sl[_OS.r_d]]
    write_commands(sig, sl, _OS.rudder, stop, delta, n, nb, e_u, e_r, st[_OX.w])


@register_block("ship.open")
class OpenLoopController(_Base):
    """Stick straight to propeller, rudder and thrusters (001 fig. 3); see the module docstring; law
    :func:`open_loop_law`."""

    role = "controller"
    law = staticmethod(open_loop_law)
    signals = OPEN_SIGNALS

    def __init__(self, cfg: ControlConfig, ship: ShipConfig):
        self._setup(cfg, ship, surge="joystick.surge_db", yaw="joystick.yaw_db")
        self.pa = OPEN_PARAMS.pack(n_open_rpm=cfg.n_open_rpm, rudder_open_stick=cfg.rudder_open_stick,
                                   delta_open=math.radians(cfg.delta_open_deg), thruster_open=cfg.thruster_open,
                                   thruster_rpm_max=ship.thruster_rpm_max, h=self.period)  # fmt: skip
        self.st = OPEN_STATE.pack(w=1.0)

    def reset(self, rng) -> None:
        self.st[_OX.w] = 1.0


PID_SIGNALS = Signals(**_BASE_ROLES, estop=Opt("bool"), **_CMD_ROLES)
BERTH_PID_PARAMS = Layout(("n", PID_PARAMS.size), ("d", PID_PARAMS.size), ("t", PID_PARAMS.size), "h")
BERTH_PID_STATE = Layout(("n", PID_STATE.size), ("d", PID_STATE.size), ("t", PID_STATE.size), "w")
_PS, _PP, _PX = PID_SIGNALS.at, BERTH_PID_PARAMS.at, BERTH_PID_STATE.at


@njit(cache=True)
def berthing_pid_law(t, sig, sl, st, pa):
    """One PID per actuator (001 eq. 39-42) on e_u = u - u_d and e_r = r - r_d: n_c = PID(-e_u) (rev/s),
    delta_c = PID(-e_r) (rad), n_B = PID(-e_r) (rev/s), n_S = -n_B. While ``_estop`` is set the commands
    are zero and no PID moves; after it their outputs ramp back (:mod:`oceangnc.core.estop`)."""
    h = pa[_PP.h]
    e_u = sig[sl[_PS.u]] - sig[sl[_PS.u_d]]
    e_r = sig[sl[_PS.r]] - sig[sl[_PS.r_d]]
    if sl[_PS.estop] >= 0 and sig[sl[_PS.estop]] != 0.0:
        st[_PX.w] = 0.0
        write_commands(sig, sl, _PS.rudder, True, 0.0, 0.0, 0.0, e_u, e_r)
        return
    w = st[_PX.w] = resume_weight(st[_PX.w], False, h, RESUME_RAMP_S)
    n = pid_run(st, _PX.n, pa, _PP.n, -e_u, h, 0.0, False, 0.0, w)
    delta = pid_run(st, _PX.d, pa, _PP.d, -e_r, h, 0.0, False, 0.0, w)
    nb = pid_run(st, _PX.t, pa, _PP.t, -e_r, h, 0.0, False, 0.0, w)
    write_commands(sig, sl, _PS.rudder, False, delta, n, nb, e_u, e_r)


@register_block("ship.pid")
class PIDController(_Base):
    """PID per actuator, 001 eq. 39-42 (n_S = -n_B); law :func:`berthing_pid_law`. ``pid_n``,
    ``pid_d``, ``pid_t`` are :class:`~oceangnc.control.pid.PID` views of its state."""

    role = "controller"
    law = staticmethod(berthing_pid_law)
    signals = PID_SIGNALS

    def __init__(self, cfg: ControlConfig, ship: ShipConfig):
        self._setup(cfg, ship)
        c, p = cfg, self.p
        nlim = c.n_limit_rpm / 60.0
        self.pa = BERTH_PID_PARAMS.pack(
            n=PID_PARAMS.pack(pid_params(c.kp_prop, c.ki_prop, c.kd_prop, -nlim, nlim)),
            d=PID_PARAMS.pack(pid_params(c.kp_rudder, c.ki_rudder, c.kd_rudder, -p[_DELTA_MAX], p[_DELTA_MAX])),
            t=PID_PARAMS.pack(pid_params(c.kp_thruster, c.ki_thruster, c.kd_thruster, -p[_NB_MAX], p[_NB_MAX])),
            h=self.period,
        )
        self.st = np.zeros(BERTH_PID_STATE.size)
        self.reset(None)
        self.pid_n = PID.view(self.st, _PX.n, self.pa, _PP.n)
        self.pid_d = PID.view(self.st, _PX.d, self.pa, _PP.d)
        self.pid_t = PID.view(self.st, _PX.t, self.pa, _PP.t)

    def reset(self, rng) -> None:
        self.st[:] = 0.0
        self.st[_PX.w] = 1.0


NL_SIGNALS = Signals(
    **_BASE_ROLES, v=In("m/s"), psi=In("rad"), rudder_now=In("rad"), rpm_prop=In("rpm"),
    current_n=Opt("m/s"), current_e=Opt("m/s"), wind_n=Opt("m/s"), wind_e=Opt("m/s"), estop=Opt("bool"),
    **_CMD_ROLES, u_rd=Out("m/s"), u_d_f=Out("m/s"), r_d_f=Out("rad/s"), x_pd=Out("N"),
)  # fmt: skip
NL_HEAD = Layout("h", "t_ref", "use_dist", "lambda1", "lambda2", "n_limit", "rate_aware", "u_switch", "c", "d")
NL_STATE = Layout("u_d", "r_d", "has", "w")
_NS, _NP, _NX = NL_SIGNALS.at, NL_HEAD.at, NL_STATE.at
_SHIP = NL_HEAD.size  #: the ship's parameter array (:data:`oceangnc.models.ship_lowspeed.LAYOUT`) from here on


@njit(cache=True)
def nonlinear_law(t, sig, sl, st, pa):
    """Feedback-linearising MIMO controller (001 eq. 27-38 with the SPEC corrections; module
    docstring): set points through the filter T u_d' = u_cmd - u_d (exact discretisation; the first
    command initialises it), the surge force X_pd of (29)-(31) and the propeller speed giving it,
    the yaw-rate pseudo-input u_rd of (32)-(34) allocated to rudder and bow thruster, current and wind
    in the model when ``use_disturbance``. Commands zero while ``_estop`` is set, the shaft speeds
    ramped back after it (:mod:`oceangnc.core.estop`)."""
    p = pa[_SHIP:]
    h = pa[_NP.h]
    t_ref = pa[_NP.t_ref]
    u = sig[sl[_NS.u]]
    v = sig[sl[_NS.v]]
    r = sig[sl[_NS.r]]
    psi = sig[sl[_NS.psi]]
    delta = sig[sl[_NS.rudder_now]]
    n = sig[sl[_NS.rpm_prop]] / 60.0
    u_cmd = sig[sl[_NS.u_d]]
    r_cmd = sig[sl[_NS.r_d]]
    if st[_NX.has] == 0.0:
        st[_NX.u_d] = u_cmd
        st[_NX.r_d] = r_cmd
        st[_NX.has] = 1.0
    if t_ref > 0:
        a = math.exp(-h / t_ref)
        ud_dot = (u_cmd - st[_NX.u_d]) / t_ref
        rd_dot = (r_cmd - st[_NX.r_d]) / t_ref
        u_d, r_d = st[_NX.u_d], st[_NX.r_d]
        st[_NX.u_d] = u_cmd + a * (st[_NX.u_d] - u_cmd)
        st[_NX.r_d] = r_cmd + a * (st[_NX.r_d] - r_cmd)
    else:
        u_d, r_d, ud_dot, rd_dot = u_cmd, r_cmd, 0.0, 0.0
    cn = ce = wn = we = 0.0
    if pa[_NP.use_dist] != 0.0:
        cn = sig[sl[_NS.current_n]] if sl[_NS.current_n] >= 0 else 0.0
        ce = sig[sl[_NS.current_e]] if sl[_NS.current_e] >= 0 else 0.0
        wn = sig[sl[_NS.wind_n]] if sl[_NS.wind_n] >= 0 else 0.0
        we = sig[sl[_NS.wind_e]] if sl[_NS.wind_e] >= 0 else 0.0
    cps, sps = math.cos(psi), math.sin(psi)
    uc = cps * cn + sps * ce
    vc = -sps * cn + cps * ce
    ur, vr = u - uc, v - vc
    m, xg = p[_M], p[_XG]
    Xh, Yh, Nh = hull_forces(ur, vr, r, p)
    XR, _, _ = rudder_forces(delta, ur, vr, r, n, p)
    XW, YW, NW = wind_load(u, v, psi, wn, we, p[_RHO_AIR], p[_A_F], p[_A_L], p[_L_OA], p[_C_X], p[_C_Y], p[_C_N])
    # surge (29)-(31)
    e_u = u - u_d
    x_pd = p[_M11] * (ud_dot - pa[_NP.lambda1] * e_u - r * vc) - (m * (vr * r + xg * r * r) + Xh + XR + XW)
    n_c = rps_for_thrust(x_pd, ur, p, pa[_NP.n_limit])
    # yaw rate (32)-(34)
    e_r = r - r_d
    fy0 = -m * ur * r + Yh + YW
    fn0 = -m * xg * ur * r + Nh + NW
    c = pa[_NP.c]
    d = pa[_NP.d]
    u_rd = rd_dot - pa[_NP.lambda2] * e_r - c * fy0 - d * fn0
    if pa[_NP.rate_aware] != 0.0:
        reach = p[_DELTA_RATE] * max(h, p[_TAU_D])
        delta_c, nb_c = allocate(u_rd, ur, vr, r, n, c, d, p, pa[_NP.u_switch], 21, delta - reach, delta + reach)
    else:
        delta_c, nb_c = allocate(u_rd, ur, vr, r, n, c, d, p, pa[_NP.u_switch], 71, -p[_DELTA_MAX], p[_DELTA_MAX])
    stop = sl[_NS.estop] >= 0 and sig[sl[_NS.estop]] != 0.0
    st[_NX.w] = resume_weight(st[_NX.w], stop, h, RESUME_RAMP_S)
    write_commands(sig, sl, _NS.rudder, stop, delta_c, n_c, nb_c, e_u, e_r, st[_NX.w])
    sig[sl[_NS.u_rd]] = u_rd
    sig[sl[_NS.u_d_f]] = u_d
    sig[sl[_NS.r_d_f]] = r_d
    sig[sl[_NS.x_pd]] = x_pd


@register_block("ship.nonlinear")
class NonlinearController(_Base):
    """Feedback-linearising MIMO controller, 001 eq. 27-38 (SPEC corrections); module docstring; law
    :func:`nonlinear_law`."""

    role = "controller"
    law = staticmethod(nonlinear_law)
    signals = NL_SIGNALS

    def __init__(self, cfg: ControlConfig, ship: ShipConfig):
        self._setup(cfg, ship, v="ship.v", psi="ship.psi", rudder_now="ship.rudder", rpm_prop="ship.rpm_prop",
                    current_n="env.current_n", current_e="env.current_e", wind_n="env.wind_n", wind_e="env.wind_e",
                    u_rd="ctrl.u_rd", u_d_f="ctrl.u_d", r_d_f="ctrl.r_d", x_pd="ctrl.x_pd")  # fmt: skip
        a, b, self.c, self.d = inverse_mass(self.p)
        head = NL_HEAD.pack(
            h=self.period,
            t_ref=cfg.t_ref,
            use_dist=float(cfg.use_disturbance),
            lambda1=cfg.lambda1,
            lambda2=cfg.lambda2,
            n_limit=cfg.n_limit_rpm / 60.0,
            rate_aware=float(cfg.rate_aware_rudder),
            u_switch=cfg.u_switch,
            c=self.c,
            d=self.d,
        )
        self.pa = np.concatenate([head, self.p])
        self.st = NL_STATE.pack(u_d=0.0, r_d=0.0, has=0.0, w=1.0)

    def reset(self, rng) -> None:
        self.st[:] = NL_STATE.pack(u_d=0.0, r_d=0.0, has=0.0, w=1.0)


def make_controller(cfg: ControlConfig, ship: ShipConfig) -> Block:
    """The controller block selected by ``cfg.mode``: the kind ``ship.<mode>`` of the block registry."""
    from ..core.registry import lookup

    return lookup(f"ship.{cfg.mode}", "control.mode")(cfg, ship)


def actuator_moment_check(ship: ShipConfig, delta: float, n: float, nb: float, ur: float, vr: float, r: float):
    """c(Y_R + Y_T) + d(N_R + N_T) for given actuators (n_S = -n_B): the left side of 001 eq. 34."""
    p = ship.params()
    _, _, c, d = inverse_mass(p)
    _, YR, NR = rudder_forces(delta, ur, vr, r, n, p)
    YT, NT = thruster_forces(nb, -nb, p)
    return c * (YR + YT) + d * (NR + NT)


__all__ = [
    "ControlConfig",
    "OpenLoopController",
    "PIDController",
    "NonlinearController",
    "make_controller",
    "rps_for_thrust",
    "CMD_KEYS",
    "actuator_moment_check",
]
