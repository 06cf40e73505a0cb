"""AHRS (003 ch. 6.1.1, appendix B table C-2: Xsens MTi-30).

Heading: the true heading through a first-order lag (the magnetic-field compensation filter that
makes the AHRS "follow slowly", 003 ch. 6.1.1), plus a slowly varying magnetic disturbance and white
noise:

    psi_f' = (psi - psi_f) / tau                         (lag, exact discretisation at the AHRS rate)
    m_{k+1} = exp(-h/T_m) m_k + sigma_m sqrt(1 - exp(-2h/T_m)) w_k   (magnetic disturbance)
    psi_ahrs = psi_f + m + sigma_psi v_k

While turning at yaw rate r the lag alone leaves an error of about tau r, so the AHRS heading differs
from the GPS heading while moving and agrees with it when still (003 fig. 6-2: mean difference
3.53 deg, sd 3.88 deg, max 15 deg while moving). tau = 1 s, sigma_m = 2 deg (T_m = 30 s) and
sigma_psi = 1 deg (the table's yaw accuracy) are our choice, checked against those statistics in
tests/test_sensors.py. Roll and pitch (if the body publishes them) get white noise of 0.5 deg (the
table's 0.5-2 deg dynamic accuracy, lower end). The yaw rate is the gyro: true r plus the 0.2 deg/s
initial bias of table C-2 (a constant drawn once) and white noise.

Outputs ``<name>.psi``, ``<name>.r`` (rad, rad/s), ``<name>.phi``, ``<name>.theta`` (rad).
"""

from __future__ import annotations

import math

from pydantic import Field

from ..core.blocks import Block
from ..core.registry import register_block
from ..core.rotations import wrap
from ..io.config import StrictModel
from .filters import angle_lowpass_step, gauss_markov


class AHRSConfig(StrictModel):
    rate: float = Field(20.0, gt=0, le=400, description="output rate, Hz")
    lag: float = Field(1.0, ge=0, le=60, description="heading lag time constant tau, s")
    yaw_noise_deg: float = Field(1.0, ge=0, le=30, description="white heading noise, deg")
    mag_sigma_deg: float = Field(2.0, ge=0, le=45, description="magnetic disturbance standard deviation, deg")
    mag_time_constant: float = Field(30.0, gt=0, le=1e5, description="magnetic disturbance correlation time, s")
    attitude_noise_deg: float = Field(0.5, ge=0, le=30, description="roll/pitch white noise, deg")
    gyro_bias_degps: float = Field(0.2, ge=0, le=10, description="gyro bias scale (table C-2), deg/s")
    gyro_noise_degps: float = Field(0.1, ge=0, le=10, description="gyro white noise, deg/s")


@register_block("sensor.ahrs")
class AHRS(Block):
    """AHRS on body ``body`` (module docstring)."""

    role = "sensor"

    def __init__(self, cfg: AHRSConfig, body: str = "usv", name: str | None = None):
        self.cfg = cfg
        self.body = body
        self.name = name or f"{body}_ahrs"
        self.period = 1.0 / cfg.rate
        self.inputs = {f"{body}.psi": "rad", f"{body}.r": "rad/s"}
        # a surface vessel has no roll/pitch states: level (0) when nobody publishes them
        self.optional_inputs = {f"{body}.phi": "rad", f"{body}.theta": "rad"}
        self.outputs = {
            f"{self.name}.psi": "rad",
            f"{self.name}.r": "rad/s",
            f"{self.name}.phi": "rad",
            f"{self.name}.theta": "rad",
        }

    def reset(self, rng) -> None:
        self.rng = rng
        c = self.cfg
        self.psi_f = None
        self.mag = math.radians(c.mag_sigma_deg) * rng.standard_normal()
        self.gyro_bias = math.radians(c.gyro_bias_degps) * rng.uniform(-1.0, 1.0)

    def compiled(self):
        """Compiled form for the fused loop (:func:`oceangnc.sensors._compiled.ahrs_step`)."""
        if self.psi_f is None:
            return None
        import numpy as np

        from ..core.fused import CompiledBlock
        from ._compiled import ahrs_step

        c, b, o = self.cfg, self.body, self.name
        pa = np.array(
            [
                self.period,
                c.lag,
                c.mag_time_constant,
                math.radians(c.mag_sigma_deg),
                math.radians(c.yaw_noise_deg),
                self.gyro_bias,
                math.radians(c.gyro_noise_degps),
                math.radians(c.attitude_noise_deg),
            ]
        )
        sig = [f"{b}.psi", f"{b}.r", f"?{b}.phi", f"?{b}.theta", f"{o}.psi", f"{o}.r", f"{o}.phi", f"{o}.theta"]
        return CompiledBlock(ahrs_step, sig, np.array([self.psi_f, self.mag]), pa, rng=self.rng)

    def step(self, t: float, bus: dict) -> None:
        c = self.cfg
        b = self.body
        psi = bus[f"{b}.psi"]
        if self.psi_f is None:
            self.psi_f = psi
        elif c.lag > 0:
            a = 1.0 - math.exp(-self.period / c.lag)
            self.psi_f = float(angle_lowpass_step(self.psi_f, a, psi))
        else:
            self.psi_f = psi
        am = math.exp(-self.period / c.mag_time_constant)
        w = self.rng.standard_normal(5)
        self.mag = float(gauss_markov(self.mag, am, math.radians(c.mag_sigma_deg), w[0]))
        bus[f"{self.name}.psi"] = wrap(self.psi_f + self.mag + math.radians(c.yaw_noise_deg) * w[1])
        bus[f"{self.name}.r"] = bus[f"{b}.r"] + self.gyro_bias + math.radians(c.gyro_noise_degps) * w[2]
        sa = math.radians(c.attitude_noise_deg)
        bus[f"{self.name}.phi"] = bus.get(f"{b}.phi", 0.0) + sa * w[3]
        bus[f"{self.name}.theta"] = bus.get(f"{b}.theta", 0.0) + sa * w[4]
