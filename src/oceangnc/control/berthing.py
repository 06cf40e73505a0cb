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

from pydantic import Field

from ..core.blocks import Block
from ..core.registry import register_block
from ..io.config import StrictModel
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
from .pid import PID

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
#: the outputs every berthing controller writes, in the order of the compiled kernels' slots
_OUT = (*CMD_KEYS, "ctrl.e_u", "ctrl.e_r")


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


class _Base(Block):
    name = "controller"

    def __init__(self, cfg: ControlConfig, ship: ShipConfig):
        self.cfg = cfg
        self.ship = ship
        self.p = ship.params()
        self.period = float(cfg.period)
        self.inputs = {"ship.u": "m/s", "ship.r": "rad/s", "cmd.u_d": "m/s", "cmd.r_d": "rad/s"}
        self.optional_inputs = {"_estop": "bool"}
        self.outputs = {
            "ship.rudder_cmd": "rad",
            "ship.n_prop_cmd": "Hz",
            "ship.n_bow_cmd": "Hz",
            "ship.n_stern_cmd": "Hz",
            "ctrl.e_u": "m/s",
            "ctrl.e_r": "rad/s",
        }

    def _write(self, bus, delta, n, nb, ns, e_u, e_r):
        if bus.get("_estop", False):
            delta = n = nb = ns = 0.0
        bus["ship.rudder_cmd"] = float(delta)
        bus["ship.n_prop_cmd"] = float(n)
        bus["ship.n_bow_cmd"] = float(nb)
        bus["ship.n_stern_cmd"] = float(ns)
        bus["ctrl.e_u"] = float(e_u)
        bus["ctrl.e_r"] = float(e_r)


@register_block("ship.open")
class OpenLoopController(_Base):
    """Stick straight to propeller, rudder and thrusters (001 fig. 3); see the module docstring."""

    role = "controller"

    def __init__(self, cfg: ControlConfig, ship: ShipConfig):
        super().__init__(cfg, ship)
        self.inputs.update({"joystick.surge_db": "1", "joystick.yaw_db": "1"})

    def _law_params(self) -> list[float]:
        c = self.cfg
        return [
            c.n_open_rpm,
            c.rudder_open_stick,
            math.radians(c.delta_open_deg),
            c.thruster_open,
            self.ship.thruster_rpm_max,
        ]

    def step(self, t, bus):
        from ._compiled_berthing_modes import open_loop_law

        delta, n, nb = open_loop_law(
            float(bus["joystick.surge_db"]), float(bus["joystick.yaw_db"]), *self._law_params()
        )
        e_u = bus["ship.u"] - bus["cmd.u_d"]
        e_r = bus["ship.r"] - bus["cmd.r_d"]
        self._write(bus, delta, n, nb, -nb, e_u, e_r)

    def compiled(self):
        """Compiled form: :func:`oceangnc.control._compiled_berthing_modes.open_loop_step`."""
        from ._compiled_berthing_modes import open_loop_form

        return open_loop_form(self, _OUT)


@register_block("ship.pid")
class PIDController(_Base):
    """PID per actuator, 001 eq. 39-42 (n_S = -n_B)."""

    role = "controller"

    def reset(self, rng):
        c = self.cfg
        p = self.p
        nlim = c.n_limit_rpm / 60.0
        self.pid_n = PID(c.kp_prop, c.ki_prop, c.kd_prop, -nlim, nlim)
        self.pid_d = PID(c.kp_rudder, c.ki_rudder, c.kd_rudder, -p[_DELTA_MAX], p[_DELTA_MAX])
        self.pid_t = PID(c.kp_thruster, c.ki_thruster, c.kd_thruster, -p[_NB_MAX], p[_NB_MAX])

    def step(self, t, bus):
        h = self.period
        e_u = bus["ship.u"] - bus["cmd.u_d"]
        e_r = bus["ship.r"] - bus["cmd.r_d"]
        # the PID class acts on (reference - measurement) = -e: n_c = -k_P e - k_I int e - k_D e'
        n = self.pid_n.step(-e_u, h)
        delta = self.pid_d.step(-e_r, h)
        nb = self.pid_t.step(-e_r, h)
        self._write(bus, delta, n, nb, -nb, e_u, e_r)

    def compiled(self):
        """Compiled form: :func:`oceangnc.control._compiled_berthing_modes.berthing_pid_step`."""
        from ._compiled_berthing_modes import pid_form

        return pid_form(self, _OUT)


@register_block("ship.nonlinear")
class NonlinearController(_Base):
    """Feedback-linearising MIMO controller, 001 eq. 27-38 (SPEC corrections); module docstring."""

    role = "controller"

    def __init__(self, cfg: ControlConfig, ship: ShipConfig):
        super().__init__(cfg, ship)
        self.inputs.update({"ship.v": "m/s", "ship.psi": "rad", "ship.rudder": "rad", "ship.rpm_prop": "rpm"})
        self.optional_inputs.update(
            {"env.current_n": "m/s", "env.current_e": "m/s", "env.wind_n": "m/s", "env.wind_e": "m/s"}
        )
        self.outputs.update({"ctrl.u_rd": "m/s", "ctrl.u_d": "m/s", "ctrl.r_d": "rad/s", "ctrl.x_pd": "N"})

    def reset(self, rng):
        self._ud = None
        self._rd = None
        a, b, c, d = inverse_mass(self.p)
        self.c = c
        self.d = d

    def compiled(self):
        """Compiled form for the fused loop (:func:`oceangnc.control._compiled_berthing.nonlinear_step`)."""
        if self._ud is None:
            return None
        import numpy as np

        from ..core.fused import CompiledBlock
        from ._compiled_berthing import nonlinear_step

        cfg = self.cfg
        head = [
            self.period,
            cfg.t_ref,
            float(cfg.use_disturbance),
            cfg.lambda1,
            cfg.lambda2,
            cfg.n_limit_rpm / 60.0,
            float(cfg.rate_aware_rudder),
            cfg.u_switch,
            self.c,
            self.d,
            0.0,
            0.0,
        ]
        sig = [
            "ship.u",
            "ship.v",
            "ship.r",
            "ship.psi",
            "ship.rudder",
            "ship.rpm_prop",
            "ship.rpm_bow",
            "ship.rpm_stern",
            "cmd.u_d",
            "cmd.r_d",
            "?env.current_n",
            "?env.current_e",
            "?env.wind_n",
            "?env.wind_e",
            "_estop",
            "ship.rudder_cmd",
            "ship.n_prop_cmd",
            "ship.n_bow_cmd",
            "ship.n_stern_cmd",
            "ctrl.e_u",
            "ctrl.e_r",
            "ctrl.u_rd",
            "ctrl.u_d",
            "ctrl.r_d",
            "ctrl.x_pd",
        ]
        return CompiledBlock(nonlinear_step, sig, np.array([self._ud, self._rd], float), np.concatenate([head, self.p]))

    def step(self, t, bus):
        cfg = self.cfg
        p = self.p
        h = self.period
        u = bus["ship.u"]
        v = bus["ship.v"]
        r = bus["ship.r"]
        psi = bus["ship.psi"]
        delta = bus["ship.rudder"]
        n = bus["ship.rpm_prop"] / 60.0
        # setpoint filter T u_d' = u_cmd - u_d (exact discretisation): smooth u_d(s), r_d(s) and rates
        u_cmd = bus["cmd.u_d"]
        r_cmd = bus["cmd.r_d"]
        if self._ud is None:
            self._ud, self._rd = u_cmd, r_cmd
        if cfg.t_ref > 0:
            a = math.exp(-h / cfg.t_ref)
            ud_dot = (u_cmd - self._ud) / cfg.t_ref
            rd_dot = (r_cmd - self._rd) / cfg.t_ref
            u_d, r_d = self._ud, self._rd
            self._ud = u_cmd + a * (self._ud - u_cmd)
            self._rd = r_cmd + a * (self._rd - r_cmd)
        else:
            u_d, r_d, ud_dot, rd_dot = u_cmd, r_cmd, 0.0, 0.0
        cn = ce = wn = we = 0.0
        if cfg.use_disturbance:
            cn, ce = bus.get("env.current_n", 0.0), bus.get("env.current_e", 0.0)
            wn, we = bus.get("env.wind_n", 0.0), bus.get("env.wind_e", 0.0)
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
        x_pd = p[_M11] * (ud_dot - cfg.lambda1 * e_u - r * vc) - (m * (vr * r + xg * r * r) + Xh + XR + XW)
        n_c = rps_for_thrust(x_pd, ur, p, cfg.n_limit_rpm / 60.0)
        # yaw rate (32)-(34)
        e_r = r - r_d
        fy0 = -m * ur * r + Yh + YW
        fn0 = -m * xg * ur * r + Nh + NW
        u_rd = rd_dot - cfg.lambda2 * e_r - self.c * fy0 - self.d * fn0
        if cfg.rate_aware_rudder:
            reach = p[_DELTA_RATE] * max(h, p[_TAU_D])
            delta_c, nb_c = allocate(
                u_rd, ur, vr, r, n, self.c, self.d, p, cfg.u_switch, 21, delta - reach, delta + reach
            )
        else:
            delta_c, nb_c = allocate(
                u_rd, ur, vr, r, n, self.c, self.d, p, cfg.u_switch, 71, -p[_DELTA_MAX], p[_DELTA_MAX]
            )
        self._write(bus, delta_c, n_c, nb_c, -nb_c, e_u, e_r)
        bus["ctrl.u_rd"] = float(u_rd)
        bus["ctrl.u_d"] = float(u_d)
        bus["ctrl.r_d"] = float(r_d)
        bus["ctrl.x_pd"] = float(x_pd)


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
