"""Ocean current: constant or first-order Gauss-Markov speed and direction (003 eq. 2.10-2.12).

The current is uniform in space, given in the NED earth frame by its speed V_c (m/s) and the
direction it flows *toward* beta_c (oceanographic convention, deg from north, clockwise). It enters
the vehicle models through the relative velocity nu_r = nu - R^T v_c (003 eq. 2.12). The
Gauss-Markov variant (003 eq. 2.11; Fossen 2011 eq. 8.93) is discretised exactly:

    V_{k+1} = V_mean + exp(-h/T) (V_k - V_mean) + sigma sqrt(1 - exp(-2h/T)) w_k,   w_k ~ N(0, 1),

and the same for the direction, so the process is stationary with standard deviation sigma.
Published signals: ``env.current_n``, ``env.current_e`` (m/s, NED), ``env.current_speed`` (m/s),
``env.current_direction_deg`` (deg, toward). Law: :func:`current_law`.
"""

from __future__ import annotations

import math
from typing import Literal

from numba import njit
from pydantic import Field

from ..core.law import LawBlock, Layout, Out, Signals
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


SIGNALS = Signals(n=Out("m/s"), e=Out("m/s"), speed=Out("m/s"), direction=Out("deg"))
#: mean speed (m/s) and direction (rad, toward); Gauss-Markov (1/0), its period and time constant (s),
#: standard deviations of the speed (m/s) and of the direction (rad)
PARAMS = Layout("speed", "direction", "gauss_markov", "period", "time_constant", "sigma_speed", "sigma_direction")
STATE = Layout("speed", "direction")
S, P, X = SIGNALS.at, PARAMS.at, STATE.at


@njit(cache=True)
def current_law(t, sig, sl, st, pa, rng):
    """The current (module docstring): with the Gauss-Markov model, after t = 0, one exact step of
    003 eq. 2.11 for the speed (kept >= 0) and the direction (two normal draws, speed first); then
    the NED velocity (m/s), the speed (m/s) and the direction (deg, toward)."""
    if pa[P.gauss_markov] != 0.0 and t > 0.0:
        a = math.exp(-pa[P.period] / pa[P.time_constant])
        s = math.sqrt(1.0 - a * a)
        w1 = rng.standard_normal()
        w2 = rng.standard_normal()
        v0 = pa[P.speed]
        st[X.speed] = max(0.0, v0 + a * (st[X.speed] - v0) + pa[P.sigma_speed] * s * w1)
        d0 = pa[P.direction]
        st[X.direction] = d0 + a * (st[X.direction] - d0) + pa[P.sigma_direction] * s * w2
    sig[sl[S.n]] = st[X.speed] * math.cos(st[X.direction])
    sig[sl[S.e]] = st[X.speed] * math.sin(st[X.direction])
    sig[sl[S.speed]] = st[X.speed]
    sig[sl[S.direction]] = math.degrees(st[X.direction])


@register_block("env.current")
class OceanCurrent(LawBlock):
    """Discrete block publishing the current's NED velocity every ``period`` s; law :func:`current_law`."""

    role = "environment"
    name = "current"
    law = staticmethod(current_law)
    signals = SIGNALS
    draws = True

    def __init__(self, cfg: CurrentConfig, period: float = 0.1):
        self.cfg = cfg
        self.period = float(period)
        self.bind(n="env.current_n", e="env.current_e", speed="env.current_speed",
                  direction="env.current_direction_deg")  # fmt: skip
        self.pa = PARAMS.pack(
            speed=cfg.speed,
            direction=math.radians(cfg.direction_deg),
            gauss_markov=1.0 if cfg.model == "gauss-markov" else 0.0,
            period=self.period,
            time_constant=cfg.time_constant,
            sigma_speed=cfg.sigma_speed,
            sigma_direction=math.radians(cfg.sigma_direction_deg),
        )
        self.st = STATE.pack(speed=self.pa[P.speed], direction=self.pa[P.direction])

    def reset(self, rng) -> None:
        self.rng = rng
        self.st[X.speed] = self.pa[P.speed]
        self.st[X.direction] = self.pa[P.direction]

    @property
    def speed(self) -> float:
        """The current's speed now, m/s."""
        return float(self.st[X.speed])

    @property
    def direction(self) -> float:
        """The direction it flows toward now, rad from north."""
        return float(self.st[X.direction])
