"""Navigation of the combined vehicle from its sensors (003 ch. 6.2): positions for guidance and control.

The USV's position and speed are the GPS fix and its speed over ground; the UUV's position is the
USV's fix plus the USBL's relative position held through dropouts
(:class:`~oceangnc.sensors.filters.DropoutHold`, prefix ``nav.usbl``; 0 before the first fix):

    nav.usv_x, nav.usv_y = gps.x, gps.y;   nav.usv_u = gps.sog
    nav.uuv_x = nav.usv_x + nav.usbl.dn;   nav.uuv_y = nav.usv_y + nav.usbl.de      (m, m/s, NED)
"""

from __future__ import annotations

from ..core.blocks import Block
from ..core.registry import register_block


@register_block("sensor.usbl_navigation")
class USBLNavigation(Block):
    """GPS + held USBL -> ``nav.*`` positions and the USV speed (module docstring)."""

    role = "sensor"
    name = "nav"

    def __init__(self, period: float, gps: str = "gps", usbl: str = "nav.usbl"):
        self.period = float(period)
        self.gps, self.usbl = gps, usbl
        self.inputs = {f"{gps}.x": "m", f"{gps}.y": "m", f"{gps}.sog": "m/s"}
        self.optional_inputs = {f"{usbl}.dn": "m", f"{usbl}.de": "m"}  # 0 until the first USBL fix
        self.outputs = {"nav.usv_x": "m", "nav.usv_y": "m", "nav.uuv_x": "m", "nav.uuv_y": "m", "nav.usv_u": "m/s"}

    def compiled(self):
        """Compiled form for the fused loop (:func:`oceangnc.sensors._compiled.nav_step`)."""
        from ..core.fused import CompiledBlock
        from ._compiled import nav_step

        g, u = self.gps, self.usbl
        return CompiledBlock(
            nav_step,
            [
                f"{g}.x",
                f"{g}.y",
                f"?{u}.dn",
                f"?{u}.de",
                f"{g}.sog",
                "nav.usv_x",
                "nav.usv_y",
                "nav.uuv_x",
                "nav.uuv_y",
                "nav.usv_u",
            ],
        )

    def step(self, t: float, bus: dict) -> None:
        g, u = self.gps, self.usbl
        bus["nav.usv_x"] = bus[f"{g}.x"]
        bus["nav.usv_y"] = bus[f"{g}.y"]
        bus["nav.uuv_x"] = bus["nav.usv_x"] + bus.get(f"{u}.dn", 0.0)
        bus["nav.uuv_y"] = bus["nav.usv_y"] + bus.get(f"{u}.de", 0.0)
        bus["nav.usv_u"] = bus[f"{g}.sog"]
