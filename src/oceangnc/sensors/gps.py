"""GPS receiver (003 ch. 6.1.1, appendix B table C-1: Hemisphere Vector H200).

Position error = a slowly varying bias + white jitter, both per horizontal axis:

    b_{k+1} = exp(-h/T) b_k + sigma_b sqrt(1 - exp(-2h/T)) w_k,   sigma_b = HDOP * UERE / sqrt(2)
    x_gps = x + b + sigma_j v_k

HDOP times the user equivalent range error (UERE) is the horizontal RMS error (the usual DOP
definition); UERE = 0.17 m makes the 2DRMS (about 95 %) error 2 * 0.9 * 0.17 = 0.3 m at the measured
mean HDOP 0.9 (003 fig. 6-1), the SBAS/DGPS horizontal accuracy of table C-1. The bias is
Gauss-Markov with a 300 s correlation time (our choice; satellite-geometry and atmospheric errors
change over minutes), and the jitter sigma_j = 0.01 m, so a
standing receiver wanders by centimetres over seconds, as 003 fig. 6-3 shows ("very accurate in cm").

Heading from the track: the course over ground atan2(dE, dN) of the position change over the last
``track_window`` seconds of fixes; it is only published as valid (``gps.cog_valid`` = 1) when the
vehicle moved more than ``min_track`` metres over that window, else the last value is held. Speed
over ground comes from the same difference. Outputs: ``gps.x``, ``gps.y`` (m, NED), ``gps.sog``
(m/s), ``gps.cog`` (rad), ``gps.cog_valid``, ``gps.valid`` (1: fix), ``gps.hdop``.

Two error models (``error_model``): ``"gauss-markov"`` (above, the default) and ``"white"``: the
fix is the true position plus independent N(0, sigma^2) noise per axis (the console's USV, 003
ch. 6.1: cm-level when still). Outage windows (``outages``, both models): no fix inside them
(``gps.valid`` = 0), the last fix is held and course/speed are not updated.
"""

from __future__ import annotations

import collections
import math
from typing import Literal

from pydantic import Field

from ..core.blocks import Block
from ..core.registry import register_block
from ..io.config import StrictModel


class GPSConfig(StrictModel):
    rate: float = Field(10.0, gt=0, le=100, description="fix rate, Hz")
    hdop: float = Field(0.9, gt=0, le=50, description="horizontal dilution of precision (003 fig 6-1: 0.9)")
    uere: float = Field(0.17, ge=0, le=50, description="user equivalent range error, m")
    bias_time_constant: float = Field(300.0, gt=0, le=1e5, description="correlation time of the position bias, s")
    jitter: float = Field(0.01, ge=0, le=10, description="white position jitter per axis, m")
    track_window: float = Field(1.0, gt=0, le=60, description="time span of the track used for course and speed, s")
    min_track: float = Field(0.2, ge=0, le=100, description="least distance moved for a valid course, m")
    error_model: Literal["gauss-markov", "white"] = Field(
        "gauss-markov", description="position error: Gauss-Markov bias + jitter, or white noise of std sigma"
    )
    sigma: float = Field(0.05, ge=0, le=50, description="white model: position noise standard deviation, m")
    outages: list[tuple[float, float]] = Field([], max_length=100, description="(start, end) windows without a fix, s")


@register_block("sensor.gps")
class GPS(Block):
    """GPS on body ``body`` (module docstring)."""

    role = "sensor"

    def __init__(self, cfg: GPSConfig, body: str = "usv", name: str = "gps"):
        self.cfg = cfg
        self.body = body
        self.name = name
        self.period = 1.0 / cfg.rate
        self.inputs = {f"{body}.x": "m", f"{body}.y": "m", f"{body}.psi": "rad"}
        self.outputs = {
            f"{name}.x": "m",
            f"{name}.y": "m",
            f"{name}.sog": "m/s",
            f"{name}.cog": "rad",
            f"{name}.cog_valid": "bool",
            f"{name}.valid": "bool",
            f"{name}.hdop": "1",
        }

    def reset(self, rng) -> None:
        c = self.cfg
        self.rng = rng
        s = c.hdop * c.uere / math.sqrt(2.0)
        self.sigma_b = s
        # the white model draws nothing here (its stream is the fixes' noise only)
        self.bias = [0.0, 0.0] if c.error_model == "white" else [s * rng.standard_normal(), s * rng.standard_normal()]
        n = max(2, int(round(c.track_window / self.period)) + 1)
        self.hist = collections.deque(maxlen=n)
        self.cog = None

    def _fix(self, bus: dict) -> tuple[float, float]:
        """One position fix (m) with the configured error model."""
        c = self.cfg
        xt, yt = bus[f"{self.body}.x"], bus[f"{self.body}.y"]
        if c.error_model == "white":
            n = self.rng.normal(0.0, c.sigma, 2) if c.sigma > 0 else (0.0, 0.0)
            return xt + float(n[0]), yt + float(n[1])
        a = math.exp(-self.period / c.bias_time_constant)
        q = self.sigma_b * math.sqrt(1.0 - a * a)
        w = self.rng.standard_normal(4)
        self.bias[0] = a * self.bias[0] + q * w[0]
        self.bias[1] = a * self.bias[1] + q * w[1]
        return xt + self.bias[0] + c.jitter * w[2], yt + self.bias[1] + c.jitter * w[3]

    def compiled(self):
        """Compiled form for the fused loop: Gauss-Markov errors without outages
        (:func:`oceangnc.sensors._compiled.gps_step`), else :func:`oceangnc.sensors._compiled_gps.gps_fix_step`."""
        c = self.cfg
        if self.cog is None:
            return None
        import numpy as np

        from ..core.fused import CompiledBlock
        from ._compiled import gps_step
        from ._compiled_gps import gps_fix_step

        n = self.hist.maxlen
        ring = np.zeros(3 * n)
        for j, row in enumerate(self.hist):
            ring[3 * j : 3 * j + 3] = row
        st = np.concatenate([[self.bias[0], self.bias[1], self.cog, len(self.hist), 0.0], ring])
        pa = np.array([self.period, c.bias_time_constant, self.sigma_b, c.jitter, c.min_track, c.hdop, n], float)
        b, o = self.body, self.name
        sig = [
            f"{b}.x",
            f"{b}.y",
            f"{o}.x",
            f"{o}.y",
            f"{o}.sog",
            f"{o}.cog",
            f"{o}.cog_valid",
            f"{o}.valid",
            f"{o}.hdop",
        ]
        if c.error_model == "white" or c.outages:  # white noise, outages: _compiled_gps.gps_fix_step
            win = [v for w in c.outages for v in w]
            extra = [1.0 if c.error_model == "white" else 0.0, c.sigma, len(c.outages), *win]
            return CompiledBlock(gps_fix_step, sig, st, np.concatenate([pa, extra]), rng=self.rng)
        return CompiledBlock(gps_step, sig, st, pa, rng=self.rng)

    def step(self, t: float, bus: dict) -> None:
        c = self.cfg
        n = self.name
        if c.outages and any(a <= t < b for a, b in c.outages):
            bus[f"{n}.valid"] = 0.0
            if f"{n}.x" not in bus:  # no fix yet: the first one is the truth, then held
                bus[f"{n}.x"], bus[f"{n}.y"] = bus[f"{self.body}.x"], bus[f"{self.body}.y"]
                bus[f"{n}.sog"], bus[f"{n}.cog"] = 0.0, bus[f"{self.body}.psi"]
                bus[f"{n}.cog_valid"], bus[f"{n}.hdop"] = 0.0, c.hdop
            return
        x, y = self._fix(bus)
        self.hist.append((t, x, y))
        t0, x0, y0 = self.hist[0]
        dn, de = x - x0, y - y0
        dist = math.hypot(dn, de)
        span = t - t0
        valid_cog = dist > c.min_track and span > 0
        if valid_cog:
            self.cog = math.atan2(de, dn)
        if self.cog is None:
            self.cog = bus[f"{self.body}.psi"]
        bus[f"{self.name}.x"] = x
        bus[f"{self.name}.y"] = y
        bus[f"{self.name}.sog"] = dist / span if span > 0 else 0.0
        bus[f"{self.name}.cog"] = self.cog
        bus[f"{self.name}.cog_valid"] = 1.0 if valid_cog else 0.0
        bus[f"{self.name}.valid"] = 1.0
        bus[f"{self.name}.hdop"] = c.hdop
