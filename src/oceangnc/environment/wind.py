"""Wind: speed and direction, or a Beaufort number (003 eq. 2.6-2.9 and table 2-4).

Direction follows the meteorological convention: the direction the wind blows *from*, deg from
north. The wind's NED velocity (where the air moves to) is published as ``env.wind_n``,
``env.wind_e`` (m/s); the vehicle models compute the relative wind and its loads from it.

Beaufort numbers map to the middle of the WMO band (m/s). Table 2-4 of 003 prints misprints
(Beaufort 5 as 8.0-10.0 m/s); the WMO bands used here are the standard ones (WMO-No. 8).
"""

from __future__ import annotations

import math

import numpy as np
from pydantic import Field, model_validator

from ..core.blocks import Block
from ..core.registry import register_block
from ..io.config import StrictModel

#: WMO Beaufort bands (lower, upper) in m/s; force 12 has no upper bound (taken as 36.9 m/s).
BEAUFORT_BANDS = [
    (0.0, 0.2),
    (0.3, 1.5),
    (1.6, 3.3),
    (3.4, 5.4),
    (5.5, 7.9),
    (8.0, 10.7),
    (10.8, 13.8),
    (13.9, 17.1),
    (17.2, 20.7),
    (20.8, 24.4),
    (24.5, 28.4),
    (28.5, 32.6),
    (32.7, 36.9),
]


def beaufort_speed(number: int) -> float:
    """Mean wind speed (m/s) of a Beaufort number 0-12 (middle of the WMO band)."""
    if not 0 <= int(number) <= 12:
        raise ValueError(f"Beaufort number must be 0-12, got {number}")
    lo, hi = BEAUFORT_BANDS[int(number)]
    return 0.5 * (lo + hi)


class WindConfig(StrictModel):
    """Wind settings: either ``speed`` or ``beaufort`` (which then sets the speed)."""

    speed: float = Field(0.0, ge=0.0, le=60.0, description="mean wind speed, m/s")
    beaufort: int | None = Field(None, ge=0, le=12, description="Beaufort number; overrides speed, 0-12")
    direction_deg: float = Field(0.0, ge=-360.0, le=360.0, description="direction the wind blows from, deg from north")
    gust_sigma: float = Field(0.0, ge=0.0, le=20.0, description="gust standard deviation, m/s")
    gust_time_constant: float = Field(5.0, gt=0.0, le=1e4, description="gust correlation time, s")

    @model_validator(mode="after")
    def _beaufort(self):
        if self.beaufort is not None:
            object.__setattr__(self, "speed", beaufort_speed(self.beaufort))
        return self


@register_block("env.wind")
class Wind(Block):
    """Discrete block publishing the wind's NED velocity (with optional first-order gusts)."""

    role = "environment"

    name = "wind"

    outputs = {"env.wind_n": "m/s", "env.wind_e": "m/s", "env.wind_speed": "m/s", "env.wind_direction_deg": "deg"}
    inputs: dict[str, str] = {}

    def __init__(self, cfg: WindConfig, period: float = 0.1):
        self.cfg = cfg
        self.period = float(period)
        self.gust = 0.0

    def reset(self, rng: np.random.Generator) -> None:
        self.rng = rng
        self.gust = 0.0

    def compiled(self):
        """Compiled form for the fused loop (steady wind only; see :mod:`oceangnc.core.fused`)."""
        if self.cfg.gust_sigma > 0.0:
            return None
        from ..core.fused import CompiledBlock
        from ..models._compiled import steady_wind_step

        return CompiledBlock(
            steady_wind_step,
            ["env.wind_n", "env.wind_e", "env.wind_speed", "env.wind_direction_deg"],
            params=np.array([self.cfg.speed, self.cfg.direction_deg]),
        )

    def step(self, t: float, bus: dict) -> None:
        c = self.cfg
        if c.gust_sigma > 0.0:
            a = math.exp(-self.period / c.gust_time_constant)
            self.gust = a * self.gust + c.gust_sigma * math.sqrt(1 - a * a) * self.rng.standard_normal()
        speed = max(0.0, c.speed + self.gust)
        to = math.radians(c.direction_deg) + math.pi  # air moves toward the opposite of "from"
        bus["env.wind_n"] = speed * math.cos(to)
        bus["env.wind_e"] = speed * math.sin(to)
        bus["env.wind_speed"] = speed
        bus["env.wind_direction_deg"] = c.direction_deg
