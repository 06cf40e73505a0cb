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

from ..core.config import StrictModel
from ..core.law import Ext, LawBlock, Layout, Out, Signals
from ..core.registry import register_block


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


@njit(cache=True)
def dead_band(s, d):
    """Stick value with a dead band ``d`` removed and rescaled to [-1, 1]."""
    s = max(-1.0, min(1.0, s))
    a = abs(s)
    if a <= d:
        return 0.0
    return math.copysign((a - d) / (1.0 - d), s)


@njit(cache=True)
def command_from_stick(su, sy, u_max_kn, u_astern_kn, knot, r_max):
    """(u_d m/s, r_d rad/s) from the dead-banded axes: ``u_max_kn`` ahead, ``u_astern_kn`` astern (kn;
    ``knot`` m/s per kn), ``r_max`` (rad/s)."""
    return su * (u_max_kn if su >= 0 else u_astern_kn) * knot, sy * r_max


@njit(cache=True)
def read_axis(value, n, noise, rng):
    """One period's reading of an axis: ``n`` samples of ``value`` with white noise (stick units) from
    ``rng``, averaged by the recursive mean of 001 eq. 26."""
    x = 0.0
    for k in range(n):
        z = value + noise * rng.standard_normal() if noise > 0.0 else value
        x += (z - x) / (k + 1.0)
    return x


def stick_to_command(surge: float, yaw: float, cfg: JoystickConfig) -> tuple[float, float]:
    """(u_d m/s, r_d rad/s) from the two filtered axes (dead band and scaling)."""
    from ..units import KNOT

    su = dead_band(float(surge), cfg.dead_band)
    sy = dead_band(float(yaw), cfg.dead_band)
    u_d, r_d = command_from_stick(su, sy, cfg.u_max_kn, cfg.u_astern_kn, KNOT, math.radians(cfg.r_max_degps))
    return float(u_d), float(r_d)


JOY_SIGNALS = Signals(surge=Ext("1"), yaw=Ext("1"), surge_f=Out("1"), yaw_f=Out("1"), surge_db=Out("1"),
                      yaw_db=Out("1"), u_d=Out("m/s"), r_d=Out("rad/s"))  # fmt: skip
JOY_PARAMS = Layout("samples", "noise", "dead_band", "u_max_kn", "u_astern_kn", "knot", "r_max")
_S, _P = JOY_SIGNALS.at, JOY_PARAMS.at


@njit(cache=True)
def joystick_law(t, sig, sl, st, pa, rng):
    """One period (001 sec. 3.1, eq. 26): each axis (centred when nobody writes it) clipped to [-1, 1],
    read ``samples`` times with noise and averaged, dead-banded and scaled to u_d (m/s), r_d (rad/s)."""
    n = int(pa[_P.samples])
    s_u = max(-1.0, min(1.0, sig[sl[_S.surge]]))
    s_r = max(-1.0, min(1.0, sig[sl[_S.yaw]]))
    f_u = read_axis(s_u, n, pa[_P.noise], rng)
    f_r = read_axis(s_r, n, pa[_P.noise], rng)
    su = dead_band(f_u, pa[_P.dead_band])
    sy = dead_band(f_r, pa[_P.dead_band])
    u_d, r_d = command_from_stick(su, sy, pa[_P.u_max_kn], pa[_P.u_astern_kn], pa[_P.knot], pa[_P.r_max])
    sig[sl[_S.surge_f]] = f_u
    sig[sl[_S.yaw_f]] = f_r
    sig[sl[_S.surge_db]] = su
    sig[sl[_S.yaw_db]] = sy
    sig[sl[_S.u_d]] = u_d
    sig[sl[_S.r_d]] = r_d


@register_block("ship.joystick")
class Joystick(LawBlock):
    """Filter and scale the two stick axes (001 sec. 3.1, eq. 26); see the module docstring; law
    :func:`joystick_law`."""

    role = "controller"
    name = "joystick"
    law = staticmethod(joystick_law)
    signals = JOY_SIGNALS
    draws = True

    def __init__(self, cfg: JoystickConfig):
        from ..units import KNOT

        self.cfg = cfg
        self.period = float(cfg.period)
        self.bind(surge="joystick.surge", yaw="joystick.yaw", surge_f="joystick.surge_f", yaw_f="joystick.yaw_f",
                  surge_db="joystick.surge_db", yaw_db="joystick.yaw_db", u_d="cmd.u_d", r_d="cmd.r_d")  # fmt: skip
        self.pa = JOY_PARAMS.pack(samples=cfg.samples, noise=cfg.noise, dead_band=cfg.dead_band,
                                  u_max_kn=cfg.u_max_kn, u_astern_kn=cfg.u_astern_kn, knot=KNOT,
                                  r_max=math.radians(cfg.r_max_degps))  # fmt: skip
        self.st = np.zeros(1)

    def reset(self, rng: np.random.Generator) -> None:
        self.rng = rng
