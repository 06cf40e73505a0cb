"""Compiled LOS / hybrid waypoint guidance of document 000 (table 1; 000 ref. 19) for the fused
loop (issue 19; kernel convention: :mod:`oceangnc.control._compiled`).

The geometry (:func:`leg_frame`, :func:`los_circle`, :func:`conventional_los`, :func:`hybrid_los`)
and the waypoint switching (:func:`waypoint_law`) have their one home here: the Python functions
and :class:`~oceangnc.guidance.los.WaypointGuidance` in :mod:`oceangnc.guidance.los` call them, and
so does the kernel :func:`waypoint_guidance_step`, so both paths give the same bits. Angles in rad,
lengths in m, NED.
"""

from __future__ import annotations

import math

from numba import njit

from ..core.rotations import wrap

BAND_PERPENDICULAR, BAND_R2, BAND_R1, BAND_LOS = 3, 2, 1, 0


@njit(cache=True)
def leg_frame(pn, pe, an, ae, bn, be):
    """(alpha, s, e, length) of the vessel at (pn, pe) relative to the leg a -> b."""
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
    """Heading at the forward intersection of the circle of ``radius`` with the leg line; NaN if it misses."""
    if radius <= abs(e):
        return math.nan
    return alpha + math.atan2(-e, math.sqrt(radius * radius - e * e))


@njit(cache=True)
def conventional_los(pn, pe, an, ae, bn, be, R):
    """Conventional LOS heading psi_l; steers at waypoint b when the circle misses the line."""
    alpha, s, e, _ = leg_frame(pn, pe, an, ae, bn, be)
    psi = los_circle(alpha, s, e, R)
    if math.isnan(psi):
        psi = math.atan2(be - pe, bn - pn)
    return psi


@njit(cache=True)
def hybrid_los(pn, pe, an, ae, bn, be, R, R1, R2):
    """Hybrid heading of 000 table 1 and the band used (3 perpendicular, 2 R2, 1 R1, 0 LOS)."""
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

    ``wp`` the n waypoints flat (north, east, ...); ``k`` the index of the waypoint steered to (the
    leg k-1 -> k), advanced past every waypoint within ``accept`` or whose perpendicular the vessel
    has passed; k = n once the route is done, after which the last leg's line is held with a
    3R look-ahead. ``los`` True: conventional LOS, else the hybrid law.
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


@njit(cache=True)
def waypoint_guidance_step(t, sig, sl, st, pa):
    """:class:`oceangnc.guidance.los.WaypointGuidance`.

    slots: x, y | psi_cmd, u_cmd, guidance.d, guidance.e, guidance.band, guidance.leg, _stop.
    state: k. params: los (1/0), R, R1, R2, accept, speed, has_speeds, stop_at_end, n,
    waypoints (2n), speeds (n).
    """
    n = int(pa[8])
    wp = pa[9 : 9 + 2 * n]
    k, psi, band, e = waypoint_law(sig[sl[0]], sig[sl[1]], wp, n, int(st[0]), pa[0] != 0.0, pa[1], pa[2], pa[3], pa[4])
    st[0] = k
    if k >= n and pa[7] != 0.0:
        sig[sl[8]] = 1.0
    kk = min(k, n - 1)
    sig[sl[2]] = psi
    sig[sl[3]] = pa[5] if pa[6] == 0.0 else pa[9 + 2 * n + kk - 1]
    sig[sl[4]] = abs(e)
    sig[sl[5]] = e
    sig[sl[6]] = float(band)
    sig[sl[7]] = float(kk)
