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
  come back. This is how the guidance and control survive a USBL dropout.
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit

from ..core.blocks import Block
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


@njit(cache=True)
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


@register_block("sensor.dropout_hold")
class DropoutHold(Block):
    """Hold-last-value dropout handling (module docstring).

    Parameters
    ----------
    name : str
        Block name; outputs are ``<out_prefix>.<signal>``.
    period : float
        Firing period, s (at least as fast as the sensor).
    valid_key : str
        Bus key of the sensor's validity flag (nonzero = fresh valid fix).
    signals : dict
        Output signal name -> input bus key.
    out_prefix : str
        Prefix of the output keys.
    units : dict, optional
        Output signal name -> unit (declared signals; default ``"1"``).
    """

    role = "sensor"

    def __init__(
        self, name: str, period: float, valid_key: str, signals: dict, out_prefix: str, units: dict | None = None
    ):
        self.name = name
        self.period = float(period)
        self.valid_key = valid_key
        self.signals = dict(signals)
        self.out = out_prefix
        units = units or {}
        self.inputs = {valid_key: "bool", **{k: units.get(o, "1") for o, k in self.signals.items()}}
        self.outputs = {
            **{f"{out_prefix}.{o}": units.get(o, "1") for o in self.signals},
            f"{out_prefix}.ok": "bool",
            f"{out_prefix}.age": "s",
            f"{out_prefix}.dropouts": "count",
        }
        self.reset(None)

    def reset(self, rng) -> None:
        self.held: dict | None = None
        self.t_fix = 0.0
        self.dropouts = 0
        self._ok = True

    def compiled(self):
        """Compiled form once a value is held (:func:`oceangnc.sensors._compiled.dropout_hold_step`)."""
        if self.held is None:
            return None
        from ..core.fused import CompiledBlock

        outs = list(self.signals)
        st = np.array([*(self.held[o] for o in outs), self.t_fix, self.dropouts, 1.0 if self._ok else 0.0], float)
        sig = [
            self.valid_key,
            *(self.signals[o] for o in outs),
            *(f"{self.out}.{o}" for o in outs),
            f"{self.out}.ok",
            f"{self.out}.age",
            f"{self.out}.dropouts",
        ]
        return CompiledBlock(dropout_hold_step, sig, st, np.array([float(len(outs))]))

    def step(self, t: float, bus: dict) -> None:
        valid = bool(bus[self.valid_key])
        if valid or self.held is None:
            if all(k in bus for k in self.signals.values()):
                self.held = {o: float(bus[k]) for o, k in self.signals.items()}
                if valid:
                    self.t_fix = t
        ok = valid
        if self._ok and not ok:
            self.dropouts += 1
        self._ok = ok
        if self.held is not None:
            for o, v in self.held.items():
                bus[f"{self.out}.{o}"] = v
        bus[f"{self.out}.ok"] = 1.0 if ok else 0.0
        bus[f"{self.out}.age"] = t - self.t_fix
        bus[f"{self.out}.dropouts"] = float(self.dropouts)


@njit(cache=True)
def dropout_hold_step(t, sig, sl, st, pa):
    """:class:`oceangnc.sensors.filters.DropoutHold` once it holds a value.

    slots: valid, in_0..in_{m-1}, out_0..out_{m-1}, ok, age, dropouts. state: held (m), t_fix,
    dropouts, last ok. params: m.
    """
    m = int(pa[0])
    valid = sig[sl[0]] != 0.0
    if valid:
        for i in range(m):
            st[i] = sig[sl[1 + i]]
        st[m] = t
    if st[m + 2] != 0.0 and not valid:
        st[m + 1] += 1.0
    st[m + 2] = 1.0 if valid else 0.0
    for i in range(m):
        sig[sl[1 + m + i]] = st[i]
    sig[sl[1 + 2 * m]] = 1.0 if valid else 0.0
    sig[sl[2 + 2 * m]] = t - st[m]
    sig[sl[3 + 2 * m]] = st[m + 1]
