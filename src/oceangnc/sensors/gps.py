"""GPS receiver (003 ch. 6.1.1, appendix B table C-1: Hemisphere Vector H200).

Position error = a slowly varying bias + white jitter, both per horizontal axis:

    b_{k+1} = exp(-h/T) b_k + sigma_b sqrt(1 - exp(-2h/T)) w_k,   sigma_b = HDOP * UERE / sqrt(2)
    x_gps = x + b + sigma_j v_k

HDOP times the user equivalent range error (UERE) is the horizontal RMS error (the usual DOP
definition); UERE = 0.17 m makes the 2DRMS (about 95 %) error 2 * 0.9 * 0.17 = 0.3 m at the measured
mean HDOP 0.9 (003 fig. 6-1), the SBAS/DGPS horizontal accuracy of table C-1. The bias is
Gauss-Markov with a 300 s correlation time (our choice; satellite-geometry and atmospheric errors change over minutes), and the jitter sigma_j = 0.01 m, so a
standing receiver wanders by centimetres over seconds, as 003 fig. 6-3 shows ("very accurate in cm").

Heading from the track: the course over ground atan2(dE, dN) of the position change over the last
``track_window`` seconds of fixes; it is only published as valid (``gps.cog_valid`` = 1) when the
vehicle moved more than ``min_track`` metres over that window, else the last value is held. Speed
over ground comes from the same difference. Outputs: ``gps.x``, ``gps.y`` (m, NED), ``gps.sog``
(m/s), ``gps.cog`` (rad), ``gps.cog_valid``, ``gps.valid`` (1: fix), ``gps.hdop``.
"""

from __future__ import annotations

import collections
import math

from pydantic import Field

from ..core.blocks import Block
from ..io.config import StrictModel


class GPSConfig(StrictModel):
    rate: float = Field(10.0, gt=0, le=100, description="fix rate, Hz")
    hdop: float = Field(0.9, gt=0, le=50, description="horizontal dilution of precision (003 fig 6-1: 0.9)")
    uere: float = Field(0.17, ge=0, le=50, description="user equivalent range error, m")
    bias_time_constant: float = Field(300.0, gt=0, le=1e5, description="correlation time of the position bias, s")
    jitter: float = Field(0.01, ge=0, le=10, description="white position jitter per axis, m")
    track_window: float = Field(1.0, gt=0, le=60, description="time span of the track used for course and speed, s")
    min_track: float = Field(0.2, ge=0, le=100, description="least distance moved for a valid course, m")


class GPS(Block):
    """GPS on body ``body`` (module docstring)."""

    def __init__(self, cfg: GPSConfig, body: str = "usv", name: str = "gps"):
        self.cfg = cfg
        self.body = body
        self.name = name
        self.period = 1.0 / cfg.rate

    def reset(self, rng) -> None:
        c = self.cfg
        self.rng = rng
        s = c.hdop * c.uere / math.sqrt(2.0)
        self.sigma_b = s
        self.bias = [s * rng.standard_normal(), s * rng.standard_normal()]
        n = max(2, int(round(c.track_window / self.period)) + 1)
        self.hist = collections.deque(maxlen=n)
        self.cog = None

    def compiled(self):
        """Compiled form for the fused loop (:func:`oceangnc.sensors._compiled.gps_step`)."""
        if self.cog is None:
            return None
        import numpy as np

        from ..core.fused import CompiledBlock
        from ._compiled import gps_step

        c = self.cfg
        n = self.hist.maxlen
        ring = np.zeros(3 * n)
        for j, row in enumerate(self.hist):
            ring[3 * j:3 * j + 3] = row
        st = np.concatenate([[self.bias[0], self.bias[1], self.cog, len(self.hist), 0.0], ring])
        pa = np.array([self.period, c.bias_time_constant, self.sigma_b, c.jitter, c.min_track, c.hdop, n], float)
        b, o = self.body, self.name
        sig = [f"{b}.x", f"{b}.y", f"{o}.x", f"{o}.y", f"{o}.sog", f"{o}.cog", f"{o}.cog_valid", f"{o}.valid",
               f"{o}.hdop"]
        return CompiledBlock(gps_step, sig, st, pa, rng=self.rng)

    def step(self, t: float, bus: dict) -> None:
        c = self.cfg
        a = math.exp(-self.period / c.bias_time_constant)
        q = self.sigma_b * math.sqrt(1.0 - a * a)
        w = self.rng.standard_normal(4)
        self.bias[0] = a * self.bias[0] + q * w[0]
        self.bias[1] = a * self.bias[1] + q * w[1]
        x = bus.get(f"{self.body}.x", 0.0) + self.bias[0] + c.jitter * w[2]
        y = bus.get(f"{self.body}.y", 0.0) + self.bias[1] + c.jitter * w[3]
        self.hist.append((t, x, y))
        t0, x0, y0 = self.hist[0]
        dn, de = x - x0, y - y0
        dist = math.hypot(dn, de)
        span = t - t0
        valid_cog = dist > c.min_track and span > 0
        if valid_cog:
            self.cog = math.atan2(de, dn)
        if self.cog is None:
            self.cog = bus.get(f"{self.body}.psi", 0.0)
        bus[f"{self.name}.x"] = x
        bus[f"{self.name}.y"] = y
        bus[f"{self.name}.sog"] = dist / span if span > 0 else 0.0
        bus[f"{self.name}.cog"] = self.cog
        bus[f"{self.name}.cog_valid"] = 1.0 if valid_cog else 0.0
        bus[f"{self.name}.valid"] = 1.0
        bus[f"{self.name}.hdop"] = c.hdop
