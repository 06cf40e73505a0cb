"""Pressure depth sensor with voltage output (003 ch. 6.1.3, appendix B table C-4: Sensys PSC).

The sensor maps 0-10 bar (gauge) to 0-5 V: V = V_0 + k (rho g z) with the nominal k = 5 V / 1e6 Pa
(0.05 V per metre of sea water). The unit's own offset and gain errors (drawn once per sensor,
within the table's +-0.25 % FS accuracy: 12.5 mV) make the nominal curve inexact, so, as in 003, the
depth is recovered by a *first-order calibration* z = c_1 V + c_0 fitted by least squares to
averaged readings at known depths (003 used 0.66-2.46 m; its eq. 6.1 is missing from the text,
so :func:`calibrate` reproduces the procedure instead of a printed line). Each reading adds white
noise (003 fig. 6-10: "a lot of oscillations"; sigma 5 mV = 0.1 m, our choice) and the 12-bit
ADC's quantisation of 0-5 V; the calibrated depth is then low-passed (first order, 0.5 Hz cut-off).

Outputs ``depth.volt`` (V), ``depth.z_raw`` (m, calibrated, unfiltered), ``depth.z`` (m, filtered).
"""

from __future__ import annotations

import numpy as np
from numba import njit
from pydantic import Field

from ..core.law import In, LawBlock, Layout, Out, Signals
from ..core.registry import register_block
from ..io.config import StrictModel
from ..units import RHO_WATER, G
from .filters import lowpass_coefficient, lowpass_step

FULL_SCALE_PA = 10e5  #: 10 bar
FULL_SCALE_V = 5.0
ADC_LSB = FULL_SCALE_V / 4096  #: 12-bit ADC, V


class DepthSensorConfig(StrictModel):
    rate: float = Field(20.0, gt=0, le=1000, description="sample rate, Hz")
    noise_v: float = Field(0.005, ge=0, le=1, description="white voltage noise, V")
    accuracy_fs: float = Field(0.0025, ge=0, le=0.1, description="offset/gain error bound, fraction of full scale")
    cutoff_hz: float = Field(0.5, gt=0, le=100, description="low-pass cut-off frequency, Hz")
    calibration_depths: list[float] = Field(
        [0.66, 1.06, 1.46, 1.86, 2.26, 2.46],
        min_length=2,
        description="depths of the calibration points (003: 0.66-2.46), m",
    )
    calibration_samples: int = Field(200, ge=1, le=100000, description="readings averaged per calibration point")


@njit(cache=True)
def ideal_voltage(z):
    """Nominal output (V) at depth z (m): 0-10 bar gauge -> 0-5 V."""
    return FULL_SCALE_V * RHO_WATER * G * max(z, 0.0) / FULL_SCALE_PA


@njit(cache=True)
def voltage(z, offset, gain, noise):
    """One reading (V) at true depth z (m): offset, gain, additive noise (V), 0-5 V clip, 12-bit
    quantisation (round half to even, as Python's ``round``)."""
    v = offset + gain * ideal_voltage(z) + noise
    v = min(FULL_SCALE_V, max(0.0, v))
    return np.rint(v / ADC_LSB) * ADC_LSB


SIGNALS = Signals(z=In("m"), volt=Out("V"), z_raw=Out("m"), z_out=Out("m"))
PARAMS = Layout("offset", "gain", "noise_v", "c1", "c0", "a")
STATE = Layout("y", "has_y")
S, P, X = SIGNALS.at, PARAMS.at, STATE.at


@njit(cache=True)
def depth_law(t, sig, sl, st, pa, rng):
    """One sample (003 ch. 6.1.3): a reading (V) of the true depth ``z`` (m) with the unit's offset,
    gain and white noise (:func:`voltage`), the first-order calibration z = c1 V + c0, and the
    first-order low-pass of the calibrated depth (the first sample initialises it)."""
    v = voltage(sig[sl[S.z]], pa[P.offset], pa[P.gain], pa[P.noise_v] * rng.standard_normal())
    z = pa[P.c1] * v + pa[P.c0]
    if st[X.has_y] == 0.0:
        st[X.y] = z
        st[X.has_y] = 1.0
    else:
        st[X.y] = lowpass_step(st[X.y], pa[P.a], z)
    sig[sl[S.volt]] = v
    sig[sl[S.z_raw]] = z
    sig[sl[S.z_out]] = st[X.y]


@register_block("sensor.depth")
class DepthSensor(LawBlock):
    """Depth sensor on body ``body`` (module docstring): reads ``<body>.z`` (m), writes ``depth.volt``
    (V), ``depth.z_raw`` and ``depth.z`` (m); law :func:`depth_law`."""

    role = "sensor"
    name = "depth"
    law = staticmethod(depth_law)
    signals = SIGNALS
    draws = True

    def __init__(self, cfg: DepthSensorConfig, body: str = "uuv"):
        self.cfg = cfg
        self.body = body
        self.period = 1.0 / cfg.rate
        self.bind(z=f"{body}.z", volt="depth.volt", z_raw="depth.z_raw", z_out="depth.z")
        self.st = STATE.pack(y=0.0, has_y=0.0)
        self.pa = PARAMS.pack(offset=0.0, gain=1.0, noise_v=cfg.noise_v, c1=1.0, c0=0.0, a=1.0)

    def reset(self, rng) -> None:
        """Draw the unit's offset and gain errors, calibrate it (003 ch. 6.1.3), clear the filter."""
        c = self.cfg
        self.rng = rng
        e = c.accuracy_fs * FULL_SCALE_V
        self.pa[P.offset] = rng.uniform(-e, e)
        self.pa[P.gain] = 1.0 + rng.uniform(-c.accuracy_fs, c.accuracy_fs)
        self.pa[P.c1], self.pa[P.c0] = calibrate(self, c.calibration_depths, c.calibration_samples)
        self.pa[P.a] = lowpass_coefficient(c.cutoff_hz, self.period)
        self.st[:] = 0.0

    def read_voltage(self, z: float) -> float:
        """One reading (V) at true depth z (m): offset, gain, noise, 12-bit quantisation, 0-5 V clip."""
        pa = self.pa
        return float(voltage(z, pa[P.offset], pa[P.gain], pa[P.noise_v] * self.rng.standard_normal()))


def calibrate(sensor: DepthSensor, depths, samples: int = 200):
    """First-order calibration z = c1 V + c0 (003 ch. 6.1.3): least squares on averaged readings.

    Returns (c1, c0) in m/V and m.
    """
    d = np.asarray(depths, float)
    v = np.array([np.mean([sensor.read_voltage(z) for _ in range(samples)]) for z in d])
    c1, c0 = np.polyfit(v, d, 1)
    return float(c1), float(c0)
