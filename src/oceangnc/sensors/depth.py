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

from ..core.blocks import Block
from ..core.registry import register_block
from ..io.config import StrictModel
from ..units import RHO_WATER, G
from .filters import LowPass

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


@register_block("sensor.depth")
class DepthSensor(Block):
    """Depth sensor on body ``body`` (module docstring)."""

    role = "sensor"

    name = "depth"

    def __init__(self, cfg: DepthSensorConfig, body: str = "uuv"):
        self.cfg = cfg
        self.body = body
        self.period = 1.0 / cfg.rate
        self.inputs = {f"{body}.z": "m"}
        self.outputs = {"depth.volt": "V", "depth.z_raw": "m", "depth.z": "m"}

    def reset(self, rng) -> None:
        c = self.cfg
        self.rng = rng
        e = c.accuracy_fs * FULL_SCALE_V
        self.offset = rng.uniform(-e, e)
        self.gain = 1.0 + rng.uniform(-c.accuracy_fs, c.accuracy_fs)
        self.c1, self.c0 = calibrate(self, c.calibration_depths, c.calibration_samples)
        self.lp = LowPass(c.cutoff_hz, self.period)

    def read_voltage(self, z: float) -> float:
        """One reading (V) at true depth z (m): offset, gain, noise, 12-bit quantisation, 0-5 V clip."""
        return float(voltage(z, self.offset, self.gain, self.cfg.noise_v * self.rng.standard_normal()))

    def compiled(self):
        """Compiled form for the fused loop (:func:`oceangnc.sensors._compiled.depth_step`)."""
        from ..core.fused import CompiledBlock
        from ._compiled import depth_step

        c = self.cfg
        y = self.lp.y
        pa = np.array(
            [
                self.offset,
                self.gain,
                c.noise_v,
                self.c1,
                self.c0,
                self.lp.a,
                FULL_SCALE_V,
                ADC_LSB,
                RHO_WATER,
                G,
                FULL_SCALE_PA,
            ]
        )
        st = np.array([y if y is not None else 0.0, 0.0 if y is None else 1.0])
        return CompiledBlock(
            depth_step, [f"{self.body}.z", "depth.volt", "depth.z_raw", "depth.z"], st, pa, rng=self.rng
        )

    def step(self, t: float, bus: dict) -> None:
        v = self.read_voltage(bus[f"{self.body}.z"])
        z = self.c1 * v + self.c0
        bus["depth.volt"] = v
        bus["depth.z_raw"] = z
        bus["depth.z"] = self.lp(z)


def calibrate(sensor: DepthSensor, depths, samples: int = 200):
    """First-order calibration z = c1 V + c0 (003 ch. 6.1.3): least squares on averaged readings.

    Returns (c1, c0) in m/V and m.
    """
    d = np.asarray(depths, float)
    v = np.array([np.mean([sensor.read_voltage(z) for _ in range(samples)]) for z in d])
    c1, c0 = np.polyfit(v, d, 1)
    return float(c1), float(c0)
