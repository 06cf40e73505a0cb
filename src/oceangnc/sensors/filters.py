"""Signal conditioning: first-order low-pass filters and dropout handling (hold last value, flag, recover).

* :class:`LowPass` - first-order IIR low-pass, y_k = y_{k-1} + a (x_k - y_{k-1}) with
  a = 1 - exp(-h / tau), tau = 1 / (2 pi f_c): the exact discretisation of tau y' + y = x with x
  held over the sample. :func:`lowpass_array` applies it to a whole array (compiled).
  003 ch. 6.1.3 says the depth sensor "shows a lot of oscillations ... it is necessary to design
  and use a low-pass filter" without giving it; the cut-off is our choice (docs/combined-vehicle.md).
* :class:`AngleLowPass` - the same on an angle, filtering the wrapped difference.
* :class:`DropoutHold` - a Block that copies measured signals to navigation signals while the sensor's
  ``valid`` flag is set, holds the last valid value while it is not, publishes a flag
  (``<out>.ok``, 1/0) and the age of the held value (``<out>.age``, s), and resumes as soon as fixes
  come back. This is how the guidance and control survive a USBL dropout. Law: :func:`dropout_hold_law`.
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit

from ..core.law import In, LawBlock, Layout, Out, Signals
from ..core.registry import register_block
from ..core.rotations import wrap


def lowpass_coefficient(cutoff_hz: float, period: float) -> float:
    """a = 1 - exp(-2 pi f_c h) of the first-order low-pass (dimensionless)."""
    return 1.0 - math.exp(-2.0 * math.pi * cutoff_hz * period)


@njit(cache=True)
def lowpass_array(x, a, y0):
    """First-order low-pass of a sampled array x with coefficient a (see module docstring)."""
    y = np.empty_like(x)
    acc = y0
    for k in range(x.size):
        acc += a * (x[k] - acc)
        y[k] = acc
    return y


@njit(cache=True, inline="always")
def lowpass_step(y, a, x):
    """One step of the first-order low-pass y <- y + a (x - y) (a from :func:`lowpass_coefficient`)."""
    return y + a * (x - y)


@njit(cache=True)
def angle_lowpass_step(y, a, x):
    """:func:`lowpass_step` of an angle (rad): y <- wrap(y + a wrap(x - y))."""
    return wrap(y + a * wrap(x - y))


@njit(cache=True)
def gauss_markov(m, a, sigma, w):
    """One step of a first-order Gauss-Markov process m <- a m + sigma sqrt(1 - a^2) w, a = exp(-h / T),
    stationary standard deviation ``sigma``, ``w`` a standard normal draw (scalars or arrays)."""
    return a * m + sigma * math.sqrt(1.0 - a * a) * w


@njit(cache=True)
def ring_slot(count, head, cap):
    """Slot for a new entry of a ring buffer of ``cap`` entries holding ``count`` from ``head`` (the
    oldest); returns (slot, new count, new head): a full buffer overwrites its oldest entry."""
    if count < cap:
        return (head + count) % cap, count + 1, head
    return head, count, (head + 1) % cap


class LowPass:
    """Scalar first-order low-pass (state: the last output); the first sample initialises it."""

    def __init__(self, cutoff_hz: float, period: float):
        self.a = lowpass_coefficient(cutoff_hz, period)
        self.y = None

    def reset(self) -> None:
        self.y = None

    def __call__(self, x: float) -> float:
        self.y = x if self.y is None else float(lowpass_step(self.y, self.a, x))
        return self.y


class AngleLowPass(LowPass):
    """First-order low-pass of an angle (rad), output wrapped to (-pi, pi]."""

    def __call__(self, x: float) -> float:
        if self.y is None:
            self.y = x
        else:
            self.y = float(angle_lowpass_step(self.y, self.a, x))
        return self.y


#: the hold's fixed signals; the m inputs (``in0`` ...) and the m held outputs (``out0`` ...) follow
HOLD_SIGNALS = Signals(valid=In("bool"), ok=Out("bool"), age=Out("s"), dropouts=Out("count"))
HOLD_PARAMS = Layout("m")
#: time of the last valid fix (s), dropouts so far, the last sample's validity, whether a value is
#: held; then the m held values
HOLD_STATE = Layout("t_fix", "dropouts", "ok", "has_held")
_HS, _HP, _HX = HOLD_SIGNALS.at, HOLD_PARAMS.at, HOLD_STATE.at
_IN, _HELD = HOLD_SIGNALS.size, HOLD_STATE.size


@njit(cache=True)
def dropout_hold_law(t, sig, sl, st, pa):
    """Hold the last valid value (module docstring): copy the m inputs while ``valid`` is set (and at
    the first sample), count a dropout when a valid sample is followed by an invalid one, publish the
    held values, the flag, the age of the held value (s) and the dropouts."""
    m = int(pa[_HP.m])
    valid = sig[sl[_HS.valid]] != 0.0
    if valid or st[_HX.has_held] == 0.0:
        for i in range(m):
            st[_HELD + i] = sig[sl[_IN + i]]
        st[_HX.has_held] = 1.0
        if valid:
            st[_HX.t_fix] = t
    if st[_HX.ok] != 0.0 and not valid:
        st[_HX.dropouts] += 1.0
    st[_HX.ok] = 1.0 if valid else 0.0
    for i in range(m):
        sig[sl[_IN + m + i]] = st[_HELD + i]
    sig[sl[_HS.ok]] = 1.0 if valid else 0.0
    sig[sl[_HS.age]] = t - st[_HX.t_fix]
    sig[sl[_HS.dropouts]] = st[_HX.dropouts]


@register_block("sensor.dropout_hold")
class DropoutHold(LawBlock):
    """Hold-last-value dropout handling (module docstring); law :func:`dropout_hold_law`.

    Parameters
    ----------
    name : str
        Block name; outputs are ``<out_prefix>.<signal>``.
    period : float
        Firing period, s (at least as fast as the sensor).
    valid_key : str
        Bus key of the sensor's validity flag (nonzero = fresh valid fix).
    signals : dict
        Output signal name -> input bus key (kept as ``sources``).
    out_prefix : str
        Prefix of the output keys.
    units : dict, optional
        Output signal name -> unit (declared signals; default ``"1"``).
    """

    role = "sensor"
    law = staticmethod(dropout_hold_law)

    def __init__(
        self, name: str, period: float, valid_key: str, signals: dict, out_prefix: str, units: dict | None = None
    ):
        self.name = name
        self.period = float(period)
        self.valid_key = valid_key
        self.sources = dict(signals)
        self.out = out_prefix
        units = units or {}
        outs = list(self.sources)
        self.signals = Signals(
            **HOLD_SIGNALS.roles,
            **{f"in{i}": In(units.get(o, "1")) for i, o in enumerate(outs)},
            **{f"out{i}": Out(units.get(o, "1")) for i, o in enumerate(outs)},
        )
        self.bind(
            valid=valid_key,
            ok=f"{out_prefix}.ok",
            age=f"{out_prefix}.age",
            dropouts=f"{out_prefix}.dropouts",
            **{f"in{i}": self.sources[o] for i, o in enumerate(outs)},
            **{f"out{i}": f"{out_prefix}.{o}" for i, o in enumerate(outs)},
        )
        self.pa = HOLD_PARAMS.pack(m=len(outs))
        self.st = np.zeros(HOLD_STATE.size + len(outs))
        self.reset(None)

    def reset(self, rng) -> None:
        self.st[:] = 0.0
        self.st[_HX.ok] = 1.0

    @property
    def held(self) -> dict | None:
        """The held values by output name, None before the first sample."""
        if not self.st[_HX.has_held]:
            return None
        return {o: float(self.st[_HELD + i]) for i, o in enumerate(self.sources)}

    @property
    def t_fix(self) -> float:
        """Time of the last valid fix, s."""
        return float(self.st[_HX.t_fix])

    @property
    def dropouts(self) -> int:
        """Dropouts so far (valid -> invalid transitions)."""
        return int(self.st[_HX.dropouts])
