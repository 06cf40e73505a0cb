"""A user's UUV controller with one compiled law (the developing.md worked example, heading on the USV's
heading, range closed by the stern thrusters), written as a :class:`oceangnc.core.law.LawBlock`."""

from numba import njit

from mylaw.gains import range_gain
from oceangnc.core.law import In, LawBlock, Layout, Out, Signals
from oceangnc.core.registry import register_block
from oceangnc.core.rotations import wrap

SIGNALS = Signals(e_x=In("m"), psi_usv=In("rad"), psi=In("rad"), port=Out("N"), stbd=Out("N"), bow=Out("N"))
PARAMS = Layout("k_heading")
S, P = SIGNALS.at, PARAMS.at


@njit(cache=True)
def hold_law(t, sig, sl, st, pa):
    """Stern thrust range_gain() e_x (N) on both sides; bow thrust k_heading wrap(psi_usv - psi) (N)."""
    thrust = range_gain() * sig[sl[S.e_x]]
    sig[sl[S.port]] = thrust
    sig[sl[S.stbd]] = thrust
    sig[sl[S.bow]] = pa[P.k_heading] * wrap(sig[sl[S.psi_usv]] - sig[sl[S.psi]])


@register_block("mylaw.hold")
class Hold(LawBlock):
    """UUV controller (module docstring)."""

    role = "controller"
    name = "uuv_control"
    law = staticmethod(hold_law)
    signals = SIGNALS

    def __init__(self, params, ctx):
        self.period = ctx.period
        self.bind(
            e_x="lf.e_x",
            psi_usv=ctx.signal("usv.psi"),
            psi="uuv.psi",
            port="uuv.thrust_port_cmd",
            stbd="uuv.thrust_stbd_cmd",
            bow="uuv.thrust_bow_cmd",
        )
        self.pa = PARAMS.pack(k_heading=float(params.get("k_heading", 10.0)))
        self.st = Layout().pack()
