"""Shared pieces of the first-order USV scenarios (000): the autopilot designs and the closed-loop blocks."""

from __future__ import annotations

import math

import numpy as np
from pydantic import Field

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
