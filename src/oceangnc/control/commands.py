"""Open-loop command blocks: a step of set points at a given time (with a compiled form, so a
scenario commanded by them runs fused, issue 19).

``command.step`` (:class:`StepCommand`): each output is ``before`` until ``t_step`` and ``after``
from then on (000 figs. 17-18: the heading and speed steps of the autopilot tests).
"""

from __future__ import annotations

import numpy as np

from ..core.blocks import Block
from ..core.registry import register_block


@register_block("command.step")
class StepCommand(Block):
    """Step set points: ``{signal: (before, after)}``, switching at ``t_step`` (s).

    The switch uses ``t >= t_step - 1e-9`` (the clock's time is ``k dt``), the law of
    :func:`oceangnc.control._compiled_first_order.step_value`. ``units`` gives each output's unit.
    """

    role = "guidance"

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
        self.inputs = {}
        self.outputs = {k: units[k] for k in self.values}

    def step(self, t: float, bus: dict) -> None:
        from ._compiled_first_order import step_value

        for k, (a, b) in self.values.items():
            bus[k] = step_value(float(t), self.t_step, a, b)

    def compiled(self):
        """Compiled form: :func:`oceangnc.control._compiled_first_order.step_command_step`."""
        from ..core.fused import CompiledBlock
        from ._compiled_first_order import step_command_step

        pa = [self.t_step]
        for a, b in self.values.values():
            pa += [a, b]
        return CompiledBlock(step_command_step, list(self.values), params=np.array(pa, dtype=np.float64))


@register_block("command.differential")
class DifferentialThrust(Block):
    """Mean thrust plus and minus a steering signal: ``port = mean + steer``, ``stbd = mean - steer`` (N).

    Reads ``steer_key`` (N, e.g. a :class:`~oceangnc.identification.trials.ZigZag` on differential
    thrust; 0 when absent); writes ``port_key`` and ``stbd_key``.
    """

    role = "guidance"

    def __init__(self, name: str, period: float, mean: float, steer_key: str, port_key: str, stbd_key: str):
        self.name = name
        self.period = float(period)
        self.mean = float(mean)
        self.keys = (steer_key, port_key, stbd_key)
        self.inputs = {steer_key: "N"}
        self.outputs = {port_key: "N", stbd_key: "N"}

    def step(self, t: float, bus: dict) -> None:
        steer = bus.get(self.keys[0], 0.0)
        bus[self.keys[1]] = self.mean + steer
        bus[self.keys[2]] = self.mean - steer

    def compiled(self):
        """Compiled form: :func:`oceangnc.control._compiled_first_order.differential_step`."""
        from ..core.fused import CompiledBlock
        from ._compiled_first_order import differential_step

        return CompiledBlock(differential_step, ["?" + self.keys[0], *self.keys[1:]], params=np.array([self.mean]))
