"""Sea-trial blocks for identification (000 sec. 2.2): the ITTC zig-zag manoeuvre and the trial sensors.

``trials`` (:mod:`oceangnc.scenarios.first_order`) runs straight, turning and zig-zag trials of a
model and logs what a crew would measure, for ``oceangnc identify first-order``.
"""

from __future__ import annotations

import math

from pydantic import Field

from ..core.blocks import Block
from ..core.registry import register_block
from ..core.rotations import wrap
from ..io.config import StrictModel


class TrialNoise(StrictModel):
    """Sensor noise on the logged measurements (white, Gaussian)."""

    speed_mps: float = Field(0.0, ge=0, le=5, description="speed noise std, m/s")
    heading_deg: float = Field(0.0, ge=0, le=30, description="heading noise std, deg")
    yaw_rate_degps: float = Field(0.0, ge=0, le=30, description="yaw-rate noise std, deg/s")


@register_block("usv.zigzag")
class ZigZag(Block):
    """ITTC zig-zag: steer +amp until the heading change reaches +psi_z, then -amp until -psi_z, and so on.

    Reads ``usv.psi`` (rad); writes ``key`` (the steering command, ``unit``: rad of rudder, or N of
    differential thrust) = 0 before ``t_step`` (s), then +-``amp * scale``. The heading change is
    measured from the heading at the first firing, wrapped to (-pi, pi].
    """

    role = "guidance"

    name = "zigzag"

    def __init__(self, amp, psi_z, t_step, period, key, scale=1.0, unit="rad"):
        self.amp, self.psi_z, self.t_step, self.period, self.key, self.scale = amp, psi_z, t_step, period, key, scale
        self.inputs = {"usv.psi": "rad"}
        self.outputs = {key: unit}
        self.sign = 1.0
        self.psi0 = None

    def reset(self, rng):
        self.sign = 1.0
        self.psi0 = None

    def step(self, t, bus):
        psi = bus["usv.psi"]
        if self.psi0 is None:
            self.psi0 = psi
        dpsi = wrap(psi - self.psi0)
        if t < self.t_step - 1e-9:
            bus[self.key] = 0.0
            return
        if self.sign > 0 and dpsi >= self.psi_z:
            self.sign = -1.0
        elif self.sign < 0 and dpsi <= -self.psi_z:
            self.sign = 1.0
        bus[self.key] = self.sign * self.amp * self.scale


@register_block("sensor.trial")
class TrialSensors(Block):
    """Measured trial signals with white noise: trial.speed, trial.heading (wrapped), trial.yaw_rate, inputs.

    ``steer_fn(bus)`` and ``thrust_fn(bus)`` give the logged inputs ``trial.steer`` / ``trial.thrust``
    (whatever the vehicle's inputs are: rudder and rpm, or differential and mean thrust); ``inputs``
    declares the signals they read.
    """

    role = "sensor"

    name = "trial_sensors"

    def __init__(self, noise: TrialNoise, period, steer_fn, thrust_fn, inputs=None):
        self.n = noise
        self.period = period
        self.steer_fn, self.thrust_fn = steer_fn, thrust_fn
        self.inputs = {"usv.u": "m/s", "usv.psi": "rad", "usv.r": "rad/s", **(inputs or {})}
        self.outputs = {
            "trial.speed": "m/s",
            "trial.heading": "rad",
            "trial.yaw_rate": "rad/s",
            "trial.steer": "1",
            "trial.thrust": "1",
        }

    def reset(self, rng):
        self.rng = rng

    def step(self, t, bus):
        g = self.rng
        n = self.n
        bus["trial.speed"] = bus["usv.u"] + (g.normal(0, n.speed_mps) if n.speed_mps else 0.0)
        psi = bus["usv.psi"] + (g.normal(0, math.radians(n.heading_deg)) if n.heading_deg else 0.0)
        bus["trial.heading"] = wrap(psi)
        bus["trial.yaw_rate"] = bus["usv.r"] + (
            g.normal(0, math.radians(n.yaw_rate_degps)) if n.yaw_rate_degps else 0.0
        )
        bus["trial.steer"] = self.steer_fn(bus)
        bus["trial.thrust"] = self.thrust_fn(bus)
