"""USV speed and heading loops and thruster mixing (003 ch. 3.3.1, eq. 3.10-3.11), plus a remote mode.

Autonomous mode (003 eq. 3.10-3.11): two anti-windup PIDs (:class:`oceangnc.control.pid.PID`)

    U_speed   = PID_1(u_d - u)                 (N per thruster, + a model feed-forward d11 u_d / 2)
    U_heading = PID_2(wrap(psi_d - psi))       (N, derivative on the measured yaw rate: -r)
    T_port = U_speed + U_heading,   T_stbd = U_speed - U_heading     (3.11)

A positive heading error (target to starboard, NED) needs N = (T_p - T_s) B/2 > 0, hence the signs.
Mixing with heading priority (our choice; 003 does not say how the sum is saturated): the heading
command is limited to +-``heading_share`` of the thrust range, then the speed PID's limits are set
each step to what the thrusters have left, [T_min + |U_heading|, T_max - |U_heading|], so both
thrusters stay inside their limits and the speed integrator's back-calculation sees the limit it
actually hit (no windup while the heading loop takes the authority).

Remote mode (the console's joystick, 003 ch. 5.4): when ``bus["console.mode"] == "remote"`` the
controller ignores the guidance and follows

    u_d = joystick.surge * u_max     (surge in [-1, 1]; negative = astern, limited to -u_max/2)
    r_d = joystick.yaw   * r_max     (yaw in [-1, 1], + = turn to starboard)

with the same speed loop and a yaw-rate PI loop PID_3(r_d - r) in place of the heading loop.
Inputs outside [-1, 1] are clipped.
"""

from __future__ import annotations

import math

from pydantic import Field

from ..core.blocks import Block
from ..io.config import StrictModel
from ..units import KGF
from .pid import PID


def aw_pid(kp: float, ki: float, kd: float, lo: float, hi: float) -> PID:
    """PID of eq. 3.10 (U = K_p e + K_I int(e + K_w (sat U - U)) + K_D e', K_w = 1/K_p), the
    :class:`~oceangnc.control.pid.PID` default: back-calculation rate K_I / K_p (tracking time
    constant T_t = T_i), so the integrator settles at the limit instead of growing by K_I e per s."""
    return PID(kp, ki, kd, lo, hi)


def _wrap(a: float) -> float:
    return (a + math.pi) % (2.0 * math.pi) - math.pi


class USVControlConfig(StrictModel):
    """Gains of the USV loops (chosen by tuning on the model: see docs/combined-vehicle.md)."""

    speed_kp: float = Field(600.0, ge=0, le=1e5, description="speed loop proportional gain, N/(m/s)")
    speed_ki: float = Field(150.0, ge=0, le=1e5, description="speed loop integral gain, N/m")
    speed_kd: float = Field(0.0, ge=0, le=1e5, description="speed loop derivative gain, N s/(m/s)")
    speed_ff: bool = Field(True, description="add the model feed-forward d11 u_d / 2 per thruster")
    heading_kp: float = Field(120.0, ge=0, le=1e5, description="heading loop proportional gain, N/rad")
    heading_ki: float = Field(5.0, ge=0, le=1e5, description="heading loop integral gain, N/(rad s)")
    heading_kd: float = Field(150.0, ge=0, le=1e5, description="heading loop derivative gain, N s/rad")
    heading_share: float = Field(0.6, gt=0, le=1, description="largest heading command, fraction of max thrust")
    yaw_rate_kp: float = Field(400.0, ge=0, le=1e5, description="remote-mode yaw-rate gain, N/(rad/s)")
    yaw_rate_ki: float = Field(100.0, ge=0, le=1e5, description="remote-mode yaw-rate integral gain, N/rad")
    u_max: float = Field(1.5, gt=0, le=5, description="remote mode: surge speed at full stick, m/s")
    r_max_degps: float = Field(15.0, gt=0, le=90, description="remote mode: yaw rate at full stick, deg/s")


class USVController(Block):
    """Speed + heading loops and mixing (module docstring); writes ``usv.thrust_port_cmd``/``_stbd_cmd`` (N).

    Parameters
    ----------
    cfg : USVControlConfig
    usv_cfg : USVConfig
        Thrust limits and d11 for the feed-forward.
    u_d : float
        Surge speed target, m/s (also read from ``usv.u_d`` if a block publishes it).
    period : float
        Loop period, s.
    meas : dict
        Bus keys of the measured surge speed, heading and yaw rate (``u``, ``psi``, ``r``).
    """

    name = "usv_control"

    def __init__(self, cfg: USVControlConfig, usv_cfg, u_d: float, period: float = 0.05, meas=None):
        self.cfg = cfg
        self.period = float(period)
        self.u_d = float(u_d)
        self.t_max = usv_cfg.max_thrust_kgf * KGF
        self.t_min = -usv_cfg.max_reverse_kgf * KGF
        self.d11 = usv_cfg.d11
        self.meas = {"u": "usv.u", "psi": "usv.psi", "r": "usv.r", **(meas or {})}
        hmax = cfg.heading_share * self.t_max
        self.speed = aw_pid(cfg.speed_kp, cfg.speed_ki, cfg.speed_kd, self.t_min, self.t_max)
        self.heading = aw_pid(cfg.heading_kp, cfg.heading_ki, cfg.heading_kd, -hmax, hmax)
        self.yaw_rate = aw_pid(cfg.yaw_rate_kp, cfg.yaw_rate_ki, 0.0, -hmax, hmax)

    def reset(self, rng) -> None:
        self.speed.reset()
        self.heading.reset()
        self.yaw_rate.reset()

    def compiled(self):
        """Compiled form for the fused loop (autopilot mode; :func:`oceangnc.control._compiled.usv_control_step`)."""
        from ..core.fused import CompiledBlock
        from ._compiled import arr, pid_params, pid_state, usv_control_step

        m = self.meas
        sig = [m["u"], m["psi"], m["r"], "?usv.u_d", "?guidance.psi_d", "usv.thrust_port_cmd",
               "usv.thrust_stbd_cmd", "usv_ctrl.u_d", "usv_ctrl.psi_d", "usv_ctrl.u_speed", "usv_ctrl.u_heading"]
        st = arr(pid_state(self.speed) + pid_state(self.heading))
        pa = arr(pid_params(self.speed) + pid_params(self.heading)
                 + [self.period, self.u_d, self.t_max, self.t_min, 0.5 * self.d11 if self.cfg.speed_ff else 0.0])
        return CompiledBlock(usv_control_step, sig, st, pa)

    def step(self, t: float, bus: dict) -> None:
        c = self.cfg
        h = self.period
        u = bus.get(self.meas["u"], 0.0)
        psi = bus.get(self.meas["psi"], 0.0)
        r = bus.get(self.meas["r"], 0.0)
        remote = bus.get("console.mode") == "remote"
        if remote:
            js = max(-1.0, min(1.0, float(bus.get("joystick.surge", 0.0))))
            jy = max(-1.0, min(1.0, float(bus.get("joystick.yaw", 0.0))))
            u_d = js * c.u_max if js >= 0 else 0.5 * js * c.u_max
            r_d = jy * math.radians(c.r_max_degps)
            u_h = self.yaw_rate.step(r_d - r, h)
            bus["usv_ctrl.r_d"] = r_d
            psi_d = psi
        else:
            u_d = float(bus.get("usv.u_d", self.u_d))
            psi_d = bus.get("guidance.psi_d", psi)
            u_h = self.heading.step(_wrap(psi_d - psi), h, e_dot=-r)
        # heading priority: the speed loop gets what is left of each thruster's range
        self.speed.u_max = max(0.0, self.t_max - abs(u_h))
        self.speed.u_min = min(0.0, self.t_min + abs(u_h))
        ff = 0.5 * self.d11 * u_d if c.speed_ff else 0.0
        u_s = self.speed.step(u_d - u, h, feedforward=ff)
        bus["usv.thrust_port_cmd"] = u_s + u_h
        bus["usv.thrust_stbd_cmd"] = u_s - u_h
        bus["usv_ctrl.u_d"] = u_d
        bus["usv_ctrl.psi_d"] = psi_d
        bus["usv_ctrl.u_speed"] = u_s
        bus["usv_ctrl.u_heading"] = u_h
