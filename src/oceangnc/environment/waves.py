r"""Sea waves: regular Airy waves and irregular seas from JONSWAP / Pierson-Moskowitz spectra (issue 29).

Document 003 leaves waves out ("waves are not modeled. Only a constant current is assumed ... The
Froude-Krilov force is zero", its cable section; ch. 2: the wave drift force "was not considered").
This module is the wave field a tow at sea needs: the elevation, particle velocity and acceleration
at any point and time, evaluated by one compiled function for all points at once.

**Spectra** (one-sided, in frequency f, Hz; :func:`jonswap`, :func:`pierson_moskowitz`)::

    S_PM(f) = (5/16) Hs^2 fp^4 f^-5 exp(-5/4 (fp/f)^4)                     (Fossen 2011 eq. 8.51 form)
    S_J(f)  = C(gamma) S_PM(f) gamma^exp(-(f - fp)^2 / (2 sigma^2 fp^2)),   sigma = 0.07 (f <= fp), 0.09
    C(gamma) = 1 - 0.287 ln(gamma)                                          (DNV-RP-C205 eq. 3.5.5.4)

with fp = 1/Tp. The normalising factor C makes Hs = 4 sqrt(m0) hold to about 1 %; :func:`spectrum`
rescales the discretised spectrum so that it holds exactly over the chosen frequency band.

**Directional spreading** (cos-2s, Longuet-Higgins; DNV-RP-C205 eq. 3.5.8.8): D(theta) proportional
to cos^{2s}((theta - theta_0)/2), normalised on the discrete directions.

**Components.** N frequencies on [f_lo, f_hi] (equal bands, each frequency drawn uniformly inside
its band so the record does not repeat with period 1/df), M directions, amplitudes
a = sqrt(2 S(f) D(theta) df dtheta), phases uniform on [0, 2 pi): all from a
``numpy.random.Generator`` of the scenario's seed (deterministic). Wave numbers from the finite-depth
dispersion relation omega^2 = g k tanh(k h) (Newton, :func:`wave_number`).

**Kinematics** (linear Airy theory, e.g. DNV-RP-C205 table 3-1), NED: x north, y east, z down from the
mean free surface, waves travelling *toward* theta (rad from north), water depth h::

    phase  phi = k (x cos theta + y sin theta) - omega t + eps
    eta    = sum a cos phi                                     (elevation, up positive, m)
    u_h    = sum a omega F_c(d) cos phi   along theta           (horizontal velocity, m/s)
    w_up   = sum a omega F_s(d) sin phi                          (vertical velocity, up positive)
    du_h   = sum a omega^2 F_c(d) sin phi,   dw_up = -sum a omega^2 F_s(d) cos phi

with F_c = cosh(k (h - d)) / sinh(k h), F_s = sinh(k (h - d)) / sinh(k h) at depth d below the mean
surface (both exp(-k d) in deep water, k h > 20). The published vector is NED: (u_N, u_E, w_D = -w_up).
Linear theory holds below the mean surface (d >= 0; between it and a crest the surface values are
held, the usual constant extrapolation); with ``wheeler = True`` the kinematics are
stretched to the instantaneous surface (Wheeler 1970; DNV-RP-C205 3.2.3): a point at depth d below
the mean surface, with eta above it, takes the values of depth d' = h (d + eta) / (h + eta)
(d' = d + eta in deep water); points above the instantaneous surface get zero velocity.
"""

from __future__ import annotations

import math
from typing import Literal

import numpy as np
from numba import njit
from pydantic import Field, model_validator

from ..io.config import StrictModel
from .dispersion import wave_number

#: k h above which the deep-water forms are used (tanh(20) = 1 - 8e-18)
DEEP_KH = 20.0


class WaveConfig(StrictModel):
    """Waves of a scenario (``environment.waves``)."""

    kind: Literal["none", "regular", "jonswap", "pierson-moskowitz"] = Field(
        "none", description="no waves, one regular Airy wave, or an irregular sea from a spectrum"
    )
    hs: float = Field(
        1.0, gt=0.0, le=20.0, description="significant wave height (irregular) or 2 x amplitude (regular), m"
    )
    tp: float = Field(6.0, gt=0.5, le=30.0, description="peak period (irregular) or period (regular), s")
    gamma: float = Field(3.3, ge=1.0, le=7.0, description="JONSWAP peak enhancement factor, 1")
    direction_deg: float = Field(
        0.0, ge=-360.0, le=360.0, description="mean direction the waves travel toward, deg from north"
    )
    spreading_s: float = Field(0.0, ge=0.0, le=100.0, description="cos-2s spreading exponent s (0: long-crested), 1")
    components: int = Field(128, ge=1, le=4096, description="number of wave frequencies, 1")
    directions: int = Field(1, ge=1, le=64, description="number of wave directions (with spreading), 1")
    f_lo: float = Field(0.5, gt=0.0, le=1.0, description="lowest frequency, as a multiple of the peak frequency, 1")
    f_hi: float = Field(4.0, ge=1.0, le=10.0, description="highest frequency, as a multiple of the peak frequency, 1")
    depth: float = Field(1000.0, gt=0.0, le=1e5, description="water depth for the dispersion relation, m")
    wheeler: bool = Field(False, description="stretch the kinematics to the instantaneous surface")
    seed: int | None = Field(None, ge=0, description="random phases' seed (default: the scenario's sim.seed)")
    update_dt: float = Field(
        0.1,
        gt=0.0,
        le=1.0,
        description="interval of the second-order expansions of the kinematics at the cable and the UUV "
        "(models/_combined_sea.py), s",
    )

    @model_validator(mode="after")
    def _band(self):
        if self.f_hi <= self.f_lo:
            raise ValueError(f"f_hi ({self.f_hi}) must be above f_lo ({self.f_lo})")
        if self.directions > 1 and self.spreading_s == 0.0:
            raise ValueError("directions > 1 needs spreading_s > 0 (long-crested waves have one direction)")
        from .sea_limits import steepness_error  # a sea steeper than the breaking limit (DNV-RP-C205 3.5.5)

        err = steepness_error(self.kind, self.hs, self.tp, self.depth)
        if err is not None:
            raise ValueError(err)
        return self


def pierson_moskowitz(f, hs: float, tp: float):
    """Pierson-Moskowitz (Bretschneider) spectrum S(f) (m^2/Hz) of significant height ``hs`` (m) and
    peak period ``tp`` (s), one-sided in frequency f (Hz)."""
    f = np.asarray(f, dtype=np.float64)
    fp = 1.0 / tp
    with np.errstate(divide="ignore", over="ignore", invalid="ignore"):
        s = 5.0 / 16.0 * hs**2 * fp**4 * f**-5.0 * np.exp(-1.25 * (fp / f) ** 4)
    return np.where(f > 0, s, 0.0)


def jonswap(f, hs: float, tp: float, gamma: float = 3.3):
    """JONSWAP spectrum S(f) (m^2/Hz): the Pierson-Moskowitz shape times gamma^r, normalised by
    C(gamma) = 1 - 0.287 ln(gamma) (DNV-RP-C205 eq. 3.5.5.1-4)."""
    f = np.asarray(f, dtype=np.float64)
    fp = 1.0 / tp
    sigma = np.where(f <= fp, 0.07, 0.09)
    r = np.exp(-((f - fp) ** 2) / (2.0 * sigma**2 * fp**2))
    return (1.0 - 0.287 * math.log(gamma)) * pierson_moskowitz(f, hs, tp) * gamma**r


class WaveField:
    """The components of one sea state (module docstring), and its compiled evaluation.

    Attributes: ``a`` amplitudes (m), ``omega`` (rad/s), ``k`` (rad/m), ``theta`` travel directions
    (rad from north), ``eps`` phases (rad), ``depth`` (m), ``wheeler`` (0/1), packed for compiled code
    as ``comps`` (5, n) and ``opts`` [depth, wheeler].
    """

    def __init__(self, a, omega, theta, eps, depth: float, wheeler: bool = False):
        self.a = np.ascontiguousarray(a, dtype=np.float64)
        self.omega = np.ascontiguousarray(omega, dtype=np.float64)
        self.theta = np.ascontiguousarray(theta, dtype=np.float64)
        self.eps = np.ascontiguousarray(eps, dtype=np.float64)
        self.depth = float(depth)
        self.wheeler = bool(wheeler)
        self.k = wave_number(self.omega, self.depth)
        self.comps = np.ascontiguousarray(np.vstack([self.a, self.omega, self.k, self.theta, self.eps]))
        self.opts = np.array([self.depth, 1.0 if wheeler else 0.0])

    @classmethod
    def from_config(cls, cfg: WaveConfig, rng: np.random.Generator) -> WaveField | None:
        """The field of ``cfg`` (None for ``kind = "none"``); phases and in-band frequencies from ``rng``."""
        if cfg.kind == "none":
            return None
        theta0 = math.radians(cfg.direction_deg)
        if cfg.kind == "regular":
            return cls([cfg.hs / 2.0], [2 * math.pi / cfg.tp], [theta0], [0.0], cfg.depth, cfg.wheeler)
        f, df, s = spectrum(cfg, rng)
        if cfg.directions > 1:
            th = theta0 + np.linspace(-math.pi, math.pi, cfg.directions, endpoint=False) + math.pi / cfg.directions
            dtheta = 2 * math.pi / cfg.directions
            d = np.cos((th - theta0) / 2.0) ** (2.0 * cfg.spreading_s)
            d = d / (d.sum() * dtheta)
        else:
            th, dtheta, d = np.array([theta0]), 1.0, np.array([1.0])
        a = np.sqrt(2.0 * np.outer(s * df, d * dtheta)).ravel()
        omega = np.repeat(2 * math.pi * f, th.size)
        theta = np.tile(th, f.size)
        eps = rng.uniform(0.0, 2 * math.pi, a.size)
        return cls(a, omega, theta, eps, cfg.depth, cfg.wheeler)

    def hs(self) -> float:
        """Significant wave height 4 sqrt(m0) of the components (m)."""
        return 4.0 * math.sqrt(0.5 * float(np.sum(self.a**2)))

    def kinematics(self, t: float, points) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """(eta (n,), velocity (n, 3), acceleration (n, 3)) at ``points`` (n, 3), NED m, time ``t`` (s)."""
        p = np.ascontiguousarray(np.atleast_2d(points), dtype=np.float64)
        out = np.zeros((p.shape[0], 7))
        wave_kinematics(float(t), p, self.comps, self.opts, out)
        return out[:, 0], out[:, 1:4], out[:, 4:7]


def spectrum(cfg: WaveConfig, rng: np.random.Generator):
    """(f (Hz), df (Hz), S(f) (m^2/Hz)) of ``cfg``'s spectrum on its band, one frequency drawn in each
    of ``cfg.components`` equal bands, S rescaled so that 4 sqrt(sum S df) = Hs exactly."""
    fp = 1.0 / cfg.tp
    edges = np.linspace(cfg.f_lo * fp, cfg.f_hi * fp, cfg.components + 1)
    df = np.diff(edges)
    f = edges[:-1] + df * rng.uniform(0.0, 1.0, cfg.components)
    s = jonswap(f, cfg.hs, cfg.tp, cfg.gamma) if cfg.kind == "jonswap" else pierson_moskowitz(f, cfg.hs, cfg.tp)
    s = s * (cfg.hs / 4.0) ** 2 / float(np.sum(s * df))
    return f, df, s


@njit(cache=True)
def wave_kinematics(t, points, comps, opts, out):
    """Elevation, velocity and acceleration of the wave field ``comps`` (5, n: a, omega, k, theta,
    eps) at ``points`` (m, 3; NED, z down from the mean surface) and time ``t`` (s), into ``out``
    (m, 7): eta (m, up), u_N, u_E, w_D (m/s), their time derivatives (m/s^2). ``opts``: water depth
    (m), Wheeler stretching (1/0). Module docstring for the equations."""
    h = opts[0]
    wheeler = opts[1] != 0.0
    n = comps.shape[1]
    for i in range(points.shape[0]):
        x = points[i, 0]
        y = points[i, 1]
        d = points[i, 2]
        eta = 0.0
        for j in range(n):
            eta += comps[0, j] * math.cos(
                comps[2, j] * (x * math.cos(comps[3, j]) + y * math.sin(comps[3, j])) - comps[1, j] * t + comps[4, j]
            )
        out[i, 0] = eta
        for c in range(1, 7):
            out[i, c] = 0.0
        if d < -eta:
            continue  # above the instantaneous surface: out of the water
        if wheeler:
            de = h * (d + eta) / (h + eta)  # Wheeler: the instantaneous surface mapped onto the mean one
        else:
            de = max(d, 0.0)  # linear theory below the mean surface, its surface value held up to the crest
        for j in range(n):
            a = comps[0, j]
            w = comps[1, j]
            k = comps[2, j]
            th = comps[3, j]
            ct = math.cos(th)
            st = math.sin(th)
            phi = k * (x * ct + y * st) - w * t + comps[4, j]
            kh = k * h
            if kh > DEEP_KH:
                fc = math.exp(-k * de)
                fs = fc
            else:
                sh = math.sinh(kh)
                fc = math.cosh(k * (h - de)) / sh
                fs = math.sinh(k * (h - de)) / sh
            cp = math.cos(phi)
            sp = math.sin(phi)
            uh = a * w * fc * cp
            wu = a * w * fs * sp
            duh = a * w * w * fc * sp
            dwu = -a * w * w * fs * cp
            out[i, 1] += uh * ct
            out[i, 2] += uh * st
            out[i, 3] -= wu
            out[i, 4] += duh * ct
            out[i, 5] += duh * st
            out[i, 6] -= dwu
