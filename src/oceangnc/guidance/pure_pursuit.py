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

from ..core.blocks import Block
from ..core.registry import register_block
from ..core.rotations import hypot
from ..errors import ConfigError


def pursuit_radius(l: float, d: float) -> float:
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


def usv_min_turning_radius(cfg, jacobian: str | None = None) -> float:
    """Minimum turning radius of the USV (m) from its model: the steady turn with one thruster at its
    full forward thrust and the other at zero (forward-only thrust, what the mixing (3.11) can hold
    while keeping way on), computed with :func:`oceangnc.models.usv.steady_turn` (``jacobian`` its
    Newton Jacobian mode)."""
    from ..models.usv import steady_turn
    from ..units import KGF

    u, v, r = steady_turn(cfg, cfg.max_thrust_kgf * KGF, 0.0, jacobian=jacobian)
    return hypot(u, v) / abs(r)


def uuv_turning_radius_at(cfg, speed: float, jacobian: str | None = None) -> float:
    """Turning radius of the UUV (m) at surge speed ``speed`` (m/s) from its model: the stern
    thrusters set to the thrust that holds ``speed`` straight ahead, the bow thruster at full thrust
    (:func:`oceangnc.models.uuv.uuv_steady_planar`). The full-power radius of
    :func:`oceangnc.models.uuv.uuv_min_turning_radius` belongs to a speed (several m/s) the towed
    UUV never reaches, so the radius at the formation's speed is the one that limits the path.
    ``jacobian``: the Newton Jacobian mode of the trims.
    """
    from ..core.roots import bracket_root
    from ..models.uuv import uuv_steady_planar
    from ..units import KGF

    hi = cfg.max_thrust_kgf * KGF
    if not speed > 0:
        raise ConfigError(f"UUV turning radius: speed must be > 0 m/s, got {speed}")
    if uuv_steady_planar(cfg, hi, hi, 0.0, jacobian)[0] < speed:
        raise ConfigError(f"UUV turning radius: the UUV cannot reach {speed} m/s")
    t0 = bracket_root(lambda T: uuv_steady_planar(cfg, T, T, 0.0, jacobian)[0] - speed, 1e-6, hi, xtol=1e-10)
    u, v, r = uuv_steady_planar(cfg, t0, t0, hi, jacobian)
    return hypot(u, v) / abs(r)


def closest_point(p, a, b):
    """Closest point F on the line through a, b to p; returns (F, s, e): s the along-track position of
    F from a (m, positive toward b), e the signed cross-track distance (m, positive when p is to
    starboard of the direction a -> b, i.e. to the right looking along the leg)."""
    a = np.asarray(a, float)
    b = np.asarray(b, float)
    p = np.asarray(p, float)
    t = b - a
    L = hypot(t[0], t[1])
    if L == 0.0:
        raise ConfigError(f"waypoints: consecutive waypoints {tuple(a)} and {tuple(b)} coincide")
    t = t / L
    w = p - a
    s = float(w[0] * t[0] + w[1] * t[1])
    e = float(-t[1] * w[0] + t[0] * w[1])  # NED: starboard normal of t is (-t_e, t_n)
    return a + s * t, s, e


def look_ahead_point(p, a, b, l: float, clamp_end: bool = False):
    """Look-ahead point G on the leg a -> b at distance ``l`` from p (table 3-1 step 4).

    Returns (G, s, e): G as an array (N, E), s and e as in :func:`closest_point`. If the vehicle is
    farther than l from the line, G is the closest point. With ``clamp_end`` G does not go past b.
    """
    F, s, e = closest_point(p, a, b)
    a = np.asarray(a, float)
    b = np.asarray(b, float)
    L = hypot(*(b - a))
    t = (b - a) / L
    ds = math.sqrt(l * l - e * e) if abs(e) < l else 0.0
    sg = s + ds
    if clamp_end and sg > L:
        sg = L
    return a + sg * t, s, e


def pursuit_command(p, psi: float, g):
    """Target heading and the pure-pursuit geometry for look-ahead point g from position p, heading psi.

    Returns (psi_d, l, d, R): psi_d (rad) the bearing of g, l = |g - p| (m), d its lateral offset
    in the vehicle frame (m, + starboard), R = l^2/(2d) (m, eq. 3.5).
    """
    dn = float(g[0] - p[0])
    de = float(g[1] - p[1])
    psi_d = math.atan2(de, dn)
    l = hypot(dn, de)
    d = -math.sin(psi) * dn + math.cos(psi) * de
    return psi_d, l, d, pursuit_radius(l, d)


@register_block("usv.pure_pursuit")
class PurePursuit(Block):
    """Waypoint-following pure-pursuit guidance (see module docstring).

    Reads ``<pos_keys>`` (N, E in m) and ``<psi_key>`` (rad); writes ``guidance.psi_d`` (rad),
    ``guidance.turn_radius`` (m, signed, eq. 3.5; +-1e6 for straight), ``guidance.cross_track`` (m),
    ``guidance.leg`` (index of the active leg's start waypoint), ``guidance.wp_reached`` (count of
    waypoints reached, the start point included once the run starts within ``acceptance`` of it),
    ``guidance.lookahead_n/e`` (m) and ``guidance.done`` (1 when the last waypoint is reached).
    """

    role = "guidance"

    name = "pure_pursuit"

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
        wp = np.asarray(waypoints, dtype=float)
        if wp.ndim != 2 or wp.shape[1] != 2 or len(wp) < 2:
            raise ConfigError("waypoints: need at least two (north, east) pairs")
        for i in range(len(wp) - 1):
            if np.allclose(wp[i], wp[i + 1]):
                raise ConfigError(f"waypoints: waypoints {i} and {i + 1} coincide")
        if not look_ahead > 0:
            raise ConfigError(f"guidance look-ahead must be > 0 m, got {look_ahead}")
        self.wp = wp
        self.l = float(look_ahead)
        self.acceptance = float(acceptance)
        self.period = float(period)
        self.pos_keys = pos_keys
        self.psi_key = psi_key
        self.stop_at_end = stop_at_end
        self.inputs = {pos_keys[0]: "m", pos_keys[1]: "m", psi_key: "rad"}
        self.outputs = {
            "guidance.psi_d": "rad",
            "guidance.turn_radius": "m",
            "guidance.cross_track": "m",
            "guidance.leg": "count",
            "guidance.wp_reached": "count",
            "guidance.lookahead_n": "m",
            "guidance.lookahead_e": "m",
            "guidance.done": "bool",
        }
        self.reset(None)

    def reset(self, rng) -> None:
        self.leg = 0
        self.reached = 0
        self.done = False
        self._started = False

    def compiled(self):
        """Compiled form for the fused loop (:func:`oceangnc.guidance._compiled.pure_pursuit_step`)."""
        from ..core.fused import CompiledBlock
        from ._compiled import pure_pursuit_step

        sig = [
            self.pos_keys[0],
            self.pos_keys[1],
            self.psi_key,
            "guidance.psi_d",
            "guidance.turn_radius",
            "guidance.cross_track",
            "guidance.leg",
            "guidance.wp_reached",
            "guidance.lookahead_n",
            "guidance.lookahead_e",
            "guidance.done",
            "_stop",
        ]
        st = np.array([self.leg, self.reached, 1.0 if self.done else 0.0, 1.0 if self._started else 0.0], float)
        pa = np.concatenate(
            [[self.l, self.acceptance, 1.0 if self.stop_at_end else 0.0, len(self.wp)], self.wp.ravel()]
        )
        return CompiledBlock(pure_pursuit_step, sig, st, pa)

    def step(self, t: float, bus: dict) -> None:
        p = np.array([bus[self.pos_keys[0]], bus[self.pos_keys[1]]])
        psi = bus[self.psi_key]
        if not self._started:
            self._started = True
            if hypot(*(p - self.wp[0])) <= self.acceptance:
                self.reached = 1
        n = len(self.wp)
        # waypoint switching: reach the end of the leg -> next leg
        while not self.done:
            a, b = self.wp[self.leg], self.wp[self.leg + 1]
            _, s, _ = closest_point(p, a, b)
            L = hypot(*(b - a))
            last = self.leg + 1 == n - 1
            near = hypot(*(p - b)) <= self.acceptance
            if near or (not last and s >= L):
                self.reached += 1
                if last:
                    self.done = True
                else:
                    self.leg += 1
                continue
            break
        a, b = self.wp[self.leg], self.wp[self.leg + 1]
        last = self.leg + 1 == n - 1
        g, s, e = look_ahead_point(p, a, b, self.l, clamp_end=last)
        psi_d, _, d, R = pursuit_command(p, psi, g)
        if self.done:
            psi_d = bus.get("guidance.psi_d", psi)
        bus["guidance.psi_d"] = psi_d
        bus["guidance.turn_radius"] = max(-1e6, min(1e6, R))
        bus["guidance.cross_track"] = e
        bus["guidance.leg"] = float(self.leg)
        bus["guidance.wp_reached"] = float(self.reached)
        bus["guidance.lookahead_n"] = float(g[0])
        bus["guidance.lookahead_e"] = float(g[1])
        bus["guidance.done"] = 1.0 if self.done else 0.0
        if self.done and self.stop_at_end:
            bus["_stop"] = True
            bus["_stop_reason"] = f"last waypoint reached at t = {t:.1f} s"
