"""Navigation of the combined vehicle from its sensors (003 ch. 6.2): positions for guidance and control.

The USV's position and speed are the GPS fix and its speed over ground; the UUV's position is the
USV's fix plus the USBL's relative position held through dropouts
(:class:`~oceangnc.sensors.filters.DropoutHold`, prefix ``nav.usbl``; 0 before the first fix):

    nav.usv_x, nav.usv_y = gps.x, gps.y;   nav.usv_u = gps.sog
    nav.uuv_x = nav.usv_x + nav.usbl.dn;   nav.uuv_y = nav.usv_y + nav.usbl.de      (m, m/s, NED)

Law: :func:`navigation_law`.
"""

from __future__ import annotations

import numpy as np
from numba import njit

from ..core.law import In, LawBlock, Opt, Out, Signals
from ..core.registry import register_block

SIGNALS = Signals(
    gps_x=In("m"),
    gps_y=In("m"),
    usbl_dn=Opt("m"),  # 0 until the first USBL fix
    usbl_de=Opt("m"),
    gps_sog=In("m/s"),
    usv_x=Out("m"),
    usv_y=Out("m"),
    uuv_x=Out("m"),
    uuv_y=Out("m"),
    usv_u=Out("m/s"),
)
S = SIGNALS.at


@njit(cache=True)
def navigation_law(t, sig, sl, st, pa):
    """The USV from the GPS, the UUV = USV + the held USBL offset (module docstring)."""
    x = sig[sl[S.gps_x]]
    y = sig[sl[S.gps_y]]
    sig[sl[S.usv_x]] = x
    sig[sl[S.usv_y]] = y
    sig[sl[S.uuv_x]] = x + (sig[sl[S.usbl_dn]] if sl[S.usbl_dn] >= 0 else 0.0)
    sig[sl[S.uuv_y]] = y + (sig[sl[S.usbl_de]] if sl[S.usbl_de] >= 0 else 0.0)
    sig[sl[S.usv_u]] = sig[sl[S.gps_sog]]


@register_block("sensor.usbl_navigation")
class USBLNavigation(LawBlock):
    """GPS + held USBL -> ``nav.*`` positions and the USV speed (module docstring); law :func:`navigation_law`."""

    role = "sensor"
    name = "nav"
    law = staticmethod(navigation_law)
    signals = SIGNALS

    def __init__(self, period: float, gps: str = "gps", usbl: str = "nav.usbl"):
        self.period = float(period)
        self.gps, self.usbl = gps, usbl
        self.bind(gps_x=f"{gps}.x", gps_y=f"{gps}.y", usbl_dn=f"{usbl}.dn", usbl_de=f"{usbl}.de",
                  gps_sog=f"{gps}.sog", usv_x="nav.usv_x", usv_y="nav.usv_y", uuv_x="nav.uuv_x",
                  uuv_y="nav.uuv_y", usv_u="nav.usv_u")  # fmt: skip
        self.pa = np.zeros(1)
        self.st = np.zeros(1)
