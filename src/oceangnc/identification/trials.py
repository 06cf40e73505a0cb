"""Sea-trial blocks for identification (000 sec. 2.2): the ITTC zig-zag manoeuvre and the trial sensors.

``trials`` (:mod:`oceangnc.scenarios.first_order`) runs straight, turning and zig-zag trials of a
model and logs what a crew would measure, for ``oceangnc identify first-order``. Laws:
:func:`zigzag_law` (the switching rule, :func:`zigzag_sign`) and :func:`trial_sensors_law`.
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit
from pydantic import Field

from ..core.law import In, LawBlock, Layout, Out, Signals, param
from ..core.registry import register_block
from ..core.rotations import wrap
from ..io.config import StrictModel


class TrialNoise(StrictModel):
    """Sensor noise on the logged measurements (white, Gaussian)."""

    speed_mps: float = Field(0.0, ge=0, le=5, description="speed noise std, m/s")
    heading_deg: float = Field(0.0, ge=0, le=30, description="heading noise std, deg")
    yaw_rate_degps: float = Field(0.0, ge=0, le=30, description="yaw-rate noise std, deg/s")


def _zigzag_signals(unit: str) -> Signals:
    return Signals(psi=In("rad"), cmd=Out(unit))


ZIGZAG_PARAMS = Layout("amp", "psi_z", "t_step", "scale")
ZIGZAG_STATE = Layout("sign", "psi0", "has_psi0")
_ZS, _ZP, _ZX = _zigzag_signals("rad").at, ZIGZAG_PARAMS.at, ZIGZAG_STATE.at


@njit(cache=True)
def zigzag_sign(t, psi, st, t_step, psi_z):
    """Sign of the zig-zag command (0 before ``t_step``), ``st`` the zig-zag's state, updated.

    The heading change is measured from the heading at the first call, wrapped to (-pi, pi]; the
    command turns to -1 once it reaches +psi_z and back to +1 at -psi_z (rad).
    """
    if st[_ZX.has_psi0] == 0.0:
        st[_ZX.psi0] = psi
        st[_ZX.has_psi0] = 1.0
    dpsi = wrap(psi - st[_ZX.psi0])
    if t < t_step - 1e-9:
        return 0.0
    if st[_ZX.sign] > 0 and dpsi >= psi_z:
        st[_ZX.sign] = -1.0
    elif st[_ZX.sign] < 0 and dpsi <= -psi_z:
        st[_ZX.sign] = 1.0
    return st[_ZX.sign]


@njit(cache=True)
def zigzag_law(t, sig, sl, st, pa):
    """The ITTC zig-zag (:class:`ZigZag`): the command is +-amp * scale with the sign of
    :func:`zigzag_sign`, 0 before t_step."""
    s = zigzag_sign(t, sig[sl[_ZS.psi]], st, pa[_ZP.t_step], pa[_ZP.psi_z])
    sig[sl[_ZS.cmd]] = 0.0 if s == 0.0 else s * pa[_ZP.amp] * pa[_ZP.scale]


@register_block("usv.zigzag")
class ZigZag(LawBlock):
    """ITTC zig-zag: steer +amp until the heading change reaches +psi_z, then -amp until -psi_z, and so on.

    Reads ``usv.psi`` (rad); writes ``key`` (the steering command, ``unit``: rad of rudder, or N of
    differential thrust) = 0 before ``t_step`` (s), then +-``amp * scale``. The heading change is
    measured from the heading at the first firing, wrapped to (-pi, pi]. Law :func:`zigzag_law`.
    """

    role = "guidance"
    name = "zigzag"
    law = staticmethod(zigzag_law)

    amp = param(_ZP.amp, "command amplitude (rad or N)")
    psi_z = param(_ZP.psi_z, "heading change that reverses the command, rad")
    t_step = param(_ZP.t_step, "start of the manoeuvre, s")
    scale = param(_ZP.scale, "scale of the command")

    def __init__(self, amp, psi_z, t_step, period, key, scale=1.0, unit="rad"):
        self.period, self.key = period, key
        self.signals = _zigzag_signals(unit)
        self.bind(psi="usv.psi", cmd=key)
        self.pa = ZIGZAG_PARAMS.pack(amp=amp, psi_z=psi_z, t_step=t_step, scale=scale)
        self.st = ZIGZAG_STATE.pack(sign=1.0, psi0=0.0, has_psi0=0.0)

    def reset(self, rng):
        self.st[:] = ZIGZAG_STATE.pack(sign=1.0, psi0=0.0, has_psi0=0.0)

    @property
    def sign(self) -> float:
        """The command's sign now (+1, -1)."""
        return float(self.st[_ZX.sign])

    @property
    def psi0(self) -> float | None:
        """The heading at the first firing (rad), None before it."""
        return float(self.st[_ZX.psi0]) if self.st[_ZX.has_psi0] else None


TRIAL_PARAMS = Layout(
    "speed_sd", "heading_sd", "yaw_rate_sd", "steer_sum", "steer_sign", "steer_scale", "thrust_sum", "thrust_sign",
    "thrust_scale",
)  # fmt: skip
_TP = TRIAL_PARAMS.at


def _trial_signals(sa: str, sb: str, ta: str, tb: str) -> Signals:
    """The trial sensors' signals, with the units of the logged inputs' signals."""
    return Signals(
        u=In("m/s"),
        psi=In("rad"),
        r=In("rad/s"),
        steer_a=In(sa),
        steer_b=In(sb),
        thrust_a=In(ta),
        thrust_b=In(tb),
        speed=Out("m/s"),
        heading=Out("rad"),
        yaw_rate=Out("rad/s"),
        steer=Out("1"),
        thrust=Out("1"),
    )


_TS = _trial_signals("1", "1", "1", "1").at


@njit(cache=True)
def logged_input(a, b, add, sign, scale):
    """A logged trial input: ``a``, or ``scale * (a + sign * b)`` when ``add`` is set."""
    return a if add == 0.0 else scale * (a + sign * b)


@njit(cache=True)
def trial_sensors_law(t, sig, sl, st, pa, rng):
    """The trial measurements (:class:`TrialSensors`): speed, heading (wrapped) and yaw rate with white
    Gaussian noise (drawn in that order, none for a zero standard deviation), and the two logged
    inputs (:func:`logged_input`)."""
    sd = pa[_TP.speed_sd]
    sig[sl[_TS.speed]] = sig[sl[_TS.u]] + (rng.normal(0.0, sd) if sd != 0.0 else 0.0)
    sd = pa[_TP.heading_sd]
    psi = sig[sl[_TS.psi]] + (rng.normal(0.0, sd) if sd != 0.0 else 0.0)
    sig[sl[_TS.heading]] = wrap(psi)
    sd = pa[_TP.yaw_rate_sd]
    sig[sl[_TS.yaw_rate]] = sig[sl[_TS.r]] + (rng.normal(0.0, sd) if sd != 0.0 else 0.0)
    sig[sl[_TS.steer]] = logged_input(
        sig[sl[_TS.steer_a]], sig[sl[_TS.steer_b]], pa[_TP.steer_sum], pa[_TP.steer_sign], pa[_TP.steer_scale]
    )
    sig[sl[_TS.thrust]] = logged_input(
        sig[sl[_TS.thrust_a]], sig[sl[_TS.thrust_b]], pa[_TP.thrust_sum], pa[_TP.thrust_sign], pa[_TP.thrust_scale]
    )


@register_block("sensor.trial")
class TrialSensors(LawBlock):
    """Measured trial signals with white noise: trial.speed, trial.heading (wrapped), trial.yaw_rate, inputs.

    ``steer`` and ``thrust`` say which signals are logged as the inputs ``trial.steer`` / ``trial.thrust``
    (whatever the vehicle's inputs are: rudder and rpm, or differential and mean thrust): a signal
    name, or ``(a, b, sign, scale)`` for ``scale * (a + sign * b)``; ``units`` gives the units of the
    signals they read. Law :func:`trial_sensors_law`.
    """

    role = "sensor"
    name = "trial_sensors"
    law = staticmethod(trial_sensors_law)
    draws = True

    def __init__(self, noise: TrialNoise, period, steer, thrust, units=None):
        self.n = noise
        self.period = period
        self.steer, self.thrust = _spec(steer), _spec(thrust)
        (sa, sb, ss, sc), (ta, tb, ts, tc) = self.steer, self.thrust
        sb, tb = sb or sa, tb or ta  # a single signal: read twice, its b role unused (steer_sum = 0)
        u = units or {}
        self.signals = _trial_signals(u.get(sa, "1"), u.get(sb, "1"), u.get(ta, "1"), u.get(tb, "1"))
        self.bind(u="usv.u", psi="usv.psi", r="usv.r", steer_a=sa, steer_b=sb, thrust_a=ta, thrust_b=tb, speed="trial.speed", heading="trial.heading", yaw_rate="trial.yaw_rate",
                  steer="trial.steer", thrust="trial.thrust")  # fmt: skip
        self.pa = TRIAL_PARAMS.pack(
            speed_sd=noise.speed_mps,
            heading_sd=math.radians(noise.heading_deg),
            yaw_rate_sd=math.radians(noise.yaw_rate_degps),
            steer_sum=0.0 if self.steer[1] is None else 1.0,
            steer_sign=ss,
            steer_scale=sc,
            thrust_sum=0.0 if self.thrust[1] is None else 1.0,
            thrust_sign=ts,
            thrust_scale=tc,
        )
        self.st = np.zeros(1)

    def reset(self, rng):
        self.rng = rng


def _spec(s) -> tuple:
    """A logged input: a signal name, or (a, b, sign, scale) for scale * (a + sign * b)."""
    if isinstance(s, str):
        return (s, None, 1.0, 1.0)
    a, b, sign, scale = s
    return (a, b, float(sign), float(scale))
