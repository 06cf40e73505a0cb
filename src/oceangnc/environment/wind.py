"""Wind: speed and direction, or a Beaufort number (003 eq. 2.6-2.9 and table 2-4).

Direction follows the meteorological convention: the direction the wind blows *from*, deg from
north. The wind's NED velocity (where the air moves to) is published as ``env.wind_n``,
``env.wind_e`` (m/s); the vehicle models compute the relative wind and its loads from it.

Beaufort numbers map to the middle of the WMO band (m/s). Table 2-4 of 003 prints misprints
(Beaufort 5 as 8.0-10.0 m/s); the WMO bands used here are the standard ones (WMO-No. 8).
"""

from __future__ import annotations

import math

from numba import njit
from pydantic import Field, model_validator

from ..core.law import LawBlock, Layout, Out, Signals
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


SIGNALS = Signals(n=Out("m/s"), e=Out("m/s"), speed=Out("m/s"), direction=Out("deg"))
#: mean speed (m/s), direction from (deg), gust standard deviation (m/s), period and gust time constant (s)
PARAMS = Layout("speed", "direction_deg", "gust_sigma", "period", "gust_time_constant")
STATE = Layout("gust")
S, P, X = SIGNALS.at, PARAMS.at, STATE.at


@njit(cache=True)
def wind_law(t, sig, sl, st, pa, rng):
    """The wind (module docstring): with gusts, one exact first-order Gauss-Markov step of the gust
    (one normal draw); the speed (m/s, >= 0), and the NED velocity of the air, which moves toward
    the opposite of the direction it blows from (deg)."""
    if pa[P.gust_sigma] > 0.0:
        a = math.exp(-pa[P.period] / pa[P.gust_time_constant])
        st[X.gust] = a * st[X.gust] + pa[P.gust_sigma] * math.sqrt(1 - a * a) * rng.standard_normal()
    speed = max(0.0, pa[P.speed] + st[X.gust])
    to = math.radians(pa[P.direction_deg]) + math.pi  # air moves toward the opposite of "from"
    sig[sl[S.n]] = speed * math.cos(to)
    sig[sl[S.e]] = speed * math.sin(to)
    sig[sl[S.speed]] = speed
    sig[sl[S.direction]] = pa[P.direction_deg]


@register_block("env.wind")
class Wind(LawBlock):
    """Discrete block publishing the wind's NED velocity (with optional first-order gusts); law
    :func:`wind_law`."""

    role = "environment"
    name = "wind"
    law = staticmethod(wind_law)
    signals = SIGNALS
    draws = True

    def __init__(self, cfg: WindConfig, period: float = 0.1):
        self.cfg = cfg
        self.period = float(period)
        self.bind(n="env.wind_n", e="env.wind_e", speed="env.wind_speed", direction="env.wind_direction_deg")
        self.pa = PARAMS.pack(
            speed=cfg.speed,
            direction_deg=cfg.direction_deg,
            gust_sigma=cfg.gust_sigma,
            period=self.period,
            gust_time_constant=cfg.gust_time_constant,
        )
        self.st = STATE.pack(gust=0.0)

    def reset(self, rng) -> None:
        self.rng = rng
        self.st[X.gust] = 0.0

    @property
    def gust(self) -> float:
        """The gust now, m/s."""
        return float(self.st[X.gust])
