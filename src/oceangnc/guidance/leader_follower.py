"""Leader-follower geometry between the USV (leader) and the UUV (follower), 003 ch. 3.2, eq. 3.7-3.9.

Relative position of the UUV in the USV's body frame (003 eq. 3.7, printed):

    l_x = -(X_usv - X_uuv) cos psi_usv - (Y_usv - Y_uuv) sin psi_usv
    l_y =  (X_usv - X_uuv) sin psi_usv - (Y_usv - Y_uuv) cos psi_usv

i.e. (l_x, l_y) = R(psi_usv)^T (p_uuv - p_usv): l_x > 0 when the UUV is ahead of the USV, l_y > 0
when it is to starboard. The relative range is l = |(l_x, l_y)| (horizontal, what the USBL gives
after removing the relative depth) and the relative bearing lambda = atan2(l_y, l_x), measured
from the USV's bow, clockwise; the follower must stay inside ``R >= l >= 0`` and behind,
``lambda in (pi/2, 3 pi/2)``.

Target offsets (003 eq. 3.8). The printed form ``l_x^d = l^d sin(lambda^d + phi_usv - pi/2)``,
``l_y^d = l^d cos(lambda^d + phi_usv - pi/2)`` mixes the USV's heading into a body-frame offset
and, with phi_usv = 0 and lambda^d = pi (directly astern), would put the target *ahead* of the
USV. We use the reading consistent with (3.7) and with lambda measured from the bow:

    l_x^d = l^d cos(lambda^d),   l_y^d = l^d sin(lambda^d)

(constant in the USV frame), so lambda^d = pi puts the UUV l^d metres astern. The follower's goals
(003 eq. 3.9) are l_x -> l_x^d, l_y -> l_y^d and a zero relative heading psi_usv - psi_uuv.

LOS bearing alpha (table 3-2): the direction from the UUV to the USV, atan2(dY, dX) in NED; the
UUV's "heading to the USV" used by the PID outside R (003 eq. 3.13).
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit

from ..core.law import In, LawBlock, Layout, Out, Signals, param
from ..core.registry import register_block
from ..core.rotations import hypot, wrap


@njit(cache=True, inline="always")
def relative_position(x_l, y_l, psi_l, x_f, y_f):
    """(l_x, l_y) of the follower in the leader's body frame (003 eq. 3.7), m."""
    dx = x_l - x_f
    dy = y_l - y_f
    c = math.cos(psi_l)
    s = math.sin(psi_l)
    return -dx * c - dy * s, dx * s - dy * c


@njit(cache=True, inline="always")
def range_bearing(lx, ly):
    """Relative range l (m) and bearing lambda from the leader's bow (rad, in [0, 2 pi))."""
    return hypot(lx, ly), math.atan2(ly, lx) % (2.0 * math.pi)


def target_offset(l_d, lambda_d):
    """Target (l_x^d, l_y^d) in the leader frame (003 eq. 3.8, read as explained above), m."""
    return l_d * math.cos(lambda_d), l_d * math.sin(lambda_d)


@njit(cache=True, inline="always")
def target_point(x_l, y_l, psi_l, lx_d, ly_d):
    """Earth-frame (N, E) position of the target offset (l_x^d, l_y^d) of a leader at (x_l, y_l, psi_l)."""
    c = math.cos(psi_l)
    s = math.sin(psi_l)
    return x_l + c * lx_d - s * ly_d, y_l + s * lx_d + c * ly_d


@njit(cache=True, inline="always")
def los_bearing(x_f, y_f, x_l, y_l):
    """Bearing from the follower to the leader (rad, NED, from north): the UUV's heading to the USV."""
    return math.atan2(y_l - y_f, x_l - x_f)


#: the outputs of :func:`geometry` (and of the block), in order, with units
OUTPUTS = {"lf.lx": "m", "lf.ly": "m", "lf.range": "m", "lf.bearing": "rad", "lf.lx_d": "m", "lf.ly_d": "m",
           "lf.target_n": "m", "lf.target_e": "m", "lf.e_x": "m", "lf.e_y": "m", "lf.rel_heading_err": "rad",
           "lf.los": "rad", "lf.los_err": "rad", "lf.outside": "bool", "lf.psi_d": "rad"}  # fmt: skip


@njit(cache=True, inline="always")
def geometry(xl, yl, psil, xf, yf, psif, lx_d, ly_d, R, relative_only):
    """Everything the block publishes (:data:`OUTPUTS`, in order) from the leader's and follower's
    positions and headings: eq. 3.7-3.9, the target point, the error in the follower's frame, the LOS
    and the desired heading (the leader's inside ``R`` or when ``relative_only``, else the LOS)."""
    lx, ly = relative_position(xl, yl, psil, xf, yf)
    rng, lam = range_bearing(lx, ly)
    tn, te = target_point(xl, yl, psil, lx_d, ly_d)
    c, s = math.cos(psif), math.sin(psif)
    dn, de = tn - xf, te - yf
    los = los_bearing(xf, yf, xl, yl)
    outside = rng > R and not relative_only
    return (lx, ly, rng, lam, lx_d, ly_d, tn, te, c * dn + s * de, -s * dn + c * de, wrap(psil - psif), los,
            wrap(los - psif), 1.0 if outside else 0.0, los if outside else psil)  # fmt: skip


#: the block's signals: the leader's and follower's positions and headings, then :data:`OUTPUTS` in order
SIGNALS = Signals(
    xl=In("m"), yl=In("m"), psil=In("rad"), xf=In("m"), yf=In("m"), psif=In("rad"),
    **{k.removeprefix("lf."): Out(u) for k, u in OUTPUTS.items()},
)  # fmt: skip
PARAMS = Layout("lx_d", "ly_d", "R", "relative_only")
S, P = SIGNALS.at, PARAMS.at


@njit(cache=True)
def leader_follower_law(t, sig, sl, st, pa):
    """The leader-follower geometry (003 eq. 3.7-3.9, :func:`geometry`) of the bound leader and follower
    with the target offset (``lx_d``, ``ly_d``; m) and the range ``R`` (m), written to the outputs of
    :data:`OUTPUTS` (each in its unit)."""
    out = geometry(
        sig[sl[S.xl]], sig[sl[S.yl]], sig[sl[S.psil]], sig[sl[S.xf]], sig[sl[S.yf]], sig[sl[S.psif]],
        pa[P.lx_d], pa[P.ly_d], pa[P.R], pa[P.relative_only] != 0.0,
    )  # fmt: skip
    (sig[sl[S.lx]], sig[sl[S.ly]], sig[sl[S.range]], sig[sl[S.bearing]], sig[sl[S.lx_d]], sig[sl[S.ly_d]],
     sig[sl[S.target_n]], sig[sl[S.target_e]], sig[sl[S.e_x]], sig[sl[S.e_y]], sig[sl[S.rel_heading_err]],
     sig[sl[S.los]], sig[sl[S.los_err]], sig[sl[S.outside]], sig[sl[S.psi_d]]) = out  # fmt: skip


@register_block("uuv.leader_follower")
class LeaderFollower(LawBlock):
    """Leader-follower guidance of the UUV: geometry, targets and the desired heading; law
    :func:`leader_follower_law`.

    Reads the leader's and follower's positions and headings from the bus keys given (truth or
    navigation estimates). Writes ``lf.lx``, ``lf.ly`` (m, eq. 3.7), ``lf.range`` (m),
    ``lf.bearing`` (rad), ``lf.lx_d``, ``lf.ly_d`` (m, eq. 3.8), ``lf.target_n/e`` (m),
    ``lf.e_x``, ``lf.e_y`` (m: target minus UUV position, in the UUV's body frame),
    ``lf.rel_heading_err`` = wrap(psi_usv - psi_uuv) (rad, eq. 3.9), ``lf.los`` (rad),
    ``lf.los_err`` = wrap(los - psi_uuv) (rad), ``lf.outside`` (1 when l > R) and ``lf.psi_d``
    (rad): the UUV's desired heading, the USV's heading inside R and the LOS outside it (in
    ``relative-angle`` mode always the USV's heading).
    """

    role = "guidance"
    name = "leader_follower"
    law = staticmethod(leader_follower_law)
    signals = SIGNALS

    R = param(P.R, "range inside which the follower keeps the leader's heading, m")
    lx_d = param(P.lx_d, "target offset ahead in the leader's frame l_x^d (eq. 3.8), m")
    ly_d = param(P.ly_d, "target offset to starboard in the leader's frame l_y^d (eq. 3.8), m")

    def __init__(
        self,
        l_d: float,
        lambda_d: float,
        R: float,
        period: float = 0.1,
        mode: str = "relative-angle-plus-heading",
        leader=("usv.x", "usv.y", "usv.psi"),
        follower=("uuv.x", "uuv.y", "uuv.psi"),
    ):
        self.l_d = float(l_d)
        self.lambda_d = float(lambda_d)
        self.period = float(period)
        self.mode = mode
        self.leader = leader
        self.follower = follower
        self.bind(xl=leader[0], yl=leader[1], psil=leader[2], xf=follower[0], yf=follower[1], psif=follower[2],
                  **{k.removeprefix("lf."): k for k in OUTPUTS})  # fmt: skip
        lx_d, ly_d = target_offset(self.l_d, self.lambda_d)
        self.pa = PARAMS.pack(lx_d=lx_d, ly_d=ly_d, R=float(R), relative_only=1.0 if mode == "relative-angle" else 0.0)
        self.st = np.zeros(1)  # no state
