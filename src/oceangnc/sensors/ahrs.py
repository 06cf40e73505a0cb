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

Outputs ``<name>.psi``, ``<name>.r`` (rad, rad/s), ``<name>.phi``, ``<name>.theta`` (rad). Law:
:func:`ahrs_law`.
"""

from __future__ import annotations

import math

from numba import njit
from pydantic import Field

from ..core.law import In, LawBlock, Layout, Opt, Out, Signals, param
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


SIGNALS = Signals(
    psi=In("rad"),
    r=In("rad/s"),
    phi=Opt("rad"),  # a surface vessel has no roll/pitch states: level (0) when nobody publishes them
    theta=Opt("rad"),
    psi_out=Out("rad"),
    r_out=Out("rad/s"),
    phi_out=Out("rad"),
    theta_out=Out("rad"),
)
#: period, lag and magnetic time constants (s); magnetic and yaw noise (rad), gyro bias and noise (rad/s),
#: roll/pitch noise (rad)
PARAMS = Layout(
    "period", "lag", "mag_time_constant", "mag_sigma", "yaw_noise", "gyro_bias", "gyro_noise", "attitude_noise"
)
STATE = Layout("psi_f", "has_psi_f", "mag")
S, P, X = SIGNALS.at, PARAMS.at, STATE.at


@njit(cache=True)
def ahrs_law(t, sig, sl, st, pa, rng):
    """One AHRS sample (module docstring): the lagged heading (the first sample initialises it), the
    magnetic disturbance's Gauss-Markov step, then five normal draws in the order magnetic, yaw, gyro,
    roll, pitch."""
    psi = sig[sl[S.psi]]
    if st[X.has_psi_f] == 0.0:
        st[X.psi_f] = psi
        st[X.has_psi_f] = 1.0
    elif pa[P.lag] > 0:
        a = 1.0 - math.exp(-pa[P.period] / pa[P.lag])
        st[X.psi_f] = angle_lowpass_step(st[X.psi_f], a, psi)
    else:
        st[X.psi_f] = psi
    am = math.exp(-pa[P.period] / pa[P.mag_time_constant])
    w0 = rng.standard_normal()
    w1 = rng.standard_normal()
    w2 = rng.standard_normal()
    w3 = rng.standard_normal()
    w4 = rng.standard_normal()
    st[X.mag] = gauss_markov(st[X.mag], am, pa[P.mag_sigma], w0)
    sig[sl[S.psi_out]] = wrap(st[X.psi_f] + st[X.mag] + pa[P.yaw_noise] * w1)
    sig[sl[S.r_out]] = sig[sl[S.r]] + pa[P.gyro_bias] + pa[P.gyro_noise] * w2
    phi = sig[sl[S.phi]] if sl[S.phi] >= 0 else 0.0
    theta = sig[sl[S.theta]] if sl[S.theta] >= 0 else 0.0
    sig[sl[S.phi_out]] = phi + pa[P.attitude_noise] * w3
    sig[sl[S.theta_out]] = theta + pa[P.attitude_noise] * w4


@register_block("sensor.ahrs")
class AHRS(LawBlock):
    """AHRS on body ``body`` (module docstring); law :func:`ahrs_law`."""

    role = "sensor"
    law = staticmethod(ahrs_law)
    signals = SIGNALS
    draws = True

    gyro_bias = param(P.gyro_bias, "the gyro's bias, drawn at reset, rad/s")

    def __init__(self, cfg: AHRSConfig, body: str = "usv", name: str | None = None):
        self.cfg = cfg
        self.body = body
        self.name = name or f"{body}_ahrs"
        self.period = 1.0 / cfg.rate
        o = self.name
        self.bind(psi=f"{body}.psi", r=f"{body}.r", phi=f"{body}.phi", theta=f"{body}.theta", psi_out=f"{o}.psi",
                  r_out=f"{o}.r", phi_out=f"{o}.phi", theta_out=f"{o}.theta")  # fmt: skip
        self.pa = PARAMS.pack(
            period=self.period,
            lag=cfg.lag,
            mag_time_constant=cfg.mag_time_constant,
            mag_sigma=math.radians(cfg.mag_sigma_deg),
            yaw_noise=math.radians(cfg.yaw_noise_deg),
            gyro_bias=0.0,
            gyro_noise=math.radians(cfg.gyro_noise_degps),
            attitude_noise=math.radians(cfg.attitude_noise_deg),
        )
        self.st = STATE.pack(psi_f=0.0, has_psi_f=0.0, mag=0.0)

    def reset(self, rng) -> None:
        """Clear the lag, draw the magnetic disturbance's initial value and the gyro's bias."""
        self.rng = rng
        c = self.cfg
        self.st[:] = 0.0
        self.st[X.mag] = math.radians(c.mag_sigma_deg) * rng.standard_normal()
        self.pa[P.gyro_bias] = math.radians(c.gyro_bias_degps) * rng.uniform(-1.0, 1.0)

    @property
    def psi_f(self) -> float | None:
        """The lagged heading (rad), None before the first sample."""
        return float(self.st[X.psi_f]) if self.st[X.has_psi_f] else None

    @property
    def mag(self) -> float:
        """The magnetic disturbance now, rad."""
        return float(self.st[X.mag])
