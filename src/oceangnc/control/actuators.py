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

import numpy as np
from numba import njit

from ..core.law import LawBlock, Out, Signals
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


@njit(cache=True)
def thrusters_off_law(t, sig, sl, st, pa):
    """Every output (N) is zero."""
    for i in range(sl.size):
        sig[sl[i]] = 0.0


@register_block("thrusters.off")
class ThrustersOff(LawBlock):
    """Zero thrust commands for the listed vehicles (the USV holds station, the UUV is passive); law
    :func:`thrusters_off_law`."""

    role = "actuator"
    name = "thrusters_off"
    law = staticmethod(thrusters_off_law)

    def __init__(self, keys, period: float = 0.01):
        self.keys = list(keys)
        self.period = period
        self.signals = Signals(**{f"off{i}": Out("N") for i in range(len(self.keys))})
        self.bind(**{f"off{i}": k for i, k in enumerate(self.keys)})
        self.st = np.zeros(1)
        self.pa = np.zeros(1)
