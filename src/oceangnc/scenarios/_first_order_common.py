"""Shared pieces of the first-order USV scenarios (000): the autopilot designs, the closed-loop blocks and the
LOS / hybrid waypoint guidance config (000 table 1)."""

from __future__ import annotations

import math
from typing import Literal

import numpy as np
from pydantic import Field, model_validator

from ..control.actuators import RudderEngineBlock
from ..control.pole_placement import (
    HeadingAutopilot,
    SpeedAutopilot,
)
from ..core.blocks import ConstantBlock
from ..errors import ConfigError
from ..io.config import ScenarioConfig, StrictModel
from ..models.first_order import FirstOrderConfig, FirstOrderSchedule

RAD2DEG = 180.0 / math.pi


# -- shared config ----------------------------------------------------------------------------------------


class HeadingDesign(StrictModel):
    """Pole placement of the heading PD (000 eq. 26-27)."""

    zeta: float = Field(0.7, gt=0, le=2, description="closed-loop damping ratio, -")
    wn: float = Field(0.6, gt=0, le=10, description="closed-loop natural frequency, rad/s")


class SpeedDesign(StrictModel):
    """Pole placement of the speed P controller (000 eq. 31)."""

    zeta: float = Field(1.0, gt=0, le=2, description="damping ratio used in eq. 31, -")
    wn: float = Field(2.0, gt=0, le=20, description="natural frequency used in eq. 31 (pole at 2 zeta w_n), rad/s")


class ClosedLoopConfig(ScenarioConfig):
    """The first-order USV with both autopilots."""

    usv: FirstOrderConfig = FirstOrderConfig()
    heading: HeadingDesign = HeadingDesign()
    speed_control: SpeedDesign = SpeedDesign()
    control_rate: float = Field(20.0, gt=0, le=1000, description="autopilot and actuator rate, Hz")


def check_design(cfg) -> None:
    """Refuse a design with 2 zeta w_n T <= 1 anywhere in the trial ranges (000 eq. 26/31), naming the key."""
    from ..control.pole_placement import heading_gains, speed_gain

    u = cfg.usv
    for sec, law, fn, speeds in (
        ("heading", ("K_r", "T_r"), heading_gains, (u.turn_lo_mps, u.turn_hi_mps)),
        ("speed_control", ("K_v", "T_v"), speed_gain, (u.straight_lo_mps, u.straight_hi_mps)),
    ):
        d = getattr(cfg, sec)
        for sp in speeds:
            c = u.coefficients(sp)
            try:
                fn(c[law[0]], c[law[1]], d.zeta, d.wn)
            except ConfigError as e:
                raise ConfigError(
                    f"config error: {sec}.wn = {d.wn:g} / {sec}.zeta = {d.zeta:g}: at {sp:g} m/s "
                    f"{str(e).split(': ', 1)[1]}"
                ) from None


def _nomoto(cfg):
    return FirstOrderSchedule(cfg.usv, "nomoto")


def _speedlaw(cfg):
    return FirstOrderSchedule(cfg.usv, "speed")


def closed_loop_blocks(cfg, guidance_blocks, rpm_open_loop: float | None = None):
    """Guidance/command blocks, heading PD, speed P (or a fixed rpm) and the actuators."""
    check_design(cfg)
    h = 1.0 / cfg.control_rate
    blocks = list(guidance_blocks)
    blocks.append(HeadingAutopilot(_nomoto(cfg), cfg.heading.zeta, cfg.heading.wn, h))
    if rpm_open_loop is None:
        blocks.append(SpeedAutopilot(_speedlaw(cfg), cfg.speed_control.zeta, cfg.speed_control.wn, h))
    else:
        n = float(rpm_open_loop)
        blocks.append(ConstantBlock("engine", h, {"usv.rpm_cmd": n}, units={"usv.rpm_cmd": "rpm"}))
    blocks.append(RudderEngineBlock(cfg.usv, h))
    return blocks


def _settling_time(t, y, target, band, t0):
    out = np.nonzero(np.abs(y - target) > band)[0]
    if out.size == 0:
        return 0.0
    if out[-1] == y.size - 1:
        return float("nan")
    return float(t[out[-1] + 1] - t0)


# -- waypoint guidance ------------------------------------------------------------------------------------


class GuidanceConfig(StrictModel):
    """LOS / hybrid guidance (000 table 1)."""

    mode: Literal["los", "hybrid"] = "hybrid"
    R: float = Field(25.0, gt=0, le=1e4, description="LOS circle radius R (and band unit of table 1), m")
    R1: float | None = Field(None, gt=0, le=1e4, description="circle radius in 0.5R < d <= R (> R; default 1.25 R), m")
    R2: float | None = Field(None, gt=0, le=1e4, description="circle radius in R < d <= 2R (> 2R; default 2.5 R), m")
    accept_radius: float | None = Field(None, gt=0, le=1e4, description="waypoint acceptance radius (default R), m")
    rate: float = Field(10.0, gt=0, le=100, description="guidance update rate, Hz")

    @model_validator(mode="after")
    def _radii(self):
        if self.R1 is not None and not self.R1 > self.R:
            raise ValueError(f"R1 = {self.R1} must be > R = {self.R} (the circle must reach the leg)")
        if self.R2 is not None and not self.R2 > 2 * self.R:
            raise ValueError(f"R2 = {self.R2} must be > 2R = {2 * self.R}")
        return self


def waypoint_guidance(g: GuidanceConfig, waypoints, speed=5.0, speeds=None, stop=True):
    """The LOS / hybrid waypoint guidance block of ``g`` (000 table 1) through ``waypoints`` [north, east] m."""
    from ..guidance.los import WaypointGuidance

    return WaypointGuidance(
        waypoints, g.mode, g.R, g.R1, g.R2, g.accept_radius, speed, speeds, 1.0 / g.rate, stop_at_end=stop
    )
