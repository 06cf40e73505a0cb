"""Open-loop command blocks: a step of set points at a given time (with a compiled form, so a
scenario commanded by them runs fused, issue 19).

``command.step`` (:class:`StepCommand`): each output is ``before`` until ``t_step`` and ``after``
from then on (000 figs. 17-18: the heading and speed steps of the autopilot tests).
"""

from __future__ import annotations

import numpy as np
from numba import njit

from ..core.law import LawBlock, Layout, Opt, Out, Signals
from ..core.registry import register_block


@njit(cache=True)
def step_value(t, t_step, before, after):
    """``after`` from ``t_step`` on (with 1 ns of slack for the clock's k dt), ``before`` until then."""
    return after if t >= t_step - 1e-9 else before


@njit(cache=True)
def step_command_law(t, sig, sl, st, pa):
    """Every output i (slots in order) is :func:`step_value` at t_step (s, ``pa[0]``) of its (before,
    after) pair, ``pa[1 + 2i]`` and ``pa[2 + 2i]`` (the block's layout: t_step, then the pairs)."""
    for i in range(sl.size):
        sig[sl[i]] = step_value(t, pa[0], pa[1 + 2 * i], pa[2 + 2 * i])


@register_block("command.step")
class StepCommand(LawBlock):
    """Step set points: ``{signal: (before, after)}``, switching at ``t_step`` (s); law
    :func:`step_command_law`. ``units`` gives each output's unit."""

    role = "guidance"
    law = staticmethod(step_command_law)

    def __init__(
        self,
        name: str,
        period: float,
        t_step: float,
        values: dict[str, tuple[float, float]],
        units: dict[str, str],
    ):
        self.name = name
        self.period = float(period)
        self.t_step = float(t_step)
        self.values = {k: (float(a), float(b)) for k, (a, b) in values.items()}
        missing = [k for k in self.values if k not in units]
        if missing:
            raise ValueError(f"command '{name}': no unit for {missing}")
        keys = list(self.values)
        step_params = Layout("t_step", ("before_after", 2 * len(keys)))  # (before, after) per output
        self.signals = Signals(**{f"out{i}": Out(units[k]) for i, k in enumerate(keys)})
        self.bind(**{f"out{i}": k for i, k in enumerate(keys)})
        before_after = [v for ab in self.values.values() for v in ab]
        self.pa = step_params.pack(t_step=self.t_step, before_after=before_after)
        self.st = np.zeros(1)


DIFF_SIGNALS = Signals(steer=Opt("N"), port=Out("N"), stbd=Out("N"))
DIFF_PARAMS = Layout("mean")
_DS, _DP = DIFF_SIGNALS.at, DIFF_PARAMS.at


@njit(cache=True)
def differential_law(t, sig, sl, st, pa):
    """port = mean + steer, stbd = mean - steer (N); steer 0 when nobody writes it."""
    steer = sig[sl[_DS.steer]] if sl[_DS.steer] >= 0 else 0.0
    sig[sl[_DS.port]] = pa[_DP.mean] + steer
    sig[sl[_DS.stbd]] = pa[_DP.mean] - steer


@register_block("command.differential")
class DifferentialThrust(LawBlock):
    """Mean thrust plus and minus a steering signal: ``port = mean + steer``, ``stbd = mean - steer`` (N);
    law :func:`differential_law`.

    Reads ``steer_key`` (N, e.g. a :class:`~oceangnc.identification.trials.ZigZag` on differential
    thrust; 0 when absent); writes ``port_key`` and ``stbd_key``.
    """

    role = "guidance"
    law = staticmethod(differential_law)
    signals = DIFF_SIGNALS

    def __init__(self, name: str, period: float, mean: float, steer_key: str, port_key: str, stbd_key: str):
        self.name = name
        self.period = float(period)
        self.mean = float(mean)
        self.keys = (steer_key, port_key, stbd_key)
        self.bind(steer=steer_key, port=port_key, stbd=stbd_key)
        self.pa = DIFF_PARAMS.pack(mean=self.mean)
        self.st = np.zeros(1)
