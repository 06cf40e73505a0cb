"""Actuator blocks with declared signals, registered under their kinds.

The actuator dynamics (saturation, thrust-voltage curves) live with the vehicle models in
:mod:`oceangnc.models`; these subclasses add the declared inputs and outputs
(:mod:`oceangnc.core.signals`) and the registry kinds, so that scenarios compose them like any
other block and the wiring check covers them:

* ``usv.thrusters`` (:class:`USVThrusterBlock`): ``<b>.thrust_{port,stbd}_cmd`` (N) or
  ``<b>.volt_{port,stbd}_cmd`` (V) -> ``<b>.thrust_{port,stbd}`` (N), 003 eq. 2.5;
* ``uuv.thrusters`` (:class:`UUVThrusterBlock`): ``<b>.thrust_{port,stbd,bow}_cmd`` -> ``<b>.thrust_*`` (N);
* ``usv.rudder_engine`` (:class:`RudderEngineBlock`): ``<b>.delta_s_cmd`` (rad), ``<b>.rpm_cmd`` (rpm) ->
  ``<b>.delta_s``, ``<b>.rpm`` of the first-order USV (000 sec. 2).

* ``thrusters.off`` (:class:`ThrustersOff`): zero thrust commands for the listed keys (a vehicle held still).

All zero their outputs on an emergency stop (``_estop``, optional input).
"""

from __future__ import annotations

from ..core.blocks import Block
from ..core.registry import register_block
from ..models.first_order import FirstOrderActuators
from ..models.usv import USVThrusters
from ..models.uuv import UUVThrusters


@register_block("usv.thrusters")
class USVThrusterBlock(USVThrusters):
    """:class:`~oceangnc.models.usv.USVThrusters` with declared signals."""

    role = "actuator"

    def __init__(self, cfg, period: float = 0.01, mode: str = "thrust", body: str = "usv"):
        super().__init__(cfg, period, mode, body)  # declares its signals (oceangnc.core.law.LawBlock.bind)


@register_block("uuv.thrusters")
class UUVThrusterBlock(UUVThrusters):
    """:class:`~oceangnc.models.uuv.UUVThrusters` with declared signals."""

    role = "actuator"

    def __init__(self, cfg, period: float = 0.01, body: str = "uuv"):
        super().__init__(cfg, period, body)  # declares its signals (oceangnc.core.law.LawBlock.bind)


@register_block("usv.rudder_engine")
class RudderEngineBlock(FirstOrderActuators):
    """:class:`~oceangnc.models.first_order.FirstOrderActuators` with declared signals."""

    role = "actuator"

    def __init__(self, cfg, period: float = 0.05, body: str = "usv"):
        super().__init__(cfg, period, body)  # declares its signals (oceangnc.core.law.LawBlock.bind)


@register_block("thrusters.off")
class ThrustersOff(Block):
    """Zero thrust commands for the listed vehicles (the USV holds station, the UUV is passive)."""

    role = "actuator"
    name = "thrusters_off"

    def __init__(self, keys, period: float = 0.01):
        self.keys = list(keys)
        self.period = period
        self.inputs = {}
        self.outputs = {k: "N" for k in self.keys}

    def compiled(self):
        """Compiled form for the fused loop (:func:`oceangnc.control._compiled_tow.thrusters_off_step`)."""
        from ..core.fused import CompiledBlock
        from ._compiled_tow import thrusters_off_step

        return CompiledBlock(thrusters_off_step, list(self.keys))

    def step(self, t: float, bus: dict) -> None:
        for k in self.keys:
            bus[k] = 0.0
