"""Depth or altitude of a towed UUV held by the winch's drum speed (issue 16).

:class:`WinchDepthController` (registered ``"winch.depth"``) computes the line speed command
``winch.speed_cmd`` (m/s, + paying out) from the UUV's depth ``uuv.z`` (mode ``"depth"``) or its altitude
above the seabed ``uuv.altitude`` (mode ``"altitude"``):

    e = z_ref - z            (depth mode: too shallow -> pay out)
    e = a - a_ref            (altitude mode: too high -> pay out)
    s_c = K_p e + K_i int e + K_d de/dt + ds_ref/dt   (PID, back-calculation anti-windup, feed-forward)

The reference may move: in depth mode a trapezoidal profile (``profile``: list of (t, z) breakpoints,
linearly interpolated), whose rate is fed forward (for a cable hanging nearly vertically a metre of
payout is a metre of depth). **Tension**: above ``tension_margin`` x the winch's tension limit the
command is raised to at least K_T (T - T_margin), so the controller pays out rather than drive the
tension to the limit (the winch itself renders at the limit as the last resort). The command is
saturated to +-``speed_max`` (the winch saturates again and logs it).
"""

from __future__ import annotations

import math
from typing import Literal

import numpy as np
from pydantic import Field

from ..core.blocks import Block
from ..core.registry import register_block
from ..io.config import StrictModel
from ._compiled_tow import profile_reference, tension_payout
from .pid import PID


class WinchControlConfig(StrictModel):
    """Gains and limits of the depth/altitude-by-winch loop."""

    mode: Literal["depth", "altitude"] = Field("depth", description="hold the UUV's depth or its altitude")
    target: float = Field(5.0, ge=0, le=1e4, description="depth (depth mode) or altitude target, m")
    profile: list[tuple[float, float]] = Field(
        [],
        description="depth mode: (t s, z m) breakpoints of a moving target, linear between them "
        "(empty: the constant target)",
    )
    kp: float = Field(0.3, ge=0, le=100, description="proportional gain, (m/s)/m")
    ki: float = Field(0.01, ge=0, le=100, description="integral gain, (m/s)/(m s)")
    kd: float = Field(0.0, ge=0, le=1000, description="derivative gain (on the measured error), (m/s)/(m/s)")
    speed_max: float = Field(0.5, gt=0, le=5, description="command limit, m/s")
    tension_margin: float = Field(
        0.8, gt=0, le=1, description="fraction of the winch's tension limit where the loop starts paying out, -"
    )
    tension_gain: float = Field(0.005, ge=0, le=10, description="K_T: payout per newton above the margin, (m/s)/N")
    rate: float = Field(10.0, gt=0, le=1000, description="loop rate, Hz")


@register_block("winch.depth")
class WinchDepthController(Block):
    """Drum speed command for a depth or altitude target (module docstring).

    Reads ``uuv.z`` or ``uuv.altitude`` (m) and ``cable.top_tension`` (N); writes ``winch.speed_cmd``
    (m/s), ``winch.target`` (m: the current depth or altitude target) and ``winch.error`` (m).
    """

    name = "winch_control"

    def __init__(self, cfg: WinchControlConfig, tension_max: float):
        self.cfg = cfg
        self.period = 1.0 / cfg.rate
        self.tension_max = float(tension_max)
        self.meas = "uuv.z" if cfg.mode == "depth" else "uuv.altitude"
        self.inputs = {self.meas: "m", "cable.top_tension": "N"}
        self.outputs = {"winch.speed_cmd": "m/s", "winch.target": "m", "winch.error": "m"}
        prof = np.asarray(cfg.profile, float) if cfg.profile else np.zeros((0, 2))
        self._pt = prof[:, 0] if len(prof) else None
        self._pz = prof[:, 1] if len(prof) else None
        self.pid = PID(cfg.kp, cfg.ki, cfg.kd, -cfg.speed_max, cfg.speed_max)

    def reset(self, rng) -> None:
        self.pid.reset()

    def reference(self, t: float) -> tuple[float, float]:
        """(target m, its rate m/s) at time ``t``."""
        if self._pt is None:
            return self.cfg.target, 0.0
        z, rate = profile_reference(float(t), self._pt, self._pz)
        return float(z), float(rate)

    def compiled(self):
        """Compiled form for the fused loop (:func:`oceangnc.control._compiled_tow.winch_depth_step`)."""
        from ..core.fused import CompiledBlock
        from ._compiled import arr, pid_params, pid_state
        from ._compiled_tow import winch_depth_step

        c = self.cfg
        prof = [] if self._pt is None or self._pz is None else [*self._pt, *self._pz]
        pa = pid_params(self.pid) + [self.period, 0.0 if c.mode == "depth" else 1.0]
        pa += [c.tension_margin * self.tension_max, c.tension_gain, c.speed_max, c.target, len(prof) // 2, *prof]
        sig = [self.meas, "?cable.top_tension", "winch.speed_cmd", "winch.target", "winch.error"]
        return CompiledBlock(winch_depth_step, sig, arr(pid_state(self.pid)), arr(pa))

    def step(self, t: float, bus: dict) -> None:
        c = self.cfg
        ref, rate = self.reference(t)
        y = float(bus.get(self.meas, math.nan))
        if not math.isfinite(y):
            bus["winch.speed_cmd"] = 0.0
            bus["winch.target"] = ref
            bus["winch.error"] = 0.0
            return
        e = (ref - y) if c.mode == "depth" else (y - ref)
        s = self.pid.step(e, self.period, feedforward=rate if c.mode == "depth" else 0.0)
        tm = c.tension_margin * self.tension_max
        T = float(bus.get("cable.top_tension", 0.0))
        bus["winch.speed_cmd"] = float(tension_payout(s, T, tm, c.tension_gain, c.speed_max))
        bus["winch.target"] = ref
        bus["winch.error"] = e
