"""Joystick input of document 001 sec. 3.1: two stick axes -> commanded surge speed and yaw rate.

The stick position (each axis in [-1, 1]; surge forward positive, yaw to starboard positive) is
read ``samples`` times per ``period`` (001: 100 samples every 100 ms) and smoothed with the recursive
mean of 001 eq. 26,

    x_k = x_{k-1} + (z_k - x_{k-1}) / k,    k = 1..N,

which equals the arithmetic mean of the N samples (:func:`recursive_mean`). The samples carry the
stick's electrical noise (``noise`` standard deviation, stick units), drawn from the block's own
generator. The filtered axis goes through a dead band and a linear scaling:

    s' = sgn(s) (|s| - d) / (1 - d) for |s| > d, else 0,
    u_d = u_max s' (s' >= 0) or u_astern s' (s' < 0),    r_d = r_max s'.

Bus: reads ``joystick.surge``, ``joystick.yaw`` (raw stick); writes ``joystick.surge_f``,
``joystick.yaw_f`` (filtered stick), ``joystick.surge_db``, ``joystick.yaw_db`` (after the dead
band, used by the open loop), ``cmd.u_d`` (m/s), ``cmd.r_d`` (rad/s).
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit
from pydantic import Field

from ..core.blocks import Block
from ..core.registry import register_block
from ..io.config import StrictModel


class JoystickConfig(StrictModel):
    """Joystick scaling and filtering."""

    dead_band: float = Field(0.05, ge=0.0, lt=0.5, description="dead band of each axis, stick units (0-1)")
    u_max_kn: float = Field(3.34, gt=0, le=20, description="surge speed at full forward stick (001: max 3.34 kn), kn")
    u_astern_kn: float = Field(1.5, ge=0, le=10, description="astern speed at full backward stick, kn")
    r_max_degps: float = Field(0.4, gt=0, le=10, description="yaw rate at full sideways stick, deg/s")
    samples: int = Field(100, ge=1, le=10000, description="raw samples averaged per period (001: 100)")
    period: float = Field(0.1, gt=0, le=5, description="filter output period (001: 100 ms), s")
    noise: float = Field(0.01, ge=0, le=0.5, description="stick read-out noise standard deviation, stick units")


@njit(cache=True)
def recursive_mean(z):
    """Recursive mean x_k = x_{k-1} + (z_k - x_{k-1})/k over the samples z (001 eq. 26)."""
    x = 0.0
    for k in range(z.size):
        x += (z[k] - x) / (k + 1.0)
    return x


def dead_band(s: float, d: float) -> float:
    """Stick value with a dead band ``d`` removed and rescaled to [-1, 1]."""
    s = max(-1.0, min(1.0, float(s)))
    a = abs(s)
    if a <= d:
        return 0.0
    return math.copysign((a - d) / (1.0 - d), s)


def stick_to_command(surge: float, yaw: float, cfg: JoystickConfig) -> tuple[float, float]:
    """(u_d m/s, r_d rad/s) from the two filtered axes (dead band and scaling)."""
    from ..units import KNOT

    su = dead_band(surge, cfg.dead_band)
    sy = dead_band(yaw, cfg.dead_band)
    u_d = su * (cfg.u_max_kn if su >= 0 else cfg.u_astern_kn) * KNOT
    return u_d, sy * math.radians(cfg.r_max_degps)


@register_block("ship.joystick")
class Joystick(Block):
    """Filter and scale the two stick axes (001 sec. 3.1, eq. 26); see the module docstring."""

    role = "controller"

    name = "joystick"

    def __init__(self, cfg: JoystickConfig):
        self.cfg = cfg
        self.period = float(cfg.period)
        self._z = np.zeros(cfg.samples)
        self.inputs = {}
        self.optional_inputs = {"joystick.surge": "1", "joystick.yaw": "1"}  # centred stick when absent
        self.outputs = {
            "joystick.surge_f": "1",
            "joystick.yaw_f": "1",
            "joystick.surge_db": "1",
            "joystick.yaw_db": "1",
            "cmd.u_d": "m/s",
            "cmd.r_d": "rad/s",
        }

    def reset(self, rng: np.random.Generator) -> None:
        self.rng = rng

    def _read(self, value: float) -> float:
        n = self.cfg.samples
        if self.cfg.noise > 0.0:
            self._z[:] = value + self.cfg.noise * self.rng.standard_normal(n)
        else:
            self._z[:] = value
        return float(recursive_mean(self._z))

    def compiled(self):
        """Compiled form for the fused loop (:func:`oceangnc.control._compiled_berthing.joystick_step`)."""
        from ..core.fused import CompiledBlock
        from ..units import KNOT
        from ._compiled_berthing import joystick_step

        c = self.cfg
        pa = np.array([c.samples, c.noise, c.dead_band, c.u_max_kn, c.u_astern_kn, KNOT, math.radians(c.r_max_degps)])
        sig = [
            "?joystick.surge",
            "?joystick.yaw",
            "joystick.surge_f",
            "joystick.yaw_f",
            "joystick.surge_db",
            "joystick.yaw_db",
            "cmd.u_d",
            "cmd.r_d",
        ]
        return CompiledBlock(joystick_step, sig, params=pa, rng=self.rng)

    def step(self, t: float, bus: dict) -> None:
        s_u = max(-1.0, min(1.0, float(bus.get("joystick.surge", 0.0))))
        s_r = max(-1.0, min(1.0, float(bus.get("joystick.yaw", 0.0))))
        f_u = self._read(s_u)
        f_r = self._read(s_r)
        u_d, r_d = stick_to_command(f_u, f_r, self.cfg)
        bus["joystick.surge_f"] = f_u
        bus["joystick.yaw_f"] = f_r
        bus["joystick.surge_db"] = dead_band(f_u, self.cfg.dead_band)
        bus["joystick.yaw_db"] = dead_band(f_r, self.cfg.dead_band)
        bus["cmd.u_d"] = u_d
        bus["cmd.r_d"] = r_d
