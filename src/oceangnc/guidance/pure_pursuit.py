"""Pure-pursuit waypoint guidance of the USV (003 ch. 3.1, eq. 3.1-3.6 and table 3-1).

Geometry (003 fig. 3-3). The vehicle is at P with heading psi; the look-ahead point G lies on the
current straight leg at distance ``l`` from P. In the vehicle's frame G is at (b, d): ``d`` is its
lateral offset and ``b`` its offset along the heading. The circle through P, tangent to the heading
and passing through G, has its centre at (0, R) and radius R:

    d^2 + b^2 = l^2                      (3.1)
    a^2 + b^2 = R^2,   a = R - d         (3.2), (3.3)
    => d^2 + b^2 = 2 R d                 (3.4)
    => R = l^2 / (2 d)                   (3.5)

so the commanded curvature is kappa = 1/R = 2 d / l^2 = 2 sin(alpha) / l, alpha the bearing of G
off the bow. The turn is tightest when G is abeam (d = l), which gives R = l/2; hence the
look-ahead is tied to the minimum turning radius by ``l = 2 R_min`` (3.6), with R_min the larger of
the USV's and the UUV's minimum turning radius (:func:`look_ahead_distance`).

Steps of table 3-1, done by :class:`PurePursuit` each period:

1. position of the USV (GPS if sensors are on: the bus keys are configurable);
2. the straight line through the current leg's waypoints;
3. the closest point F on that line (cross-track error e = signed distance to it, positive when
   the vehicle is to starboard of the leg);
4. the look-ahead point G on the leg at distance l from the vehicle: F moved along the leg by
   sqrt(l^2 - e^2) (if |e| >= l, G = F: head straight back to the line), and d, R from (3.5);
5. the target heading psi_d = atan2(G_e - P_e, G_n - P_n).

Waypoint switching (not printed in 003; our choice): waypoint k is *reached* when the vehicle comes
within ``acceptance`` metres of it or passes the normal to the leg through it; then the next leg
starts. On the last leg G is clamped to the final waypoint, and reaching it sets ``_stop`` if asked.
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit

from ..core.law import In, LawBlock, Layout, Out, Signals, entry, param
from ..core.registry import register_block
from ..core.rotations import hypot
from ..errors import ConfigError


@njit(cache=True, inline="always")
def pursuit_radius(l, d):
    """Turning radius R = l^2 / (2 d) (003 eq. 3.5), m; signed like d (positive: turn to starboard).

    ``l`` is the look-ahead distance (m), ``d`` the lateral offset of the look-ahead point in the
    vehicle frame (m, positive to starboard). ``d == 0`` gives an infinite radius (straight ahead).
    """
    if d == 0.0:
        return math.inf
    return l * l / (2.0 * d)


def look_ahead_distance(*min_turning_radii: float) -> float:
    """Look-ahead l = 2 R_min (003 eq. 3.6), R_min the largest of the given minimum turning radii (m)."""
    if not min_turning_radii or any(not (r > 0 and math.isfinite(r)) for r in min_turning_radii):
        raise ConfigError(f"look-ahead: minimum turning radii must be finite and > 0, got {min_turning_radii}")
    return 2.0 * max(min_turning_radii)


def usv_min_turning_radius(cfg, jacobian: str | None = None, interpreted: bool = False) -> float:
    """Minimum turning radius of the USV (m) from its model: the steady turn with one thruster at its
    full forward thrust and the other at zero (forward-only thrust, what the mixing (3.11) can hold
    while keeping way on), computed with :func:`oceangnc.models.usv.steady_turn` (``jacobian`` its
    Newton Jacobian mode, ``interpreted`` its model run as Python: compiling nothing)."""
    from ..models.usv import steady_turn
    from ..units import KGF

    u, v, r = steady_turn(cfg, cfg.max_thrust_kgf * KGF, 0.0, jacobian=jacobian, interpreted=interpreted)
    return hypot.py_func(u, v) / abs(r)  # a Python call: compiling it costs 0.5 s of a first run


def uuv_turning_radius_at(cfg, speed: float, jacobian: str | None = None, interpreted: bool = False) -> float:
    """Turning radius of the UUV (m) at surge speed ``speed`` (m/s) from its model: the stern
    thrusters set to the thrust that holds ``speed`` straight ahead, the bow thruster at full thrust
    (:func:`oceangnc.models.uuv.uuv_steady_planar`). The full-power radius of
    :func:`oceangnc.models.uuv.uuv_min_turning_radius` belongs to a speed (several m/s) the towed
    UUV never reaches, so the radius at the formation's speed is the one that limits the path.
    ``jacobian``: the Newton Jacobian mode of the trims; ``interpreted``: their model run as Python.
    """
    from ..core.roots import bracket_root
    from ..models.uuv import uuv_steady_planar
    from ..units import KGF

    hi = cfg.max_thrust_kgf * KGF
    if not speed > 0:
        raise ConfigError(f"UUV turning radius: speed must be > 0 m/s, got {speed}")
    if uuv_steady_planar(cfg, hi, hi, 0.0, jacobian, interpreted)[0] < speed:
        raise ConfigError(f"UUV turning radius: the UUV cannot reach {speed} m/s")

    def surplus(T):
        return uuv_steady_planar(cfg, T, T, 0.0, jacobian, interpreted)[0] - speed

    t0 = bracket_root(surplus, 1e-6, hi, xtol=1e-10)
    u, v, r = uuv_steady_planar(cfg, t0, t0, hi, jacobian, interpreted)
    return hypot.py_func(u, v) / abs(r)  # a Python call: compiling it costs 0.5 s of a first run


def check_acceptance(acceptance: float, r_usv: float) -> None:
    """Refuse a route the USV cannot finish: pure pursuit ends only inside ``guidance.acceptance`` of the last
    waypoint (the legs before switch at their end's normal too), and a circle narrower than the USV's minimum
    turning radius ``r_usv`` (m) is missed on pass after pass: the USV circles it to the end of the run (measured,
    route (0,0) (20,0) (19,4): acceptance 0.1 m circled for 300 s, 0.3 m took two extra loops, 72 s against
    44 s at 0.5 m; R_min = 0.36 m)."""
    if acceptance < r_usv:
        from ..errors import ConfigError

        raise ConfigError(
            f"guidance.acceptance: {acceptance:g} m is below the USV's minimum turning radius {r_usv:.3g} m, so "
            f"the last waypoint can be missed on every pass (endless circles); allowed >= {r_usv:.3g} m"
        )


@njit(cache=True, inline="always")
def leg_offsets(x, y, a0, a1, b0, b1):
    """``(s, e)`` of the point (x, y) (N, E in m) on the leg a -> b (table 3-1 step 3): s the
    along-track position of the closest point F from a (m, positive toward b), e the signed
    cross-track distance (m, positive when the point is to starboard of the direction a -> b, i.e. to
    the right looking along the leg; NED: the starboard normal of the unit tangent t is (-t_e, t_n))."""
    t0 = b0 - a0
    t1 = b1 - a1
    L = hypot(t0, t1)
    t0 = t0 / L
    t1 = t1 / L
    w0 = x - a0
    w1 = y - a1
    s = w0 * t0 + w1 * t1
    e = -t1 * w0 + t0 * w1
    return s, e


@njit(cache=True, inline="always")
def look_ahead_goal(x, y, a0, a1, b0, b1, lookahead, last):
    """``(e, g_n, g_e)``: cross-track distance e (m, :func:`leg_offsets`) of the point (x, y) from the
    leg a -> b, and the look-ahead goal G on the leg at distance ``lookahead`` (m) from the point
    (table 3-1 step 4, fig. 3-3): F moved along the leg by sqrt(l^2 - e^2), or F itself when
    |e| >= l; not past b on the ``last`` leg. The one home of this geometry: pure pursuit and the
    console's route pilot (:mod:`oceangnc.guidance.route_pilot`)."""
    s, e = leg_offsets(x, y, a0, a1, b0, b1)
    L = hypot(b0 - a0, b1 - a1)
    t0 = (b0 - a0) / L
    t1 = (b1 - a1) / L
    ds = math.sqrt(lookahead * lookahead - e * e) if abs(e) < lookahead else 0.0
    sg = s + ds
    if last and sg > L:
        sg = L
    return e, a0 + sg * t0, a1 + sg * t1


@njit(cache=True, inline="always")
def pursuit_turn(x, y, psi, g0, g1):
    """``(psi_d, l, d, R)`` of the vehicle at (x, y) (m) with heading psi (rad) pursuing the point G =
    (g0, g1) (table 3-1 step 5): psi_d = atan2(G_e - P_e, G_n - P_n) (rad), l = |G - P| (m), d the
    lateral offset of G in the vehicle frame (m, + starboard, eq. 3.1) and R = l^2 / (2 d) (m, eq. 3.5)."""
    dn = g0 - x
    de = g1 - y
    psi_d = math.atan2(de, dn)
    ll = hypot(dn, de)
    d = -math.sin(psi) * dn + math.cos(psi) * de
    return psi_d, ll, d, pursuit_radius(ll, d)


def closest_point(p, a, b):
    """Closest point F on the line through a, b to p; returns (F, s, e) with s, e of :func:`leg_offsets`."""
    a = np.asarray(a, float)
    b = np.asarray(b, float)
    L = hypot(b[0] - a[0], b[1] - a[1])
    if L == 0.0:
        raise ConfigError(f"waypoints: consecutive waypoints {tuple(a)} and {tuple(b)} coincide")
    s, e = leg_offsets(float(p[0]), float(p[1]), a[0], a[1], b[0], b[1])
    return a + s * ((b - a) / L), float(s), float(e)


def look_ahead_point(p, a, b, l: float, clamp_end: bool = False):
    """Look-ahead point G on the leg a -> b at distance ``l`` from p (table 3-1 step 4,
    :func:`look_ahead_goal`); returns (G as an array (N, E), s, e) as :func:`closest_point`. With
    ``clamp_end`` G does not go past b."""
    _, s, _ = closest_point(p, a, b)
    a0, a1, b0, b1 = (float(v) for v in (*a, *b))
    e, g0, g1 = look_ahead_goal(float(p[0]), float(p[1]), a0, a1, b0, b1, float(l), bool(clamp_end))
    return np.array([g0, g1]), s, float(e)


def pursuit_command(p, psi: float, g):
    """Target heading and the pure-pursuit geometry for look-ahead point g from position p, heading psi:
    ``(psi_d, l, d, R)`` of :func:`pursuit_turn`."""
    psi_d, ll, d, R = pursuit_turn(float(p[0]), float(p[1]), float(psi), float(g[0]), float(g[1]))
    return float(psi_d), float(ll), float(d), float(R)


SIGNALS = Signals(x=In("m"), y=In("m"), psi=In("rad"), psi_d=Out("rad"), turn_radius=Out("m"),
                  cross_track=Out("m"), leg=Out("count"), wp_reached=Out("count"), lookahead_n=Out("m"),
                  lookahead_e=Out("m"), done=Out("bool"), stop=Out("bool"))  # fmt: skip
PARAMS = Layout("l", "acceptance", "stop_at_end", "n")
STATE = Layout("leg", "reached", "done", "started")
S, P, X = SIGNALS.at, PARAMS.at, STATE.at
#: the waypoints follow the parameters: n rows (north, east), m, from this offset of ``pa``
WP = P.n + 1
#: largest turning radius written (m): a straight course (R infinite) is written as +-1e6
R_STRAIGHT = 1e6


@njit(cache=True)
def pure_pursuit_law(t, sig, sl, st, pa):
    """One period of table 3-1 (003 ch. 3.1): waypoint switching, then the look-ahead point G on the
    active leg (:func:`look_ahead_goal`; clamped to the last waypoint on the last leg) and the pursuit
    heading and radius (:func:`pursuit_turn`, eq. 3.5).

    Switching: the end b of the active leg is reached within ``acceptance`` (m) of it, or (not on the
    last leg) past its normal, s >= |b - a|; reaching the last waypoint makes the route done, which
    holds the last heading (the vehicle's own on a first period) and sets ``_stop`` if asked. On its
    first period the block counts the start waypoint as reached when the vehicle is within
    ``acceptance`` of it."""
    x = sig[sl[S.x]]
    y = sig[sl[S.y]]
    psi = sig[sl[S.psi]]
    n = int(pa[P.n])
    leg = int(st[X.leg])
    reached = st[X.reached]
    done = st[X.done] != 0.0
    first = st[X.started] == 0.0
    if first:
        st[X.started] = 1.0
        if hypot(x - pa[WP], y - pa[WP + 1]) <= pa[P.acceptance]:
            reached = 1.0
    while not done:
        a0, a1 = pa[WP + 2 * leg], pa[WP + 2 * leg + 1]
        b0, b1 = pa[WP + 2 * leg + 2], pa[WP + 2 * leg + 3]
        s, e = leg_offsets(x, y, a0, a1, b0, b1)
        L = hypot(b0 - a0, b1 - a1)
        last = leg + 1 == n - 1
        near = hypot(x - b0, y - b1) <= pa[P.acceptance]
        if near or (not last and s >= L):
            reached += 1.0
            if last:
                done = True
            else:
                leg += 1
            continue
        break
    a0, a1 = pa[WP + 2 * leg], pa[WP + 2 * leg + 1]
    b0, b1 = pa[WP + 2 * leg + 2], pa[WP + 2 * leg + 3]
    e, g0, g1 = look_ahead_goal(x, y, a0, a1, b0, b1, pa[P.l], leg + 1 == n - 1)
    psi_d, _, _, R = pursuit_turn(x, y, psi, g0, g1)
    if done:
        psi_d = psi if first else sig[sl[S.psi_d]]
    st[X.leg] = leg
    st[X.reached] = reached
    st[X.done] = 1.0 if done else 0.0
    sig[sl[S.psi_d]] = psi_d
    sig[sl[S.turn_radius]] = max(-R_STRAIGHT, min(R_STRAIGHT, R))
    sig[sl[S.cross_track]] = e
    sig[sl[S.leg]] = float(leg)
    sig[sl[S.wp_reached]] = reached
    sig[sl[S.lookahead_n]] = g0
    sig[sl[S.lookahead_e]] = g1
    sig[sl[S.done]] = 1.0 if done else 0.0
    if done and pa[P.stop_at_end] != 0.0:
        sig[sl[S.stop]] = 1.0


@register_block("usv.pure_pursuit")
class PurePursuit(LawBlock):
    """Waypoint-following pure-pursuit guidance (see module docstring); law :func:`pure_pursuit_law`.

    Reads ``<pos_keys>`` (N, E in m) and ``<psi_key>`` (rad); writes ``guidance.psi_d`` (rad),
    ``guidance.turn_radius`` (m, signed, eq. 3.5; +-1e6 for straight), ``guidance.cross_track`` (m),
    ``guidance.leg`` (index of the active leg's start waypoint), ``guidance.wp_reached`` (count of
    waypoints reached, the start point included once the run starts within ``acceptance`` of it),
    ``guidance.lookahead_n/e`` (m), ``guidance.done`` (1 when the last waypoint is reached) and, with
    ``stop_at_end``, ``_stop`` (the run ends at the last waypoint).
    """

    role = "guidance"
    name = "pure_pursuit"
    law = staticmethod(pure_pursuit_law)
    signals = SIGNALS

    l = param(P.l, "look-ahead distance l, m (eq. 3.6)")  # noqa: E741 (the document's symbol)
    acceptance = param(P.acceptance, "waypoint acceptance radius, m")
    stop_at_end = entry("pa", P.stop_at_end, bool, "end the run (``_stop``) at the last waypoint")
    leg = entry("st", X.leg, int, "index of the active leg's start waypoint")
    reached = entry("st", X.reached, int, "waypoints reached")
    done = entry("st", X.done, bool, "the last waypoint is reached")
    _started = entry("st", X.started, bool, "the block has run (the start waypoint was checked)")

    def __init__(
        self,
        waypoints,
        look_ahead: float,
        acceptance: float,
        period: float = 0.1,
        pos_keys=("usv.x", "usv.y"),
        psi_key: str = "usv.psi",
        stop_at_end: bool = True,
    ):
        if not look_ahead > 0:
            raise ConfigError(f"guidance look-ahead must be > 0 m, got {look_ahead}")
        self.period = float(period)
        self.pos_keys = pos_keys
        self.psi_key = psi_key
        self.bind(x=pos_keys[0], y=pos_keys[1], psi=psi_key, psi_d="guidance.psi_d",
                  turn_radius="guidance.turn_radius", cross_track="guidance.cross_track", leg="guidance.leg",
                  wp_reached="guidance.wp_reached", lookahead_n="guidance.lookahead_n",
                  lookahead_e="guidance.lookahead_e", done="guidance.done", stop="_stop")  # fmt: skip
        self.pa = PARAMS.pack(l=float(look_ahead), acceptance=float(acceptance), stop_at_end=float(stop_at_end), n=0.0)
        self.wp = waypoints
        self.st = STATE.pack(dict.fromkeys(STATE.names, 0.0))

    @property
    def wp(self) -> np.ndarray:
        """The waypoints, (n, 2) north, east in m: a view of the parameter array's tail (from :data:`WP`)."""
        n = int(self.pa[P.n])
        return self.pa[WP : WP + 2 * n].reshape(n, 2)

    @wp.setter
    def wp(self, waypoints) -> None:
        """Replace the route (at least two points, no two consecutive ones equal); the parameter array is
        rebuilt when the route does not fit in it (a fused loop already built keeps the old array)."""
        wp = np.asarray(waypoints, dtype=float)
        if wp.ndim != 2 or wp.shape[1] != 2 or len(wp) < 2:
            raise ConfigError("waypoints: need at least two (north, east) pairs")
        for i in range(len(wp) - 1):
            if np.allclose(wp[i], wp[i + 1]):
                raise ConfigError(f"waypoints: waypoints {i} and {i + 1} coincide")
        if self.pa.size < WP + wp.size:
            self.pa = np.concatenate([self.pa[:WP], np.zeros(wp.size)])
        self.pa[P.n] = len(wp)
        self.pa[WP : WP + wp.size] = wp.ravel()

    def reset(self, rng) -> None:
        """The first leg, nothing reached, not started."""
        self.st[:] = 0.0
