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

from ..core.blocks import Block
from ..core.registry import register_block
from . import _compiled_waypoints as _cw
from ._compiled_waypoints import BAND_LOS, BAND_PERPENDICULAR, BAND_R1, BAND_R2  # noqa: F401 (re-exported)


def leg_frame(pn: float, pe: float, an: float, ae: float, bn: float, be: float):
    """(alpha, s, e, length) of the vessel at (pn, pe) relative to the leg a -> b; angles rad, lengths m
    (compiled: :func:`oceangnc.guidance._compiled_waypoints.leg_frame`)."""
    return _cw.leg_frame(float(pn), float(pe), float(an), float(ae), float(bn), float(be))


def los_circle_heading(alpha: float, s: float, e: float, radius: float) -> float | None:
    """Heading (rad) at the forward intersection of the circle of ``radius`` (m) with the leg line, or None.

    With the vessel at cross-track e, the target is ``sqrt(R^2 - e^2)`` ahead along the line, so the
    heading is ``alpha + atan2(-e, sqrt(R^2 - e^2))``.
    """
    psi = _cw.los_circle(float(alpha), float(s), float(e), float(radius))
    return None if math.isnan(psi) else psi


def conventional_los(pn, pe, an, ae, bn, be, R):
    """Conventional LOS heading psi_l (rad); steers at waypoint b when the circle misses the line."""
    return _cw.conventional_los(*(float(v) for v in (pn, pe, an, ae, bn, be, R)))


def hybrid_los(pn, pe, an, ae, bn, be, R, R1, R2):
    """Hybrid heading of 000 table 1 (rad) and the band used (3 perpendicular, 2 R2, 1 R1, 0 LOS)."""
    psi, band = _cw.hybrid_los(*(float(v) for v in (pn, pe, an, ae, bn, be, R, R1, R2)))
    return psi, int(band)


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


@register_block("usv.los")
class WaypointGuidance(Block):
    """Waypoint following with conventional LOS or the hybrid law of 000 table 1.

    Reads ``<b>.x``, ``<b>.y`` (m); writes ``<b>.psi_cmd`` (rad), ``<b>.u_cmd`` (m/s, the speed of
    the current leg if ``speeds`` are given, else ``speed``), ``guidance.d`` (perpendicular distance,
    m), ``guidance.e`` (signed cross-track, m, + starboard), ``guidance.band`` and ``guidance.leg``.
    After the last waypoint it holds the last leg's heading and, if ``stop_at_end``, stops the run.

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
        self.wp = wp
        self._wp_flat = np.ascontiguousarray(wp.ravel())
        self.mode = mode
        self.R = float(R)
        self.R1 = float(R1) if R1 is not None else 1.25 * self.R
        self.R2 = float(R2) if R2 is not None else 2.5 * self.R
        if not (self.R1 > self.R and self.R2 > 2 * self.R):
            raise ValueError(
                f"need R1 > R and R2 > 2R so that each band's circle reaches the leg; got R={self.R}, "
                f"R1={self.R1}, R2={self.R2}"
            )
        self.accept = float(accept_radius) if accept_radius is not None else self.R
        self.speed = float(speed)
        self.speeds = None if speeds is None else np.asarray(speeds, float)
        self.period = float(period)
        self.body = body
        self.stop_at_end = stop_at_end
        self.inputs = {f"{body}.x": "m", f"{body}.y": "m"}
        self.outputs = {
            f"{body}.psi_cmd": "rad",
            f"{body}.u_cmd": "m/s",
            "guidance.d": "m",
            "guidance.e": "m",
            "guidance.band": "enum",
            "guidance.leg": "count",
        }
        self.k = 1
        self.done = False

    def reset(self, rng) -> None:
        self.k = 1
        self.done = False

    def step(self, t: float, bus: dict) -> None:
        b = self.body
        pn, pe = float(bus[f"{b}.x"]), float(bus[f"{b}.y"])
        n = len(self.wp)
        self.k, psi, band, e = _cw.waypoint_law(
            pn, pe, self._wp_flat, n, self.k, self.mode == "los", self.R, self.R1, self.R2, self.accept
        )
        if self.k >= n:
            self.done = True
            if self.stop_at_end:
                bus["_stop"] = True
                bus["_stop_reason"] = f"last waypoint reached at t = {t:.1f} s"
        k = min(self.k, n - 1)
        bus[f"{b}.psi_cmd"] = psi
        bus[f"{b}.u_cmd"] = self.speed if self.speeds is None else float(self.speeds[k - 1])
        bus["guidance.d"] = abs(e)
        bus["guidance.e"] = e
        bus["guidance.band"] = float(band)
        bus["guidance.leg"] = float(k)

    def compiled(self):
        """Compiled form: :func:`oceangnc.guidance._compiled_waypoints.waypoint_guidance_step`."""
        from ..core.fused import CompiledBlock

        b = self.body
        n = len(self.wp)
        speeds = np.zeros(n) if self.speeds is None else self.speeds
        head = [1.0 if self.mode == "los" else 0.0, self.R, self.R1, self.R2, self.accept, self.speed]
        head += [0.0 if self.speeds is None else 1.0, 1.0 if self.stop_at_end else 0.0, float(n)]
        pa = np.concatenate([head, self._wp_flat, speeds]).astype(np.float64)
        sigs = [f"{b}.x", f"{b}.y", f"{b}.psi_cmd", f"{b}.u_cmd", "guidance.d", "guidance.e", "guidance.band"]
        sigs += ["guidance.leg", "_stop"]
        return CompiledBlock(_cw.waypoint_guidance_step, sigs, state=np.array([float(self.k)]), params=pa)
