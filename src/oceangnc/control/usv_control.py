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

:class:`USVRateController` (``usv.rate_pid``) is the inner loop pair of the console's USV: speed and
yaw-rate PIDs on setpoints ``usv.u_d`` / ``usv.r_d`` (from :class:`oceangnc.guidance.route_pilot.RoutePilot`)
with the steady-state feed-forwards of the linear model (003 eq. 2.3), ``U_speed = d11 u_d / 2 + PID``
(N per thruster) and ``U_heading = d33 r_d / B + PID`` (N), and an open-loop stick mode.

Every USV controller of the project mixes through :func:`mix` (003 eq. 3.11).
"""

from __future__ import annotations

import math

from numba import njit
from pydantic import Field

from ..core.blocks import Block
from ..core.registry import register_block
from ..core.rotations import wrap
from ..io.config import StrictModel
from ..units import KGF
from ._compiled import arr, pid_params, pid_state, pid_step
from .pid import PID


@njit(cache=True)
def mix(u_speed, u_heading):
    """Thruster mixing of 003 eq. 3.11: ``(T_port, T_stbd) = (U_speed + U_heading, U_speed - U_heading)`` (N).

    A positive ``U_heading`` turns to starboard: N = (T_port - T_stbd) B / 2 = U_heading B (003 eq. 2.4).
    Compiled, so the fused kernels call the same function.
    """
    return u_speed + u_heading, u_speed - u_heading


@njit(cache=True)
def speed_range(t_min, t_max, u_heading):
    """Heading priority (003 eq. 3.11): the speed loop's output range (N) is what is left of each
    thruster's range [t_min, t_max] after the heading command, [min(0, t_min + |U_h|), max(0, t_max - |U_h|)]."""
    return min(0.0, t_min + abs(u_heading)), max(0.0, t_max - abs(u_heading))


def speed_loop(pid: PID, u_d: float, u: float, h: float, d11: float, share: float = 0.5) -> float:
    """The USV surge-speed loop: ``PID(u_d - u)`` (003 eq. 3.10) plus the steady-state feed-forward
    ``share * d11 u_d`` of the linear surge model (003 eq. 2.3: d11 u = T_port + T_stbd), ``share`` =
    1/2 per thruster or 1 on the total thrust (N). The one home of this law: every USV controller calls it
    (the compiled kernels take ``share * d11`` as a parameter)."""
    return pid.step(u_d - u, h, feedforward=share * d11 * u_d)


def aw_pid(kp: float, ki: float, kd: float, lo: float, hi: float) -> PID:
    """PID of eq. 3.10 (U = K_p e + K_I int(e + K_w (sat U - U)) + K_D e', K_w = 1/K_p), the
    :class:`~oceangnc.control.pid.PID` default: back-calculation rate K_I / K_p (tracking time
    constant T_t = T_i), so the integrator settles at the limit instead of growing by K_I e per s."""
    return PID(kp, ki, kd, lo, hi)


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


@register_block("usv.pid")
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

    role = "controller"

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
        self.inputs = {self.meas["u"]: "m/s", self.meas["psi"]: "rad", self.meas["r"]: "rad/s"}
        self.optional_inputs = {
            "console.mode": "str",
            "joystick.surge": "1",
            "joystick.yaw": "1",
            "usv.u_d": "m/s",
            "guidance.psi_d": "rad",
        }
        self.outputs = {
            "usv.thrust_port_cmd": "N",
            "usv.thrust_stbd_cmd": "N",
            "usv_ctrl.u_d": "m/s",
            "usv_ctrl.psi_d": "rad",
            "usv_ctrl.u_speed": "N",
            "usv_ctrl.u_heading": "N",
            "usv_ctrl.r_d": "rad/s",
        }

    params_model = USVControlConfig

    @classmethod
    def from_context(cls, params: USVControlConfig, ctx) -> USVController:
        """Built from a scenario's ``control.usv`` slot: ``ctx.cfg.usv`` (thrust limits, d11), the surge
        target ``ctx.info["surge_speed"]`` (m/s) and the measured u, psi, r by role."""
        meas = {"u": ctx.signal("usv.u"), "psi": ctx.signal("usv.psi"), "r": ctx.signal("usv.r")}
        return cls(params, ctx.cfg.usv, ctx.info["surge_speed"], ctx.period, meas=meas)

    def reset(self, rng) -> None:
        self.speed.reset()
        self.heading.reset()
        self.yaw_rate.reset()

    def compiled(self):
        """Compiled form for the fused loop (autopilot mode; :func:`oceangnc.control._compiled.usv_control_step`)."""
        from ..core.fused import CompiledBlock

        m = self.meas
        sig = [
            m["u"],
            m["psi"],
            m["r"],
            "?usv.u_d",
            "?guidance.psi_d",
            "usv.thrust_port_cmd",
            "usv.thrust_stbd_cmd",
            "usv_ctrl.u_d",
            "usv_ctrl.psi_d",
            "usv_ctrl.u_speed",
            "usv_ctrl.u_heading",
        ]
        st = arr(pid_state(self.speed) + pid_state(self.heading))
        pa = arr(
            pid_params(self.speed)
            + pid_params(self.heading)
            + [self.period, self.u_d, self.t_max, self.t_min, 0.5 * self.d11 if self.cfg.speed_ff else 0.0]
        )
        return CompiledBlock(usv_control_step, sig, st, pa)

    def step(self, t: float, bus: dict) -> None:
        c = self.cfg
        h = self.period
        u = bus[self.meas["u"]]
        psi = bus[self.meas["psi"]]
        r = bus[self.meas["r"]]
        remote = bus.get("console.mode") == "remote"
        if remote:
            js = max(-1.0, min(1.0, float(bus["joystick.surge"])))
            jy = max(-1.0, min(1.0, float(bus["joystick.yaw"])))
            u_d = js * c.u_max if js >= 0 else 0.5 * js * c.u_max
            r_d = jy * math.radians(c.r_max_degps)
            u_h = self.yaw_rate.step(r_d - r, h)
            bus["usv_ctrl.r_d"] = r_d
            psi_d = psi
        else:
            u_d = float(bus.get("usv.u_d", self.u_d))
            psi_d = bus.get("guidance.psi_d", psi)
            u_h = self.heading.step(wrap(psi_d - psi), h, e_dot=-r)
        # heading priority: the speed loop gets what is left of each thruster's range
        self.speed.u_min, self.speed.u_max = speed_range(self.t_min, self.t_max, u_h)
        u_s = speed_loop(self.speed, u_d, u, h, self.d11 if c.speed_ff else 0.0)
        bus["usv.thrust_port_cmd"], bus["usv.thrust_stbd_cmd"] = mix(u_s, u_h)
        bus["usv_ctrl.u_d"] = u_d
        bus["usv_ctrl.psi_d"] = psi_d
        bus["usv_ctrl.u_speed"] = u_s
        bus["usv_ctrl.u_heading"] = u_h


class RateControlConfig(StrictModel):
    """Inner-loop PID gains (003 eq. 3.10) of :class:`USVRateController`; adjustable from the console."""

    rate: float = Field(50.0, gt=0, le=1000, description="pilot (guidance + control) rate, Hz")
    speed_kp: float = Field(300.0, ge=0, le=1e5, description="surge-speed PID proportional gain, N/(m/s)")
    speed_ki: float = Field(150.0, ge=0, le=1e5, description="surge-speed PID integral gain, N/m")
    yaw_kp: float = Field(300.0, ge=0, le=1e5, description="yaw-rate PID proportional gain, N/(rad/s)")
    yaw_ki: float = Field(200.0, ge=0, le=1e5, description="yaw-rate PID integral gain, N/rad")


@register_block("usv.rate_pid")
class USVRateController(Block):
    """Speed and yaw-rate PIDs with model feed-forwards, mixed by 003 eq. 3.11 (module docstring).

    Reads ``usv.u_d`` (m/s), ``usv.r_d`` (rad/s), ``usv.u`` (m/s), ``usv.r`` (rad/s); in remote mode
    with ``console.loop == "open"`` the stick goes straight to the thrusters (``U_speed`` =
    surge x the open-loop thrust, ``U_heading`` = yaw x the open-loop differential thrust). On an
    emergency stop (``_estop``) both integrators are cleared so that nothing has wound up when the
    stop is reset. Writes ``usv.thrust_port_cmd`` / ``usv.thrust_stbd_cmd`` (N).

    Parameters
    ----------
    cfg : RateControlConfig
    usv_cfg : USVConfig
        Thrust limits, d11, d33 and the thruster spacing B.
    stick : StickConfig
        Open-loop thrusts at full stick (:class:`oceangnc.guidance.route_pilot.StickConfig`).
    mode, loop : str
        Initial console mode and loop when the console has not written them.
    """

    role = "controller"
    name = "usv_pilot"

    def __init__(self, cfg: RateControlConfig, usv_cfg, stick, mode: str = "auto", loop: str = "closed"):
        self.period = 1.0 / cfg.rate
        self.usv_cfg = usv_cfg
        self.stick = stick
        self.mode, self.loop = mode, loop
        hi = usv_cfg.max_thrust_kgf * KGF
        lo = usv_cfg.max_reverse_kgf * KGF
        self.speed_pid = PID(cfg.speed_kp, cfg.speed_ki, 0.0, -lo, hi)
        self.yaw_pid = PID(cfg.yaw_kp, cfg.yaw_ki, 0.0, -hi, hi)
        self.inputs = {"usv.u_d": "m/s", "usv.r_d": "rad/s", "usv.u": "m/s", "usv.r": "rad/s"}
        self.optional_inputs = {
            "console.mode": "str",
            "console.loop": "str",
            "joystick.surge": "1",
            "joystick.yaw": "1",
            "_estop": "bool",
        }
        self.outputs = {"usv.thrust_port_cmd": "N", "usv.thrust_stbd_cmd": "N"}

    def gain_specs(self) -> list[dict]:
        """The gains an operator may change while running: name, value, range, unit, description."""
        return [
            {
                "name": "speed_kp",
                "value": self.speed_pid.kp,
                "min": 0.0,
                "max": 5000.0,
                "unit": "N/(m/s)",
                "description": "surge-speed PID proportional gain",
            },
            {
                "name": "speed_ki",
                "value": self.speed_pid.ki,
                "min": 0.0,
                "max": 5000.0,
                "unit": "N/m",
                "description": "surge-speed PID integral gain",
            },
            {
                "name": "yaw_kp",
                "value": self.yaw_pid.kp,
                "min": 0.0,
                "max": 5000.0,
                "unit": "N/(rad/s)",
                "description": "yaw-rate PID proportional gain",
            },
            {
                "name": "yaw_ki",
                "value": self.yaw_pid.ki,
                "min": 0.0,
                "max": 5000.0,
                "unit": "N/rad",
                "description": "yaw-rate PID integral gain",
            },
        ]

    def set_gain(self, name: str, value: float) -> None:
        """Set one gain listed by :meth:`gain_specs` (the console validates the range first)."""
        target = {
            "speed_kp": (self.speed_pid, "kp"),
            "speed_ki": (self.speed_pid, "ki"),
            "yaw_kp": (self.yaw_pid, "kp"),
            "yaw_ki": (self.yaw_pid, "ki"),
        }
        if name not in target:
            raise KeyError(name)
        obj, attr = target[name]
        setattr(obj, attr, float(value))

    def reset(self, rng) -> None:
        self.speed_pid.reset()
        self.yaw_pid.reset()

    def compiled(self):
        """Compiled form: :func:`oceangnc.control._compiled_rate.rate_control_step` (PIDs without hold/ramp)."""
        from ..core.fused import CompiledBlock
        from ..core.fused_strings import ENUMS
        from ._compiled_rate import rate_control_step

        if any(pid.held or pid._ramp_left > 0.0 for pid in (self.speed_pid, self.yaw_pid)):
            return None
        p, st = self.usv_cfg, self.stick
        # external signals with a slot even when absent (0, or code -1 for the default mode), so that
        # values injected between runs reach the kernel
        sigs = ["usv.u_d", "usv.r_d", "usv.u", "usv.r", "console.mode", "console.loop", "joystick.surge"]
        sigs += ["joystick.yaw", "_estop", "usv.thrust_port_cmd", "usv.thrust_stbd_cmd"]
        pa = pid_params(self.speed_pid) + pid_params(self.yaw_pid) + [self.period, p.d11, p.d33, p.thruster_spacing]
        pa += [st.open_loop_thrust_kgf, st.open_loop_reverse_kgf, st.open_loop_diff_kgf, KGF]
        pa += [ENUMS["console.mode"].index(self.mode), ENUMS["console.loop"].index(self.loop)]
        return CompiledBlock(rate_control_step, sigs, arr(pid_state(self.speed_pid) + pid_state(self.yaw_pid)), arr(pa))

    def step(self, t: float, bus: dict) -> None:
        h = self.period
        p = self.usv_cfg
        u_d, r_d = bus["usv.u_d"], bus["usv.r_d"]
        mode = bus.get("console.mode", self.mode)
        loop = bus.get("console.loop", self.loop)
        if bus.get("_estop", False):
            self.speed_pid.reset()
            self.yaw_pid.reset()
            u_speed = u_head = 0.0
        elif mode == "remote" and loop == "open":
            st = self.stick
            surge = max(-1.0, min(1.0, float(bus["joystick.surge"])))
            yaw = max(-1.0, min(1.0, float(bus["joystick.yaw"])))
            u_speed = surge * (st.open_loop_thrust_kgf if surge >= 0 else st.open_loop_reverse_kgf) * KGF
            u_head = yaw * st.open_loop_diff_kgf * KGF
            self.speed_pid.reset()
            self.yaw_pid.reset()
        else:
            u_speed = speed_loop(self.speed_pid, u_d, bus["usv.u"], h, p.d11)
            u_head = self.yaw_pid.step(r_d - bus["usv.r"], h, feedforward=p.d33 * r_d / p.thruster_spacing)
        bus["usv.thrust_port_cmd"], bus["usv.thrust_stbd_cmd"] = mix(u_speed, u_head)


@njit(cache=True)
def usv_control_step(t, sig, sl, st, pa):
    """:class:`oceangnc.control.usv_control.USVController` (autopilot mode).

    slots: u, psi, r, ?usv.u_d, ?guidance.psi_d | thrust_port_cmd, thrust_stbd_cmd, usv_ctrl.u_d,
    usv_ctrl.psi_d, usv_ctrl.u_speed, usv_ctrl.u_heading. state: speed PID, heading PID.
    params: speed PID, heading PID, h, u_d default, t_max, t_min, 0.5 d11 (or 0: no feed-forward).
    """
    h = pa[12]
    u = sig[sl[0]]
    psi = sig[sl[1]]
    r = sig[sl[2]]
    u_d = sig[sl[3]] if sl[3] >= 0 else pa[13]
    psi_d = sig[sl[4]] if sl[4] >= 0 else psi
    u_h = pid_step(st, 5, pa, 6, wrap(psi_d - psi), h, -r, True, 0.0, pa[9], pa[10])
    t_max = pa[14]
    t_min = pa[15]
    s_min, s_max = speed_range(t_min, t_max, u_h)
    ff = pa[16] * u_d
    u_s = pid_step(st, 0, pa, 0, u_d - u, h, 0.0, False, ff, s_min, s_max)
    sig[sl[5]], sig[sl[6]] = mix(u_s, u_h)
    out = (u_d, psi_d, u_s, u_h)
    for i in range(4):
        sig[sl[7 + i]] = out[i]
