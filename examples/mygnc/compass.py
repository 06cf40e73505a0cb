"""UUV compass with white noise and dropouts: each sample reads uuv.psi + sigma n (rad, n standard
normal); with probability ``p_drop`` the sample is lost and the last good heading is held
(``compass.valid`` = 0). Two draws per sample, always in this order: the noise, then the dropout."""

import math

from numba import njit

from oceangnc.core.law import In, LawBlock, Layout, Out, Signals
from oceangnc.core.registry import register_block
from oceangnc.core.rotations import wrap

SIGNALS = Signals(psi_true=In("rad"), psi=Out("rad"), valid=Out("1"))
PARAMS = Layout("sigma", "p_drop")
STATE = Layout("held", "has")
S, P, X = SIGNALS.at, PARAMS.at, STATE.at


@njit(cache=True)
def compass_law(t, sig, sl, st, pa, rng):
    """One sample (module docstring); the held heading lives in the state."""
    noise = pa[P.sigma] * rng.standard_normal()
    lost = rng.random() < pa[P.p_drop]
    if not lost or st[X.has] == 0.0:
        st[X.held] = wrap(sig[sl[S.psi_true]] + noise)
        st[X.has] = 1.0
    sig[sl[S.psi]] = st[X.held]
    sig[sl[S.valid]] = 0.0 if lost else 1.0


@register_block("mygnc.compass")
class Compass(LawBlock):
    """Compass (module docstring); parameters ``sigma_deg`` (deg) and ``p_drop`` (0-1)."""

    role = "sensor"
    name = "compass"
    law = staticmethod(compass_law)
    signals = SIGNALS
    draws = True  # the law takes the block's own random generator

    def __init__(self, params, ctx):
        self.period = ctx.period
        self.bind(psi_true="uuv.psi", psi="compass.psi", valid="compass.valid")
        sigma = math.radians(float(params.get("sigma_deg", 1.0)))
        self.pa = PARAMS.pack(sigma=sigma, p_drop=float(params.get("p_drop", 0.1)))
        self.st = STATE.pack(held=0.0, has=0.0)

    def reset(self, rng):
        self.rng = rng
        self.st[:] = 0.0
