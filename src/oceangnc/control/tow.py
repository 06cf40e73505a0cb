"""Straight-tow loops of both vehicles of the combined system (003 ch. 4 a, figs 4-2 to 4-5).

USV: total thrust = PID(u_d - u) + d11 u_d (feed-forward), split equally, plus a differential PD on
the heading error, mixed by 003 eq. 3.11 (:func:`oceangnc.control.usv_control.mix`). UUV: total
stern thrust = PID(u_d - u) - X_u|u| u_d |u_d| (feed-forward of the axial drag), split equally; bow
thrust = PD on the heading error. The gains are design values of ``tow-straight``.
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit
from pydantic import Field

from ..core.config import StrictModel
from ..core.law import FALSE, TRUE, In, LawBlock, Layout, Out, Signals
from ..core.registry import register_block
from ..core.rotations import wrap
from ..models.usv import USVConfig
from ..models.uuv import UUVConfig
from ..units import KGF
from .pid import PID, PID_PARAMS, PID_STATE, pid_params, pid_run
from .usv_control import mix


@njit(cache=True)
def bearing_to(n_to, e_to, n_from, e_from):
    """Bearing (rad) from point ``from`` to point ``to`` (NED north, east in m)."""
    return math.atan2(e_to - e_from, n_to - n_from)


@njit(cache=True)
def drag_feedforward(x_uu, u_d):
    """Surge thrust (N) that balances the UUV's axial quadratic drag at speed ``u_d`` (m/s):
    -X_u|u| u_d |u_d|, ``x_uu`` = X_u|u| (kg/m, negative)."""
    return -x_uu * u_d * abs(u_d)


class TowCommand(StrictModel):
    """Speed and heading commands of ``tow-straight`` and the loop gains (design values)."""

    usv_speed: float = Field(0.5, ge=0, le=3, description="USV surge speed command (003 ch. 4: 0.5), m/s")
    uuv_speed: float = Field(0.27, ge=-1, le=3, description="UUV surge speed command (003: 0.27 or 0.48), m/s")
    heading_deg: float = Field(0.0, ge=-360, le=360, description="heading command of both vehicles, deg")
    start_s: float = Field(20.0, ge=0, le=1e4, description="time the commands start (hanging before), s")
    usv_kp_speed: float = Field(800.0, ge=0, le=1e5, description="USV speed P gain (total thrust), N s/m")
    usv_ki_speed: float = Field(200.0, ge=0, le=1e5, description="USV speed I gain, N/m")
    usv_kp_heading: float = Field(300.0, ge=0, le=1e5, description="USV heading P gain (differential), N/rad")
    usv_kd_heading: float = Field(400.0, ge=0, le=1e5, description="USV heading D gain, N s/rad")
    uuv_kp_speed: float = Field(150.0, ge=0, le=1e5, description="UUV speed P gain (total stern thrust), N s/m")
    uuv_ki_speed: float = Field(30.0, ge=0, le=1e5, description="UUV speed I gain, N/m")
    uuv_kp_heading: float = Field(40.0, ge=0, le=1e4, description="UUV heading P gain (bow thrust), N/rad")
    uuv_kd_heading: float = Field(40.0, ge=0, le=1e4, description="UUV heading D gain, N s/rad")


def uuv_loop_params(uuv: UUVConfig, kp_speed: float, ki_speed: float, kp_heading: float, kd_heading: float):
    """Gains of the UUV's tow loops (:data:`~oceangnc.control.pid.PID_PARAMS` arrays): surge-speed PI on
    the total stern thrust, limited to twice a thruster's range, and heading PD on the bow thruster (N)."""
    t_max = uuv.max_thrust_kgf * KGF
    r_max = uuv.max_reverse_kgf * KGF
    speed = PID_PARAMS.pack(pid_params(kp_speed, ki_speed, 0.0, -2 * r_max, 2 * t_max))
    head = PID_PARAMS.pack(pid_params(kp_heading, 0.0, kd_heading, -r_max, t_max))
    return speed, head


@njit(cache=True)
def uuv_loops(sig, sl, i, o, st, x_speed, x_head, pa, p_speed, p_head, u_d, psi_d, h, x_uu):
    """The UUV's tow loops: stern thrust PID(u_d - u) - X_u|u| u_d |u_d| (axial-drag feed-forward,
    :func:`drag_feedforward`) shared by both stern thrusters; bow thrust PD(wrap(psi_d - psi), -r).
    Reads ``sl[i:i+3]`` (uuv.u, uuv.psi, uuv.r), writes ``sl[o:o+3]`` (uuv.thrust_{port,stbd,bow}_cmd, N);
    the PIDs at state offsets ``x_speed``, ``x_head`` and parameter offsets ``p_speed``, ``p_head``."""
    ff = drag_feedforward(x_uu, u_d)
    tot = pid_run(st, x_speed, pa, p_speed, u_d - sig[sl[i]], h, 0.0, FALSE, ff, 1.0)
    sig[sl[o]] = 0.5 * tot
    sig[sl[o + 1]] = 0.5 * tot
    e = wrap(psi_d - sig[sl[i + 1]])
    sig[sl[o + 2]] = pid_run(st, x_head, pa, p_head, e, h, -sig[sl[i + 2]], TRUE, 0.0, 1.0)


TOW_SIGNALS = Signals(
    usv_u=In("m/s"), usv_psi=In("rad"), usv_r=In("rad/s"), uuv_u=In("m/s"), uuv_psi=In("rad"), uuv_r=In("rad/s"),
    usv_port=Out("N"), usv_stbd=Out("N"), uuv_port=Out("N"), uuv_stbd=Out("N"), uuv_bow=Out("N"),
)  # fmt: skip
TOW_PARAMS = Layout(
    ("usv_speed", PID_PARAMS.size),
    ("usv_head", PID_PARAMS.size),
    ("uuv_speed", PID_PARAMS.size),
    ("uuv_head", PID_PARAMS.size),
    "h",
    "psi_d",
    "start_s",
    "u_d_usv",
    "u_d_uuv",
    "d11",
    "x_uu",
)
TOW_STATE = Layout(
    ("usv_speed", PID_STATE.size),
    ("usv_head", PID_STATE.size),
    ("uuv_speed", PID_STATE.size),
    ("uuv_head", PID_STATE.size),
)
_S, _P, _X = TOW_SIGNALS.at, TOW_PARAMS.at, TOW_STATE.at


@njit(cache=True)
def tow_straight_law(t, sig, sl, st, pa):
    """Both vehicles' loops of the straight tow (module docstring, 003 ch. 4 a): zero thrust before
    ``start_s``; then the USV's total thrust PID(u_d - u) + d11 u_d and a differential PD on the
    heading error, mixed by 003 eq. 3.11, and the UUV's loops (:func:`uuv_loops`). Outputs in N."""
    h = pa[_P.h]
    psi_d = pa[_P.psi_d]
    if t < pa[_P.start_s]:
        for i in range(_S.usv_port, _S.uuv_bow + 1):
            sig[sl[i]] = 0.0
        return
    u_d = pa[_P.u_d_usv]
    ff = pa[_P.d11] * u_d
    tot = pid_run(st, _X.usv_speed, pa, _P.usv_speed, u_d - sig[sl[_S.usv_u]], h, 0.0, FALSE, ff, 1.0)
    e = wrap(psi_d - sig[sl[_S.usv_psi]])
    dif = pid_run(st, _X.usv_head, pa, _P.usv_head, e, h, -sig[sl[_S.usv_r]], TRUE, 0.0, 1.0)
    sig[sl[_S.usv_port]], sig[sl[_S.usv_stbd]] = mix(0.5 * tot, 0.5 * dif)  # the one mixer (003 eq. 3.11)
    uuv_loops(sig, sl, _S.uuv_u, _S.uuv_port, st, _X.uuv_speed, _X.uuv_head, pa, _P.uuv_speed, _P.uuv_head,
              pa[_P.u_d_uuv], psi_d, h, pa[_P.x_uu])  # fmt: skip


@register_block("tow.straight")
class TowStraightControl(LawBlock):
    """Surge-speed and heading loops of both vehicles for the straight tow (003 ch. 4 a); law
    :func:`tow_straight_law`.

    USV: total thrust = PID(u_d - u) + d11 u_d (feed-forward), split equally, plus a differential
    PD on the heading error (003 eq. 3.11 mixing). UUV: total stern thrust = PID(u_d - u) - X_u|u|
    u_d |u_d| (feed-forward of the axial drag), split equally; bow thrust = PD on the heading error.
    Before ``start_s`` both speed commands are 0 and the thrusts are 0. Writes the ``*_cmd`` keys.
    """

    role = "controller"
    name = "tow_control"
    law = staticmethod(tow_straight_law)
    signals = TOW_SIGNALS

    def __init__(self, cmd: TowCommand, usv: USVConfig, uuv: UUVConfig, period: float = 0.01):
        self.cmd = cmd
        self.period = period
        self.usv_cfg = usv
        self.uuv_cfg = uuv
        self.bind(
            usv_u="usv.u",
            usv_psi="usv.psi",
            usv_r="usv.r",
            uuv_u="uuv.u",
            uuv_psi="uuv.psi",
            uuv_r="uuv.r",
            usv_port="usv.thrust_port_cmd",
            usv_stbd="usv.thrust_stbd_cmd",
            uuv_port="uuv.thrust_port_cmd",
            uuv_stbd="uuv.thrust_stbd_cmd",
            uuv_bow="uuv.thrust_bow_cmd",
        )
        c = cmd
        t_usv = usv.max_thrust_kgf * KGF
        r_usv = usv.max_reverse_kgf * KGF
        uuv_speed, uuv_head = uuv_loop_params(uuv, c.uuv_kp_speed, c.uuv_ki_speed, c.uuv_kp_heading, c.uuv_kd_heading)
        self.pa = TOW_PARAMS.pack(
            usv_speed=PID_PARAMS.pack(pid_params(c.usv_kp_speed, c.usv_ki_speed, 0.0, -2 * r_usv, 2 * t_usv)),
            usv_head=PID_PARAMS.pack(pid_params(c.usv_kp_heading, 0.0, c.usv_kd_heading, -t_usv, t_usv)),
            uuv_speed=uuv_speed,
            uuv_head=uuv_head,
            h=period,
            psi_d=math.radians(c.heading_deg),
            start_s=c.start_s,
            u_d_usv=c.usv_speed,
            u_d_uuv=c.uuv_speed,
            d11=usv.d11,
            x_uu=uuv.X_uu_total,
        )
        self.st = np.zeros(TOW_STATE.size)
        for n in ("usv_speed", "usv_head", "uuv_speed", "uuv_head"):
            setattr(self, n, PID.view(self.st, getattr(_X, n), self.pa, getattr(_P, n)))

    def reset(self, rng) -> None:
        self.st[:] = 0.0


class UUVFollowConfig(StrictModel):
    """UUV loops of ``tow-survey-depth``: heading toward the USV, surge speed held (0: thrusters off)."""

    speed: float = Field(0.8, ge=0, le=3, description="UUV surge speed command (0: thrusters off), m/s")
    kp_speed: float = Field(150.0, ge=0, le=1e5, description="speed P gain (total stern thrust), N s/m")
    ki_speed: float = Field(30.0, ge=0, le=1e5, description="speed I gain, N/m")
    kp_heading: float = Field(40.0, ge=0, le=1e4, description="heading P gain (bow thrust), N/rad")
    kd_heading: float = Field(40.0, ge=0, le=1e4, description="heading D gain, N s/rad")


class UUVFollowParams(UUVFollowConfig):
    """The gains and the vehicle the block drives, given by its scenario (``build_block(..., given=...)``)."""

    uuv: UUVConfig = Field(..., description="the UUV driven: thrust limits and surge drag X_uu")


FOLLOW_SIGNALS = Signals(
    usv_x=In("m"), usv_y=In("m"), uuv_x=In("m"), uuv_y=In("m"), uuv_u=In("m/s"), uuv_psi=In("rad"), uuv_r=In("rad/s"),
    port=Out("N"), stbd=Out("N"), bow=Out("N"),
)  # fmt: skip
FOLLOW_PARAMS = Layout(("speed", PID_PARAMS.size), ("head", PID_PARAMS.size), "u_d", "h", "x_uu")
FOLLOW_STATE = Layout(("speed", PID_STATE.size), ("head", PID_STATE.size))
_FS, _FP, _FX = FOLLOW_SIGNALS.at, FOLLOW_PARAMS.at, FOLLOW_STATE.at


@njit(cache=True)
def uuv_follow_law(t, sig, sl, st, pa):
    """The UUV heads for the USV (bearing from the UUV to the USV, :func:`bearing_to`) and holds its
    surge speed (:func:`uuv_loops`); a speed command of 0 switches its thrusters off (N)."""
    u_d = pa[_FP.u_d]
    if u_d <= 0.0:
        sig[sl[_FS.port]] = 0.0
        sig[sl[_FS.stbd]] = 0.0
        sig[sl[_FS.bow]] = 0.0
        return
    psi_d = bearing_to(sig[sl[_FS.usv_x]], sig[sl[_FS.usv_y]], sig[sl[_FS.uuv_x]], sig[sl[_FS.uuv_y]])
    uuv_loops(sig, sl, _FS.uuv_u, _FS.port, st, _FX.speed, _FX.head, pa, _FP.speed, _FP.head, u_d, psi_d,
              pa[_FP.h], pa[_FP.x_uu])  # fmt: skip


@register_block("uuv.follow_tow")
class UUVFollow(LawBlock):
    """UUV heading toward the USV (bow thruster PD) and surge speed (stern PID with drag feed-forward);
    law :func:`uuv_follow_law`."""

    role = "controller"
    name = "uuv_follow"
    law = staticmethod(uuv_follow_law)
    signals = FOLLOW_SIGNALS
    params_model = UUVFollowParams

    #: role (a truth signal name) of each measured input; the scenario may wire another bus key to it
    MEASURED = {"usv_x": "usv.x", "usv_y": "usv.y", "uuv_x": "uuv.x", "uuv_y": "uuv.y", "uuv_u": "uuv.u",
                "uuv_psi": "uuv.psi", "uuv_r": "uuv.r"}  # fmt: skip

    def __init__(self, cfg: UUVFollowConfig, uuv: UUVConfig, period: float = 0.01, meas=None):
        self.cfg = cfg
        self.uuv_cfg = uuv
        self.period = period
        keys = {**self.MEASURED, **(meas or {})}
        self.bind(**keys, port="uuv.thrust_port_cmd", stbd="uuv.thrust_stbd_cmd", bow="uuv.thrust_bow_cmd")
        speed, head = uuv_loop_params(uuv, cfg.kp_speed, cfg.ki_speed, cfg.kp_heading, cfg.kd_heading)
        self.pa = FOLLOW_PARAMS.pack(speed=speed, head=head, u_d=cfg.speed, h=period, x_uu=uuv.X_uu_total)
        self.st = np.zeros(FOLLOW_STATE.size)
        self.speed = PID.view(self.st, _FX.speed, self.pa, _FP.speed)
        self.head = PID.view(self.st, _FX.head, self.pa, _FP.head)

    @classmethod
    def from_context(cls, params: UUVFollowParams, ctx) -> UUVFollow:
        """Built from a scenario's UUV controller slot (``control.uuv.kind = "follow_tow"``): its gains,
        the vehicle ``uuv`` it drives and the measured positions, speed, heading and yaw rate by role."""
        meas = {n: ctx.signal(role) for n, role in cls.MEASURED.items()}
        return cls(params, params.uuv, ctx.period, meas=meas)

    def reset(self, rng) -> None:
        self.st[:] = 0.0
