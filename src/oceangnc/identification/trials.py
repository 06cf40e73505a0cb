"""Sea-trial blocks for identification (000 sec. 2.2): the ITTC zig-zag manoeuvre and the trial sensors.

``trials`` (:mod:`oceangnc.scenarios.first_order`) runs straight, turning and zig-zag trials of a
model and logs what a crew would measure, for ``oceangnc identify first-order``.
"""

from __future__ import annotations

import math

import numpy as np
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
        from ._compiled_trials import zigzag_law

        st = np.array([self.sign, 0.0 if self.psi0 is None else self.psi0, 0.0 if self.psi0 is None else 1.0])
        s = zigzag_law(float(t), float(bus["usv.psi"]), st, float(self.t_step), float(self.psi_z))
        self.sign, self.psi0 = float(st[0]), float(st[1])
        bus[self.key] = 0.0 if s == 0.0 else s * self.amp * self.scale

    def compiled(self):
        """Compiled form: :func:`oceangnc.identification._compiled_trials.zigzag_step`."""
        from ..core.fused import CompiledBlock
        from ._compiled_trials import zigzag_step

        st = np.array([self.sign, 0.0 if self.psi0 is None else self.psi0, 0.0 if self.psi0 is None else 1.0])
        pa = np.array([self.amp, self.psi_z, self.t_step, self.scale], dtype=np.float64)
        return CompiledBlock(zigzag_step, ["usv.psi", self.key], st, pa)


@register_block("sensor.trial")
class TrialSensors(Block):
    """Measured trial signals with white noise: trial.speed, trial.heading (wrapped), trial.yaw_rate, inputs.

    ``steer`` and ``thrust`` say which signals are logged as the inputs ``trial.steer`` / ``trial.thrust``
    (whatever the vehicle's inputs are: rudder and rpm, or differential and mean thrust): a signal
    name, or ``(a, b, sign, scale)`` for ``scale * (a + sign * b)``; ``units`` gives the units of the
    signals they read.
    """

    role = "sensor"

    name = "trial_sensors"

    def __init__(self, noise: TrialNoise, period, steer, thrust, units=None):
        self.n = noise
        self.period = period
        self.steer, self.thrust = _spec(steer), _spec(thrust)
        self.inputs = {"usv.u": "m/s", "usv.psi": "rad", "usv.r": "rad/s", **(units or {})}
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
        bus["trial.steer"] = _value(bus, self.steer)
        bus["trial.thrust"] = _value(bus, self.thrust)

    def compiled(self):
        """Compiled form: :func:`oceangnc.identification._compiled_trials.trial_sensors_step`."""
        from ..core.fused import CompiledBlock
        from ._compiled_trials import trial_sensors_step

        n = self.n
        (sa, sb, ss, sc), (ta, tb, ts, tc) = self.steer, self.thrust
        sigs = ["usv.u", "usv.psi", "usv.r", sa, sb or "?", ta, tb or "?"]
        sigs += ["trial.speed", "trial.heading", "trial.yaw_rate", "trial.steer", "trial.thrust"]
        sd = [n.speed_mps, math.radians(n.heading_deg), math.radians(n.yaw_rate_degps)]
        pa = np.array([*sd, ss, sc, ts, tc], dtype=np.float64)
        return CompiledBlock(trial_sensors_step, sigs, params=pa, rng=self.rng)


def _spec(s) -> tuple:
    """A logged input: a signal name, or (a, b, sign, scale) for scale * (a + sign * b)."""
    if isinstance(s, str):
        return (s, None, 1.0, 1.0)
    a, b, sign, scale = s
    return (a, b, float(sign), float(scale))


def _value(bus, spec) -> float:
    a, b, sign, scale = spec
    return bus[a] if b is None else scale * (bus[a] + sign * bus[b])
