"""UUV heading-and-range controller: bow thrust k_heading wrap(psi_usv - psi_compass) (N), stern
thrust k_range e_x on both sides (N, leader-follower range error, 003 eq. 3.12), saturated."""

from numba import njit

from oceangnc.core.law import In, LawBlock, Layout, Out, Signals
from oceangnc.core.registry import register_block
from oceangnc.core.rotations import wrap

SIGNALS = Signals(e_x=In("m"), psi_usv=In("rad"), psi=In("rad"), port=Out("N"), stbd=Out("N"), bow=Out("N"))
PARAMS = Layout("k_range", "k_heading", "limit")
S, P = SIGNALS.at, PARAMS.at


@njit(cache=True)
def heading_hold_law(t, sig, sl, st, pa):
    """The law, written once: the Python step and the fused loop both call it."""
    stern = min(pa[P.limit], max(-pa[P.limit], pa[P.k_range] * sig[sl[S.e_x]]))
    sig[sl[S.port]] = stern
    sig[sl[S.stbd]] = stern
    bow = pa[P.k_heading] * wrap(sig[sl[S.psi_usv]] - sig[sl[S.psi]])
    sig[sl[S.bow]] = min(pa[P.limit], max(-pa[P.limit], bow))


@register_block("mygnc.heading_hold")
class HeadingHold(LawBlock):
    """UUV controller (module docstring); parameters ``k_range`` (N/m), ``k_heading`` (N/rad),
    ``limit`` (N)."""

    role = "controller"
    name = "uuv_control"
    law = staticmethod(heading_hold_law)
    signals = SIGNALS

    def __init__(self, params, ctx):
        self.period = ctx.period
        self.bind(
            e_x="lf.e_x",
            psi_usv=ctx.signal("usv.psi"),
            psi="compass.psi",
            port="uuv.thrust_port_cmd",
            stbd="uuv.thrust_stbd_cmd",
            bow="uuv.thrust_bow_cmd",
        )
        self.pa = PARAMS.pack(
            k_range=float(params.get("k_range", 20.0)),
            k_heading=float(params.get("k_heading", 10.0)),
            limit=float(params.get("limit", 40.0)),
        )
        self.st = Layout().pack()
