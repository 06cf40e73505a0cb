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
(``gps.valid`` = 0), the last fix is held and course/speed are not updated (an outage before the
first fix publishes the true position as that first fix). Law: :func:`gps_law`.
"""

from __future__ import annotations

import math
from typing import Literal

import numpy as np
from numba import njit
from pydantic import Field

from ..core.law import In, LawBlock, Layout, Out, Signals
from ..core.registry import register_block
from ..io.config import StrictModel
from .filters import gauss_markov, ring_slot


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


SIGNALS = Signals(
    x=In("m"),
    y=In("m"),
    psi=In("rad"),
    x_out=Out("m"),
    y_out=Out("m"),
    sog=Out("m/s"),
    cog=Out("rad"),
    cog_valid=Out("bool"),
    valid=Out("bool"),
    hdop=Out("1"),
)
#: period and bias time constant (s), bias sigma_b, jitter and min_track (m), HDOP, track entries n,
#: white model (1/0) and its sigma (m), m outage windows; then the m windows (start, end), s
PARAMS = Layout(
    "period", "bias_time_constant", "sigma_b", "jitter", "min_track", "hdop", "n", "white", "sigma", "m"
)  # fmt: skip
#: bias (m, N and E), course (rad) and whether one is set, whether anything was published, the track
#: ring's count and head; then the ring of n fixes (t, x, y)
STATE = Layout("bias_n", "bias_e", "cog", "has_cog", "published", "count", "head")
S, P, X = SIGNALS.at, PARAMS.at, STATE.at
_WIN, _RING = PARAMS.size, STATE.size


@njit(cache=True)
def gps_fix(sig, sl, st, pa, rng):
    """One position fix (m, NED) with the configured error model: white, two normal draws (none when
    sigma = 0); or the Gauss-Markov bias and white jitter, four draws (bias N, E, jitter N, E)."""
    if pa[P.white] != 0.0:
        s = pa[P.sigma]
        nx = rng.normal(0.0, s) if s > 0 else 0.0
        ny = rng.normal(0.0, s) if s > 0 else 0.0
        return sig[sl[S.x]] + nx, sig[sl[S.y]] + ny
    a = math.exp(-pa[P.period] / pa[P.bias_time_constant])
    w0 = rng.standard_normal()
    w1 = rng.standard_normal()
    w2 = rng.standard_normal()
    w3 = rng.standard_normal()
    st[X.bias_n] = gauss_markov(st[X.bias_n], a, pa[P.sigma_b], w0)
    st[X.bias_e] = gauss_markov(st[X.bias_e], a, pa[P.sigma_b], w1)
    return sig[sl[S.x]] + st[X.bias_n] + pa[P.jitter] * w2, sig[sl[S.y]] + st[X.bias_e] + pa[P.jitter] * w3


@njit(cache=True)
def gps_law(t, sig, sl, st, pa, rng):
    """One GPS sample (module docstring): nothing but ``valid`` = 0 inside an outage (the truth as the
    first fix if none was published yet); else a fix (:func:`gps_fix`) into the track ring, the
    course over ground (valid past min_track; the body's heading until a first course) and the speed
    over ground from the ring's oldest entry."""
    for i in range(int(pa[P.m])):
        if pa[_WIN + 2 * i] <= t < pa[_WIN + 2 * i + 1]:
            sig[sl[S.valid]] = 0.0
            if st[X.published] == 0.0:  # no fix yet: the first one is the truth, then held
                sig[sl[S.x_out]] = sig[sl[S.x]]
                sig[sl[S.y_out]] = sig[sl[S.y]]
                sig[sl[S.sog]] = 0.0
                sig[sl[S.cog]] = sig[sl[S.psi]]
                sig[sl[S.cog_valid]] = 0.0
                sig[sl[S.hdop]] = pa[P.hdop]
                st[X.published] = 1.0
            return
    x, y = gps_fix(sig, sl, st, pa, rng)
    j, count, head = ring_slot(int(st[X.count]), int(st[X.head]), int(pa[P.n]))
    st[_RING + 3 * j] = t
    st[_RING + 3 * j + 1] = x
    st[_RING + 3 * j + 2] = y
    st[X.count] = count
    st[X.head] = head
    t0 = st[_RING + 3 * head]
    dn, de = x - st[_RING + 3 * head + 1], y - st[_RING + 3 * head + 2]
    dist = math.hypot(dn, de)
    span = t - t0
    valid_cog = dist > pa[P.min_track] and span > 0
    if valid_cog:
        st[X.cog] = math.atan2(de, dn)
        st[X.has_cog] = 1.0
    if st[X.has_cog] == 0.0:
        st[X.cog] = sig[sl[S.psi]]
        st[X.has_cog] = 1.0
    st[X.published] = 1.0
    sig[sl[S.x_out]] = x
    sig[sl[S.y_out]] = y
    sig[sl[S.sog]] = dist / span if span > 0 else 0.0
    sig[sl[S.cog]] = st[X.cog]
    sig[sl[S.cog_valid]] = 1.0 if valid_cog else 0.0
    sig[sl[S.valid]] = 1.0
    sig[sl[S.hdop]] = pa[P.hdop]


@register_block("sensor.gps")
class GPS(LawBlock):
    """GPS on body ``body`` (module docstring); law :func:`gps_law`."""

    role = "sensor"
    law = staticmethod(gps_law)
    signals = SIGNALS
    draws = True

    def __init__(self, cfg: GPSConfig, body: str = "usv", name: str = "gps"):
        self.cfg = cfg
        self.body = body
        self.name = name
        self.period = 1.0 / cfg.rate
        self.bind(x=f"{body}.x", y=f"{body}.y", psi=f"{body}.psi", x_out=f"{name}.x", y_out=f"{name}.y",
                  sog=f"{name}.sog", cog=f"{name}.cog", cog_valid=f"{name}.cog_valid", valid=f"{name}.valid",
                  hdop=f"{name}.hdop")  # fmt: skip
        n = max(2, int(round(cfg.track_window / self.period)) + 1)  # fixes in the track window
        head = PARAMS.pack(
            period=self.period,
            bias_time_constant=cfg.bias_time_constant,
            sigma_b=cfg.hdop * cfg.uere / math.sqrt(2.0),
            jitter=cfg.jitter,
            min_track=cfg.min_track,
            hdop=cfg.hdop,
            n=n,
            white=1.0 if cfg.error_model == "white" else 0.0,
            sigma=cfg.sigma,
            m=len(cfg.outages),
        )
        self.pa = np.concatenate([head, np.asarray(cfg.outages, float).reshape(-1)])
        self.st = np.zeros(STATE.size + 3 * n)

    @property
    def sigma_b(self) -> float:
        """Standard deviation of the position bias per axis, m."""
        return float(self.pa[P.sigma_b])

    def reset(self, rng) -> None:
        """Clear the track and the course; draw the bias's initial value (Gauss-Markov model)."""
        self.rng = rng
        self.st[:] = 0.0
        if self.cfg.error_model != "white":  # the white model draws nothing here (its stream is the fixes' noise)
            s = self.sigma_b
            self.st[X.bias_n] = s * rng.standard_normal()
            self.st[X.bias_e] = s * rng.standard_normal()
