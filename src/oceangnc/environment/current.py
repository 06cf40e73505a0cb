"""Ocean current: constant or first-order Gauss-Markov speed and direction (003 eq. 2.10-2.12).

The current is uniform in space, given in the NED earth frame by its speed V_c (m/s) and the
direction it flows *toward* beta_c (oceanographic convention, deg from north, clockwise). It enters
the vehicle models through the relative velocity nu_r = nu - R^T v_c (003 eq. 2.12). The
Gauss-Markov variant (003 eq. 2.11; Fossen 2011 eq. 8.93) is discretised exactly:

    V_{k+1} = V_mean + exp(-h/T) (V_k - V_mean) + sigma sqrt(1 - exp(-2h/T)) w_k,   w_k ~ N(0, 1),

and the same for the direction, so the process is stationary with standard deviation sigma.
Published signals: ``env.current_n``, ``env.current_e`` (m/s, NED), ``env.current_speed`` (m/s),
``env.current_direction_deg`` (deg, toward).
"""

from __future__ import annotations

import math
from typing import Literal

import numpy as np
from pydantic import Field

from ..core.blocks import Block
from ..core.registry import register_block
from ..io.config import StrictModel


class CurrentConfig(StrictModel):
    """Current settings."""

    speed: float = Field(0.0, ge=0.0, le=5.0, description="mean current speed, m/s")
    direction_deg: float = Field(
        0.0, ge=-360.0, le=360.0, description="direction the current flows toward, deg from north"
    )
    model: Literal["constant", "gauss-markov"] = "constant"
    time_constant: float = Field(300.0, gt=0.0, le=1e6, description="Gauss-Markov correlation time, s")
    sigma_speed: float = Field(0.02, ge=0.0, le=1.0, description="Gauss-Markov speed standard deviation, m/s")
    sigma_direction_deg: float = Field(
        5.0, ge=0.0, le=180.0, description="Gauss-Markov direction standard deviation, deg"
    )


@register_block("env.current")
class OceanCurrent(Block):
    """Discrete block publishing the current's NED velocity every ``period`` s."""

    role = "environment"

    name = "current"

    outputs = {
        "env.current_n": "m/s",
        "env.current_e": "m/s",
        "env.current_speed": "m/s",
        "env.current_direction_deg": "deg",
    }
    inputs: dict[str, str] = {}

    def __init__(self, cfg: CurrentConfig, period: float = 0.1):
        self.cfg = cfg
        self.period = float(period)
        self.speed = cfg.speed
        self.direction = math.radians(cfg.direction_deg)

    def reset(self, rng: np.random.Generator) -> None:
        self.rng = rng
        self.speed = self.cfg.speed
        self.direction = math.radians(self.cfg.direction_deg)

    def compiled(self):
        """Compiled form for the fused loop (constant current only; see :mod:`oceangnc.core.fused`)."""
        if self.cfg.model != "constant":
            return None
        from ..core.fused import CompiledBlock
        from ..models._compiled import constant_current_step

        return CompiledBlock(
            constant_current_step,
            ["env.current_n", "env.current_e", "env.current_speed", "env.current_direction_deg"],
            params=np.array([self.cfg.speed, math.radians(self.cfg.direction_deg)]),
        )

    def step(self, t: float, bus: dict) -> None:
        c = self.cfg
        if c.model == "gauss-markov" and t > 0.0:
            a = math.exp(-self.period / c.time_constant)
            s = math.sqrt(1.0 - a * a)
            w1, w2 = self.rng.standard_normal(2)
            self.speed = max(0.0, c.speed + a * (self.speed - c.speed) + c.sigma_speed * s * w1)
            d0 = math.radians(c.direction_deg)
            self.direction = d0 + a * (self.direction - d0) + math.radians(c.sigma_direction_deg) * s * w2
        bus["env.current_n"] = self.speed * math.cos(self.direction)
        bus["env.current_e"] = self.speed * math.sin(self.direction)
        bus["env.current_speed"] = self.speed
        bus["env.current_direction_deg"] = math.degrees(self.direction)
