"""Line-of-sight waypoint guidance: conventional LOS and the hybrid perpendicular/LOS law of document 000.

Geometry of a leg from waypoint a to waypoint b (NED, m): alpha = atan2(b_e - a_e, b_n - a_n) is
the leg's heading; the vessel at p has along-track distance s and signed cross-track distance e
(positive to starboard of the leg); the perpendicular distance of 000 sec. 3.2 is d = |e|, and the
foot of the perpendicular is a + s (cos alpha, sin alpha).

* Conventional (enclosure-based) LOS (000 ref. 19, Fossen, Breivik & Skjetne 2003; 000 fig. 10):
  a circle of radius R around the vessel cuts the leg's line at two points; the vessel steers at the
  one ahead, i.e. at the line point ``s + sqrt(R^2 - e^2)`` (heading psi_l). When the circle does
  not reach the line (d >= R) it steers at the leg's end waypoint (the usual fallback).
* Hybrid guidance (000 table 1): by the perpendicular distance d,

  ======================  ==========================================================
  d > 2R                  psi_d: steer at the foot of the perpendicular (right angle)
  R < d <= 2R             psi_R2: LOS with circle radius R2 (R2 > 2R)
  0.5R < d <= R           psi_R1: LOS with circle radius R1 (R1 > R)
  d <= 0.5R               psi_l: conventional LOS with radius R
  ======================  ==========================================================

  000 prints neither R1 nor R2; each band's circle must reach the line (R2 > 2R, R1 > R), and we
  take R2 = 2.5 R, R1 = 1.25 R by default: entering each band at its outer edge the vessel closes at
  asin(0.8) = 53 deg, easing to 24 deg at its inner edge, after the 90 deg approach from far away.

Waypoint switching: the leg a -> b is done when the vessel is within the acceptance radius of b or
has passed b's perpendicular (s >= |b - a|). The first leg runs from waypoint 0 to waypoint 1, so a
vessel starting far from waypoint 0 joins the line 0-1 at a right angle first (000 fig. 21).
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit

from ..core.law import In, LawBlock, Layout, Out, Signals, param
from ..core.registry import register_block
from ..core.rotations import wrap
from .views import entry

BAND_PERPENDICULAR, BAND_R2, BAND_R1, BAND_LOS = 3, 2, 1, 0


@njit(cache=True)
def leg_frame(pn, pe, an, ae, bn, be):
    """(alpha, s, e, length) of the vessel at (pn, pe) relative to the leg a -> b (module docstring);
    angles rad, lengths m."""
    dn, de = bn - an, be - ae
    length = math.hypot(dn, de)
    alpha = math.atan2(de, dn)
    c, sn = math.cos(alpha), math.sin(alpha)
    rn, re = pn - an, pe - ae
    s = c * rn + sn * re
    e = -sn * rn + c * re
    return alpha, s, e, length


@njit(cache=True)
def los_circle(alpha, s, e, radius):
    """Heading (rad) at the forward intersection of the circle of ``radius`` (m) with the leg line, NaN
    if it misses: the target is ``sqrt(R^2 - e^2)`` ahead along the line, so the heading is
    ``alpha + atan2(-e, sqrt(R^2 - e^2))``."""
    if radius <= abs(e):
        return math.nan
    return alpha + math.atan2(-e, math.sqrt(radius * radius - e * e))


def los_circle_heading(alpha: float, s: float, e: float, radius: float) -> float | None:
    """:func:`los_circle`, None when the circle misses the line."""
    psi = los_circle(float(alpha), float(s), float(e), float(radius))
    return None if math.isnan(psi) else float(psi)


@njit(cache=True)
def conventional_los(pn, pe, an, ae, bn, be, R):
    """Conventional LOS heading psi_l (rad, 000 ref. 19); steers at waypoint b when the circle misses
    the line."""
    alpha, s, e, _ = leg_frame(pn, pe, an, ae, bn, be)
    psi = los_circle(alpha, s, e, R)
    if math.isnan(psi):
        psi = math.atan2(be - pe, bn - pn)
    return psi


@njit(cache=True)
def hybrid_los(pn, pe, an, ae, bn, be, R, R1, R2):
    """Hybrid heading of 000 table 1 (rad) and the band used (3 perpendicular, 2 R2, 1 R1, 0 LOS)."""
    alpha, s, e, _ = leg_frame(pn, pe, an, ae, bn, be)
    d = abs(e)
    if d > 2.0 * R:
        return alpha - math.copysign(0.5 * math.pi, e), BAND_PERPENDICULAR
    if d > R:
        return los_circle(alpha, s, e, R2), BAND_R2
    if d > 0.5 * R:
        return los_circle(alpha, s, e, R1), BAND_R1
    return los_circle(alpha, s, e, R), BAND_LOS


@njit(cache=True)
def waypoint_law(pn, pe, wp, n, k, los, R, R1, R2, accept):
    """One step of the waypoint guidance: ``(k, psi_cmd, band, e)``.

    ``wp`` the n waypoints flat (north, east, ...; m); ``k`` the index of the waypoint steered to (the
    leg k-1 -> k), advanced past every waypoint within ``accept`` (m) or whose perpendicular the
    vessel has passed; k = n once the route is done, after which the last leg's line is held with a
    3R look-ahead. ``los`` True: conventional LOS, else the hybrid law (000 table 1).
    """
    while k < n:
        an, ae = wp[2 * k - 2], wp[2 * k - 1]
        bn, be = wp[2 * k], wp[2 * k + 1]
        _, s, _, length = leg_frame(pn, pe, an, ae, bn, be)
        if math.hypot(bn - pn, be - pe) < accept or s >= length:
            k += 1
            continue
        break
    kk = min(k, n - 1)
    an, ae = wp[2 * kk - 2], wp[2 * kk - 1]
    bn, be = wp[2 * kk], wp[2 * kk + 1]
    alpha, s, e, _ = leg_frame(pn, pe, an, ae, bn, be)
    if k >= n:
        psi, band = alpha - math.atan2(e, 3.0 * R), BAND_LOS
    elif los:
        psi, band = conventional_los(pn, pe, an, ae, bn, be, R), BAND_LOS
    else:
        psi, band = hybrid_los(pn, pe, an, ae, bn, be, R, R1, R2)
    return k, wrap(psi), band, e


def distance_to_polyline(px, py, path_x, path_y, chunk: int = 512) -> np.ndarray:
    """Shortest distance (m) from each point (px, py) to the polyline through (path_x, path_y)."""
    px = np.atleast_1d(np.asarray(px, float))
    py = np.atleast_1d(np.asarray(py, float))
    ax, ay = np.asarray(path_x, float)[:-1], np.asarray(path_y, float)[:-1]
    bx, by = np.asarray(path_x, float)[1:], np.asarray(path_y, float)[1:]
    dx, dy = bx - ax, by - ay
    L2 = dx * dx + dy * dy
    L2 = np.where(L2 > 0, L2, 1.0)
    out = np.empty(px.size)
    for i in range(0, px.size, chunk):
        qx = px[i : i + chunk, None]
        qy = py[i : i + chunk, None]
        w = np.clip(((qx - ax) * dx + (qy - ay) * dy) / L2, 0.0, 1.0)
        out[i : i + chunk] = np.sqrt(np.min((ax + w * dx - qx) ** 2 + (ay + w * dy - qy) ** 2, axis=1))
    return out


SIGNALS = Signals(x=In("m"), y=In("m"), psi_cmd=Out("rad"), u_cmd=Out("m/s"), d=Out("m"), e=Out("m"),
                  band=Out("enum"), leg=Out("count"), stop=Out("bool"))  # fmt: skip
PARAMS = Layout("los", "R", "R1", "R2", "accept", "speed", "has_speeds", "stop_at_end", "n")
STATE = Layout("k")
S, P, X = SIGNALS.at, PARAMS.at, STATE.at
#: the route follows the parameters: n waypoints (north, east; m) from this offset of ``pa``, then the
#: n speeds (m/s; zeros without ``speeds``) from ``WP + 2 n``
WP = P.n + 1


@njit(cache=True)
def waypoint_guidance_law(t, sig, sl, st, pa):
    """One period of the LOS / hybrid waypoint guidance (000 table 1, :func:`waypoint_law`): the heading
    command, the speed of the leg steered (the leg's own with ``speeds``), |e|, e, the band and the
    leg; once past the last waypoint ``_stop`` if asked."""
    n = int(pa[P.n])
    wp = pa[WP : WP + 2 * n]
    los = pa[P.los] != 0.0
    k, psi, band, e = waypoint_law(
        sig[sl[S.x]], sig[sl[S.y]], wp, n, int(st[X.k]), los, pa[P.R], pa[P.R1], pa[P.R2], pa[P.accept]
    )
    st[X.k] = k
    if k >= n and pa[P.stop_at_end] != 0.0:
        sig[sl[S.stop]] = 1.0
    kk = min(k, n - 1)
    sig[sl[S.psi_cmd]] = psi
    sig[sl[S.u_cmd]] = pa[P.speed] if pa[P.has_speeds] == 0.0 else pa[WP + 2 * n + kk - 1]
    sig[sl[S.d]] = abs(e)
    sig[sl[S.e]] = e
    sig[sl[S.band]] = float(band)
    sig[sl[S.leg]] = float(kk)


@register_block("usv.los")
class WaypointGuidance(LawBlock):
    """Waypoint following with conventional LOS or the hybrid law of 000 table 1; law
    :func:`waypoint_guidance_law`.

    Reads ``<b>.x``, ``<b>.y`` (m); writes ``<b>.psi_cmd`` (rad), ``<b>.u_cmd`` (m/s, the speed of
    the current leg if ``speeds`` are given, else ``speed``), ``guidance.d`` (perpendicular distance,
    m), ``guidance.e`` (signed cross-track, m, + starboard), ``guidance.band`` and ``guidance.leg``.
    After the last waypoint it holds the last leg's heading and, if ``stop_at_end``, stops the run
    (``_stop``).

    Parameters
    ----------
    waypoints : array (n, 2)
        North, east (m), n >= 2.
    mode : "los" or "hybrid"
    R, R1, R2 : float
        Circle radii (m); see the module docstring.
    accept_radius : float
        Acceptance radius of a waypoint (m).
    speeds : array (n,), optional
        Speed command per waypoint (m/s), used on the leg that starts at it.
    """

    role = "guidance"
    name = "guidance"
    law = staticmethod(waypoint_guidance_law)
    signals = SIGNALS

    R = param(P.R, "LOS circle radius R, m")
    R1 = param(P.R1, "circle radius of the band 0.5R < d <= R, m")
    R2 = param(P.R2, "circle radius of the band R < d <= 2R, m")
    accept = param(P.accept, "waypoint acceptance radius, m")
    speed = param(P.speed, "speed command without per-waypoint speeds, m/s")
    stop_at_end = entry("pa", P.stop_at_end, bool, "end the run (``_stop``) past the last waypoint")
    k = entry("st", X.k, int, "index of the waypoint steered to (the number of waypoints once done)")

    def __init__(
        self,
        waypoints,
        mode: str = "hybrid",
        R: float = 20.0,
        R1: float | None = None,
        R2: float | None = None,
        accept_radius: float | None = None,
        speed: float = 5.0,
        speeds=None,
        period: float = 0.1,
        body: str = "usv",
        stop_at_end: bool = False,
    ):
        wp = np.asarray(waypoints, float)
        if wp.ndim != 2 or wp.shape[0] < 2 or wp.shape[1] != 2:
            raise ValueError("waypoints must be an (n >= 2, 2) array of north, east in m")
        if mode not in ("los", "hybrid"):
            raise ValueError(f"guidance mode must be 'los' or 'hybrid', got {mode!r}")
        R = float(R)
        R1 = float(R1) if R1 is not None else 1.25 * R
        R2 = float(R2) if R2 is not None else 2.5 * R
        if not (R1 > R and R2 > 2 * R):
            raise ValueError(
                f"need R1 > R and R2 > 2R so that each band's circle reaches the leg; got R={R}, R1={R1}, R2={R2}"
            )
        n = len(wp)
        sp = np.zeros(n) if speeds is None else np.asarray(speeds, float)
        self.mode = mode
        self.period = float(period)
        self.body = body
        self.bind(x=f"{body}.x", y=f"{body}.y", psi_cmd=f"{body}.psi_cmd", u_cmd=f"{body}.u_cmd", d="guidance.d",
                  e="guidance.e", band="guidance.band", leg="guidance.leg", stop="_stop")  # fmt: skip
        head = PARAMS.pack(
            los=1.0 if mode == "los" else 0.0,
            R=R,
            R1=R1,
            R2=R2,
            accept=float(accept_radius) if accept_radius is not None else R,
            speed=float(speed),
            has_speeds=0.0 if speeds is None else 1.0,
            stop_at_end=1.0 if stop_at_end else 0.0,
            n=float(n),
        )
        self.pa = np.concatenate([head, wp.ravel(), sp]).astype(np.float64)
        self.st = STATE.pack(k=1.0)

    @property
    def wp(self) -> np.ndarray:
        """The waypoints, (n, 2) north, east in m: a view of the parameter array (from :data:`WP`)."""
        n = int(self.pa[P.n])
        return self.pa[WP : WP + 2 * n].reshape(n, 2)

    @property
    def speeds(self) -> np.ndarray | None:
        """The per-waypoint speeds (m/s; a view of the parameter array), or None."""
        n = int(self.pa[P.n])
        return None if self.pa[P.has_speeds] == 0.0 else self.pa[WP + 2 * n : WP + 3 * n]

    @property
    def done(self) -> bool:
        """The last waypoint is passed."""
        return self.k >= int(self.pa[P.n])

    def reset(self, rng) -> None:
        """Steer to waypoint 1 (the leg 0 -> 1)."""
        self.st[X.k] = 1.0
