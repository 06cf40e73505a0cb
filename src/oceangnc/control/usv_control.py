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

import numpy as np
from numba import njit
from pydantic import Field

from ..core.config import StrictModel
from ..core.estop import RESUME_RAMP_S, resume_weight
from ..core.fused_strings import ENUMS
from ..core.law import FALSE, TRUE, Ext, In, LawBlock, Layout, Opt, Out, Signals, param
from ..core.registry import register_block
from ..core.rotations import wrap
from ..models.usv import USVConfig
from ..units import KGF
from .pid import PID, PID_PARAMS, PID_STATE, pid_clear, pid_params, pid_run, pid_step_w


@njit(cache=True, inline="always")
def mix(u_speed, u_heading):
    """Thruster mixing of 003 eq. 3.11: ``(T_port, T_stbd) = (U_speed + U_heading, U_speed - U_heading)`` (N).

    A positive ``U_heading`` turns to starboard: N = (T_port - T_stbd) B / 2 = U_heading B (003 eq. 2.4).
    Compiled, so the fused kernels call the same function.
    """
    return u_speed + u_heading, u_speed - u_heading


@njit(cache=True, inline="always")
def speed_range(t_min, t_max, u_heading):
    """Heading priority (003 eq. 3.11): the speed loop's output range (N) is what is left of each
    thruster's range [t_min, t_max] after the heading command, [min(0, t_min + |U_h|), max(0, t_max - |U_h|)]."""
    return min(0.0, t_min + abs(u_heading)), max(0.0, t_max - abs(u_heading))


def speed_loop(pid: PID, u_d: float, u: float, h: float, d11: float, share: float = 0.5) -> float:
    """The USV surge-speed loop: ``PID(u_d - u)`` (003 eq. 3.10) plus the steady-state feed-forward
    ``share * d11 u_d`` of the linear surge model (003 eq. 2.3: d11 u = T_port + T_stbd), ``share`` =
    1/2 per thruster or 1 on the total thrust (N), for a controller holding a :class:`PID` object (the
    compiled laws call :func:`pid_step` with the feed-forward ``share * d11 * u_d`` the same way)."""
    return pid.step(u_d - u, h, feedforward=share * d11 * u_d)


_REMOTE = float(ENUMS["console.mode"].index("remote"))
_OPEN = float(ENUMS["console.loop"].index("open"))


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


class USVControlParams(USVControlConfig):
    """The gains and what the block takes from its scenario (``build_block(..., given=...)``): the
    vehicle it drives (thrust limits, d11) and the surge speed target."""

    usv: USVConfig = Field(..., description="the USV driven: thrust limits (kgf) and d11 (feed-forward)")
    u_d: float = Field(..., description="surge speed target, m/s")


USV_PID_SIGNALS = Signals(
    u=In("m/s"),
    psi=In("rad"),
    r=In("rad/s"),
    u_d=Opt("m/s"),
    psi_d=Opt("rad"),
    estop=Opt("bool"),
    mode=Ext("str"),
    surge=Ext("1"),
    yaw=Ext("1"),
    port=Out("N"),
    stbd=Out("N"),
    u_d_out=Out("m/s"),
    psi_d_out=Out("rad"),
    u_speed=Out("N"),
    u_heading=Out("N"),
    r_d=Out("rad/s"),
)
USV_PID_PARAMS = Layout(
    ("speed", PID_PARAMS.size),
    ("heading", PID_PARAMS.size),
    ("yaw_rate", PID_PARAMS.size),
    "h",
    "u_d",
    "t_max",
    "t_min",
    "ff",
    "u_max",
    "r_max",
)
USV_PID_STATE = Layout(("speed", PID_STATE.size), ("heading", PID_STATE.size), ("yaw_rate", PID_STATE.size), "w")
_S, _P, _X = USV_PID_SIGNALS.at, USV_PID_PARAMS.at, USV_PID_STATE.at


@njit(cache=True)
def usv_pid_law(t, sig, sl, st, pa):
    """Speed and heading loops, mixing, and the remote mode (module docstring; 003 eq. 3.10-3.11).

    Autopilot: U_h = PID_2(wrap(psi_d - psi), e_dot = -r) (N), then the speed loop on what the
    thrusters have left, U_s = PID_1(u_d - u) + ff u_d, T = (U_s + U_h, U_s - U_h) (N). Remote
    (``console.mode`` = remote): u_d = stick x u_max (astern at half), r_d = stick x r_max and a yaw-rate
    PI loop in place of the heading loop. While ``_estop`` is set the thrust is zero and no PID moves;
    after it the PID outputs ramp back (:mod:`oceangnc.core.estop`).
    """
    u = sig[sl[_S.u]]
    psi = sig[sl[_S.psi]]
    r = sig[sl[_S.r]]
    h = pa[_P.h]
    if sl[_S.estop] >= 0 and sig[sl[_S.estop]] != 0.0:
        st[_X.w] = 0.0
        sig[sl[_S.port]] = 0.0
        sig[sl[_S.stbd]] = 0.0
        sig[sl[_S.u_speed]] = 0.0
        sig[sl[_S.u_heading]] = 0.0
        return
    w = st[_X.w] = resume_weight(st[_X.w], FALSE, h, RESUME_RAMP_S)
    r_d = 0.0
    if sig[sl[_S.mode]] == _REMOTE:
        js = max(-1.0, min(1.0, sig[sl[_S.surge]]))
        jy = max(-1.0, min(1.0, sig[sl[_S.yaw]]))
        u_d = js * pa[_P.u_max] if js >= 0 else 0.5 * js * pa[_P.u_max]
        r_d = jy * pa[_P.r_max]
        u_h = pid_run(st, _X.yaw_rate, pa, _P.yaw_rate, r_d - r, h, 0.0, FALSE, 0.0, w)
        psi_d = psi
    else:
        u_d = sig[sl[_S.u_d]] if sl[_S.u_d] >= 0 else pa[_P.u_d]
        psi_d = sig[sl[_S.psi_d]] if sl[_S.psi_d] >= 0 else psi
        u_h = pid_run(st, _X.heading, pa, _P.heading, wrap(psi_d - psi), h, -r, TRUE, 0.0, w)
    # heading priority: the speed loop gets what is left of each thruster's range
    s_min, s_max = speed_range(pa[_P.t_min], pa[_P.t_max], u_h)
    u_s = pid_step_w(st, _X.speed, pa, _P.speed, u_d - u, h, 0.0, FALSE, pa[_P.ff] * u_d, s_min, s_max, w)
    sig[sl[_S.port]], sig[sl[_S.stbd]] = mix(u_s, u_h)
    sig[sl[_S.u_d_out]] = u_d
    sig[sl[_S.psi_d_out]] = psi_d
    sig[sl[_S.u_speed]] = u_s
    sig[sl[_S.u_heading]] = u_h
    sig[sl[_S.r_d]] = r_d


@register_block("usv.pid")
class USVController(LawBlock):
    """Speed + heading loops and mixing (module docstring); writes ``usv.thrust_port_cmd``/``_stbd_cmd`` (N);
    law :func:`usv_pid_law`. ``speed``, ``heading`` and ``yaw_rate`` are :class:`PID` views of its state.

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
    law = staticmethod(usv_pid_law)
    signals = USV_PID_SIGNALS
    params_model = USVControlParams

    def __init__(self, cfg: USVControlConfig, usv_cfg, u_d: float, period: float = 0.05, meas=None):
        self.cfg = cfg
        self.period = float(period)
        self.t_max = usv_cfg.max_thrust_kgf * KGF
        self.t_min = -usv_cfg.max_reverse_kgf * KGF
        self.d11 = usv_cfg.d11
        self.meas = {"u": "usv.u", "psi": "usv.psi", "r": "usv.r", **(meas or {})}
        m = self.meas
        self.bind(
            u=m["u"],
            psi=m["psi"],
            r=m["r"],
            u_d="usv.u_d",
            psi_d="guidance.psi_d",
            estop="_estop",
            mode="console.mode",
            surge="joystick.surge",
            yaw="joystick.yaw",
            port="usv.thrust_port_cmd",
            stbd="usv.thrust_stbd_cmd",
            u_d_out="usv_ctrl.u_d",
            psi_d_out="usv_ctrl.psi_d",
            u_speed="usv_ctrl.u_speed",
            u_heading="usv_ctrl.u_heading",
            r_d="usv_ctrl.r_d",
        )
        hmax = cfg.heading_share * self.t_max
        self.pa = USV_PID_PARAMS.pack(
            speed=PID_PARAMS.pack(pid_params(cfg.speed_kp, cfg.speed_ki, cfg.speed_kd, self.t_min, self.t_max)),
            heading=PID_PARAMS.pack(pid_params(cfg.heading_kp, cfg.heading_ki, cfg.heading_kd, -hmax, hmax)),
            yaw_rate=PID_PARAMS.pack(pid_params(cfg.yaw_rate_kp, cfg.yaw_rate_ki, 0.0, -hmax, hmax)),
            h=self.period,
            u_d=float(u_d),
            t_max=self.t_max,
            t_min=self.t_min,
            ff=0.5 * self.d11 if cfg.speed_ff else 0.0,
            u_max=cfg.u_max,
            r_max=math.radians(cfg.r_max_degps),
        )
        self.st = np.zeros(USV_PID_STATE.size)
        self.st[_X.w] = 1.0
        self.speed = PID.view(self.st, _X.speed, self.pa, _P.speed)
        self.heading = PID.view(self.st, _X.heading, self.pa, _P.heading)
        self.yaw_rate = PID.view(self.st, _X.yaw_rate, self.pa, _P.yaw_rate)

    u_d = param(_P.u_d, "surge speed target (m/s) when no block publishes usv.u_d; settable while running")

    @classmethod
    def from_context(cls, params: USVControlParams, ctx) -> USVController:
        """Built from a scenario's ``control.usv`` slot: its own parameters (the gains, the vehicle
        ``usv``: thrust limits, d11; the surge target ``u_d``, m/s) and the measured u, psi, r by role."""
        meas = {"u": ctx.signal("usv.u"), "psi": ctx.signal("usv.psi"), "r": ctx.signal("usv.r")}
        return cls(params, params.usv, params.u_d, ctx.period, meas=meas)

    def reset(self, rng) -> None:
        self.st[:] = 0.0
        self.st[_X.w] = 1.0


class RateControlConfig(StrictModel):
    """Inner-loop PID gains (003 eq. 3.10) of :class:`USVRateController`; adjustable from the console."""

    rate: float = Field(50.0, gt=0, le=1000, description="pilot (guidance + control) rate, Hz")
    speed_kp: float = Field(300.0, ge=0, le=1e5, description="surge-speed PID proportional gain, N/(m/s)")
    speed_ki: float = Field(150.0, ge=0, le=1e5, description="surge-speed PID integral gain, N/m")
    yaw_kp: float = Field(300.0, ge=0, le=1e5, description="yaw-rate PID proportional gain, N/(rad/s)")
    yaw_ki: float = Field(200.0, ge=0, le=1e5, description="yaw-rate PID integral gain, N/rad")


RATE_SIGNALS = Signals(
    u_d=In("m/s"),
    r_d=In("rad/s"),
    u=In("m/s"),
    r=In("rad/s"),
    mode=Ext("str"),
    loop=Ext("str"),
    surge=Ext("1"),
    yaw=Ext("1"),
    estop=Ext("bool"),
    port=Out("N"),
    stbd=Out("N"),
)
RATE_PARAMS = Layout(
    ("speed", PID_PARAMS.size),
    ("yaw", PID_PARAMS.size),
    "h",
    "d11",
    "d33",
    "b",
    "open_ahead",
    "open_astern",
    "open_diff",
    "mode",
    "loop",
)
RATE_STATE = Layout(("speed", PID_STATE.size), ("yaw", PID_STATE.size))
_RS, _RP, _RX = RATE_SIGNALS.at, RATE_PARAMS.at, RATE_STATE.at


@njit(cache=True)
def rate_pid_law(t, sig, sl, st, pa):
    """Speed and yaw-rate PIDs with the linear model's feed-forwards (003 eq. 2.3, 3.10) mixed by eq.
    3.11: U_speed = PID(u_d - u) + d11 u_d / 2, U_heading = PID(r_d - r) + d33 r_d / B (N). In remote
    mode with the open loop, the stick goes to the thrusters (open-loop thrusts, N). ``_estop``
    clears both integrators and gives zero thrust. ``console.mode``/``console.loop`` absent (code -1):
    the block's own defaults."""
    h = pa[_RP.h]
    u_d = sig[sl[_RS.u_d]]
    r_d = sig[sl[_RS.r_d]]
    mode = sig[sl[_RS.mode]] if sig[sl[_RS.mode]] >= 0.0 else pa[_RP.mode]
    loop = sig[sl[_RS.loop]] if sig[sl[_RS.loop]] >= 0.0 else pa[_RP.loop]
    if sig[sl[_RS.estop]] != 0.0:
        pid_clear(st, _RX.speed)
        pid_clear(st, _RX.yaw)
        u_speed = 0.0
        u_head = 0.0
    elif mode == _REMOTE and loop == _OPEN:
        surge = max(-1.0, min(1.0, sig[sl[_RS.surge]]))
        yaw = max(-1.0, min(1.0, sig[sl[_RS.yaw]]))
        u_speed = surge * (pa[_RP.open_ahead] if surge >= 0 else pa[_RP.open_astern]) * KGF
        u_head = yaw * pa[_RP.open_diff] * KGF
        pid_clear(st, _RX.speed)
        pid_clear(st, _RX.yaw)
    else:
        ff = 0.5 * pa[_RP.d11] * u_d
        u_speed = pid_run(st, _RX.speed, pa, _RP.speed, u_d - sig[sl[_RS.u]], h, 0.0, FALSE, ff, 1.0)
        ff = pa[_RP.d33] * r_d / pa[_RP.b]
        u_head = pid_run(st, _RX.yaw, pa, _RP.yaw, r_d - sig[sl[_RS.r]], h, 0.0, FALSE, ff, 1.0)
    sig[sl[_RS.port]], sig[sl[_RS.stbd]] = mix(u_speed, u_head)


@register_block("usv.rate_pid")
class USVRateController(LawBlock):
    """Speed and yaw-rate PIDs with model feed-forwards, mixed by 003 eq. 3.11 (module docstring);
    law :func:`rate_pid_law`.

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
    law = staticmethod(rate_pid_law)
    signals = RATE_SIGNALS
    params_model = RateControlConfig

    def __init__(self, cfg: RateControlConfig, usv_cfg, stick, mode: str = "auto", loop: str = "closed"):
        self.period = 1.0 / cfg.rate
        self.usv_cfg = usv_cfg
        self.stick = stick
        self.mode, self.loop = mode, loop
        hi = usv_cfg.max_thrust_kgf * KGF
        lo = usv_cfg.max_reverse_kgf * KGF
        self.bind(
            u_d="usv.u_d",
            r_d="usv.r_d",
            u="usv.u",
            r="usv.r",
            mode="console.mode",
            loop="console.loop",
            surge="joystick.surge",
            yaw="joystick.yaw",
            estop="_estop",
            port="usv.thrust_port_cmd",
            stbd="usv.thrust_stbd_cmd",
        )
        self.pa = RATE_PARAMS.pack(
            speed=PID_PARAMS.pack(pid_params(cfg.speed_kp, cfg.speed_ki, 0.0, -lo, hi)),
            yaw=PID_PARAMS.pack(pid_params(cfg.yaw_kp, cfg.yaw_ki, 0.0, -hi, hi)),
            h=self.period,
            d11=usv_cfg.d11,
            d33=usv_cfg.d33,
            b=usv_cfg.thruster_spacing,
            open_ahead=stick.open_loop_thrust_kgf,
            open_astern=stick.open_loop_reverse_kgf,
            open_diff=stick.open_loop_diff_kgf,
            mode=ENUMS["console.mode"].index(mode),
            loop=ENUMS["console.loop"].index(loop),
        )
        self.st = np.zeros(RATE_STATE.size)
        self.speed_pid = PID.view(self.st, _RX.speed, self.pa, _RP.speed)
        self.yaw_pid = PID.view(self.st, _RX.yaw, self.pa, _RP.yaw)

    def gain_specs(self) -> list[dict]:
        """The gains an operator may change while running: name, value, range, unit, description."""
        rows = [
            ("speed_kp", self.speed_pid.kp, "N/(m/s)", "surge-speed PID proportional gain"),
            ("speed_ki", self.speed_pid.ki, "N/m", "surge-speed PID integral gain"),
            ("yaw_kp", self.yaw_pid.kp, "N/(rad/s)", "yaw-rate PID proportional gain"),
            ("yaw_ki", self.yaw_pid.ki, "N/rad", "yaw-rate PID integral gain"),
        ]
        return [{"name": n, "value": v, "min": 0.0, "max": 5000.0, "unit": u, "description": d} for n, v, u, d in rows]

    def set_gain(self, name: str, value: float) -> None:
        """Set one gain listed by :meth:`gain_specs` (the console validates the range first); the law
        reads it from the parameter array at its next step, on either clock."""
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
        self.st[:] = 0.0
