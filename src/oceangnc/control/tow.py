"""Straight-tow loops of both vehicles of the combined system (003 ch. 4 a, figs 4-2 to 4-5).

USV: total thrust = PID(u_d - u) + d11 u_d (feed-forward), split equally, plus a differential PD on
the heading error, mixed by 003 eq. 3.11 (:func:`oceangnc.control.usv_control.mix`). UUV: total
stern thrust = PID(u_d - u) - X_u|u| u_d |u_d| (feed-forward of the axial drag), split equally; bow
thrust = PD on the heading error. The gains are design values of ``tow-straight``.
"""

from __future__ import annotations

import math

from pydantic import Field

from ..core.blocks import Block
from ..core.registry import register_block
from ..core.rotations import wrap
from ..io.config import StrictModel
from ..models.usv import USVConfig
from ..models.uuv import UUVConfig
from ..units import KGF
from ._compiled_tow import bearing_to, drag_feedforward
from .pid import PID
from .usv_control import mix, speed_loop

_USV_CMD = ("usv.thrust_port_cmd", "usv.thrust_stbd_cmd")
_UUV_CMD = ("uuv.thrust_port_cmd", "uuv.thrust_stbd_cmd", "uuv.thrust_bow_cmd")


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


def uuv_loops(uuv: UUVConfig, kp_speed: float, ki_speed: float, kp_heading: float, kd_heading: float):
    """The UUV's tow loops: surge-speed PI on the total stern thrust, limited to twice a thruster's
    range, and heading PD on the bow thruster (N)."""
    t_max = uuv.max_thrust_kgf * KGF
    r_max = uuv.max_reverse_kgf * KGF
    return (PID(kp_speed, ki_speed, 0.0, -2 * r_max, 2 * t_max), PID(kp_heading, 0.0, kd_heading, -r_max, t_max))


def uuv_loops_step(bus: dict, uuv: UUVConfig, speed: PID, head: PID, u_d: float, psi_d: float, h: float) -> None:
    """One step of :func:`uuv_loops`: stern thrust PID(u_d - u) - X_u|u| u_d |u_d| (axial-drag
    feed-forward) shared by both stern thrusters; bow thrust PD(wrap(psi_d - psi), -r). Writes the
    ``uuv.thrust_*_cmd`` keys (N)."""
    ff = float(drag_feedforward(uuv.X_uu_total, u_d))
    tot = speed.step(u_d - bus["uuv.u"], h, feedforward=ff)
    bus["uuv.thrust_port_cmd"] = 0.5 * tot
    bus["uuv.thrust_stbd_cmd"] = 0.5 * tot
    bus["uuv.thrust_bow_cmd"] = head.step(wrap(psi_d - bus["uuv.psi"]), h, e_dot=-bus["uuv.r"])


@register_block("tow.straight")
class TowStraightControl(Block):
    """Surge-speed and heading loops of both vehicles for the straight tow (003 ch. 4 a).

    USV: total thrust = PID(u_d - u) + d11 u_d (feed-forward), split equally, plus a differential
    PD on the heading error (003 eq. 3.11 mixing). UUV: total stern thrust = PID(u_d - u) - X_u|u|
    u_d |u_d| (feed-forward of the axial drag), split equally; bow thrust = PD on the heading error.
    Before ``start_s`` both speed commands are 0 and the thrusts are 0. Writes the ``*_cmd`` keys.
    """

    role = "controller"
    name = "tow_control"

    def __init__(self, cmd: TowCommand, usv: USVConfig, uuv: UUVConfig, period: float = 0.01):
        self.cmd = cmd
        self.period = period
        self.usv_cfg = usv
        self.uuv_cfg = uuv
        self.inputs = {
            "usv.u": "m/s",
            "usv.psi": "rad",
            "usv.r": "rad/s",
            "uuv.u": "m/s",
            "uuv.psi": "rad",
            "uuv.r": "rad/s",
        }
        self.outputs = {
            "usv.thrust_port_cmd": "N",
            "usv.thrust_stbd_cmd": "N",
            "uuv.thrust_port_cmd": "N",
            "uuv.thrust_stbd_cmd": "N",
            "uuv.thrust_bow_cmd": "N",
        }

    def reset(self, rng) -> None:
        c = self.cmd
        t_usv = self.usv_cfg.max_thrust_kgf * KGF
        r_usv = self.usv_cfg.max_reverse_kgf * KGF
        self.usv_speed = PID(c.usv_kp_speed, c.usv_ki_speed, 0.0, -2 * r_usv, 2 * t_usv)
        self.usv_head = PID(c.usv_kp_heading, 0.0, c.usv_kd_heading, -t_usv, t_usv)
        self.uuv_speed, self.uuv_head = uuv_loops(
            self.uuv_cfg, c.uuv_kp_speed, c.uuv_ki_speed, c.uuv_kp_heading, c.uuv_kd_heading
        )

    def compiled(self):
        """Compiled form for the fused loop (:func:`oceangnc.control._compiled_tow.tow_straight_step`)."""
        from ..core.fused import CompiledBlock
        from ._compiled import arr, pid_params, pid_state
        from ._compiled_tow import tow_straight_step

        c = self.cmd
        pids = (self.usv_speed, self.usv_head, self.uuv_speed, self.uuv_head)
        st = arr(sum((pid_state(q) for q in pids), []))
        pa = sum((pid_params(q) for q in pids), []) + [self.period, math.radians(c.heading_deg), c.start_s]
        pa += [c.usv_speed, c.uuv_speed, self.usv_cfg.d11, self.uuv_cfg.X_uu_total]
        sig = ["usv.u", "usv.psi", "usv.r", "uuv.u", "uuv.psi", "uuv.r", *_USV_CMD, *_UUV_CMD]
        return CompiledBlock(tow_straight_step, sig, st, arr(pa))

    def step(self, t: float, bus: dict) -> None:
        c = self.cmd
        h = self.period
        psi_d = math.radians(c.heading_deg)
        if t < c.start_s:
            for k in (
                "usv.thrust_port_cmd",
                "usv.thrust_stbd_cmd",
                "uuv.thrust_port_cmd",
                "uuv.thrust_stbd_cmd",
                "uuv.thrust_bow_cmd",
            ):
                bus[k] = 0.0
            return
        # USV
        tot = speed_loop(self.usv_speed, c.usv_speed, bus["usv.u"], h, self.usv_cfg.d11, share=1.0)
        e = wrap(psi_d - bus["usv.psi"])
        dif = self.usv_head.step(e, h, e_dot=-bus["usv.r"])
        bus["usv.thrust_port_cmd"], bus["usv.thrust_stbd_cmd"] = mix(0.5 * tot, 0.5 * dif)
        uuv_loops_step(bus, self.uuv_cfg, self.uuv_speed, self.uuv_head, c.uuv_speed, psi_d, h)


class UUVFollowConfig(StrictModel):
    """UUV loops of ``tow-survey-depth``: heading toward the USV, surge speed held (0: thrusters off)."""

    speed: float = Field(0.8, ge=0, le=3, description="UUV surge speed command (0: thrusters off), m/s")
    kp_speed: float = Field(150.0, ge=0, le=1e5, description="speed P gain (total stern thrust), N s/m")
    ki_speed: float = Field(30.0, ge=0, le=1e5, description="speed I gain, N/m")
    kp_heading: float = Field(40.0, ge=0, le=1e4, description="heading P gain (bow thrust), N/rad")
    kd_heading: float = Field(40.0, ge=0, le=1e4, description="heading D gain, N s/rad")


@register_block("uuv.follow_tow")
class UUVFollow(Block):
    """UUV heading toward the USV (bow thruster PD) and surge speed (stern PID with drag feed-forward)."""

    role = "controller"
    name = "uuv_follow"

    def __init__(self, cfg: UUVFollowConfig, uuv: UUVConfig, period: float = 0.01):
        self.cfg = cfg
        self.uuv_cfg = uuv
        self.period = period
        self.inputs = {
            k: u
            for k, u in (
                ("usv.x", "m"),
                ("usv.y", "m"),
                ("uuv.x", "m"),
                ("uuv.y", "m"),
                ("uuv.psi", "rad"),
                ("uuv.r", "rad/s"),
                ("uuv.u", "m/s"),
            )
        }
        self.outputs = {"uuv.thrust_port_cmd": "N", "uuv.thrust_stbd_cmd": "N", "uuv.thrust_bow_cmd": "N"}

    params_model = UUVFollowConfig

    @classmethod
    def from_context(cls, params: UUVFollowConfig, ctx) -> UUVFollow:
        """Built from a scenario's UUV controller slot (``control.uuv.kind = "follow_tow"``)."""
        return cls(params, ctx.cfg.uuv, ctx.period)

    def reset(self, rng) -> None:
        c = self.cfg
        self.speed, self.head = uuv_loops(self.uuv_cfg, c.kp_speed, c.ki_speed, c.kp_heading, c.kd_heading)

    def compiled(self):
        """Compiled form for the fused loop (:func:`oceangnc.control._compiled_tow.uuv_follow_step`)."""
        from ..core.fused import CompiledBlock
        from ._compiled import arr, pid_params, pid_state
        from ._compiled_tow import uuv_follow_step

        sig = ["usv.x", "usv.y", "uuv.x", "uuv.y", "uuv.u", "uuv.psi", "uuv.r", *_UUV_CMD]
        st = arr(pid_state(self.speed) + pid_state(self.head))
        pa = pid_params(self.speed) + pid_params(self.head) + [self.cfg.speed, self.period, self.uuv_cfg.X_uu_total]
        return CompiledBlock(uuv_follow_step, sig, st, arr(pa))

    def step(self, t: float, bus: dict) -> None:
        c = self.cfg
        if c.speed <= 0.0:
            bus["uuv.thrust_port_cmd"] = bus["uuv.thrust_stbd_cmd"] = bus["uuv.thrust_bow_cmd"] = 0.0
            return
        psi_d = bearing_to(bus["usv.x"], bus["usv.y"], bus["uuv.x"], bus["uuv.y"])
        uuv_loops_step(bus, self.uuv_cfg, self.speed, self.head, c.speed, psi_d, self.period)
