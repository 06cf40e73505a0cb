"""Compiled forms of the guidance blocks (kernel convention: :mod:`oceangnc.control._compiled`)."""

from __future__ import annotations

import math

from numba import njit

from ..core.rotations import hypot


@njit(cache=True)
def _closest_s(p0, p1, a0, a1, b0, b1):
    t0 = b0 - a0
    t1 = b1 - a1
    L = hypot(t0, t1)
    t0 = t0 / L
    t1 = t1 / L
    w0 = p0 - a0
    w1 = p1 - a1
    s = w0 * t0 + w1 * t1
    e = -t1 * w0 + t0 * w1
    return s, e


@njit(cache=True)
def look_ahead_point(x, y, a0, a1, b0, b1, lookahead, last):
    """``(e, g_n, g_e)``: cross-track distance e (m, positive to starboard of a -> b) of the point
    (x, y) from the leg a -> b, and the look-ahead goal G on the leg at distance ``lookahead`` (m) from
    the point (003 eq. 3.5, fig. 3-2; on the leg's own point when |e| >= lookahead), not past b on the
    ``last`` leg. The one home of this geometry: pure pursuit and the console's route pilot."""
    s, e = _closest_s(x, y, a0, a1, b0, b1)
    L = hypot(b0 - a0, b1 - a1)
    t0 = (b0 - a0) / L
    t1 = (b1 - a1) / L
    ds = math.sqrt(lookahead * lookahead - e * e) if abs(e) < lookahead else 0.0
    sg = s + ds
    if last and sg > L:
        sg = L
    return e, a0 + sg * t0, a1 + sg * t1


@njit(cache=True)
def pure_pursuit_step(t, sig, sl, st, pa):
    """:class:`oceangnc.guidance.pure_pursuit.PurePursuit` (003 table 3-1, eq. 3.5).

    slots: pos_n, pos_e, psi | guidance.psi_d, turn_radius, cross_track, leg, wp_reached,
    lookahead_n, lookahead_e, done, _stop. state: leg, reached, done, started.
    params: l, acceptance, stop_at_end, n, waypoints (n x 2, row-major).
    """
    p0 = sig[sl[0]]
    p1 = sig[sl[1]]
    psi = sig[sl[2]]
    n = int(pa[3])
    leg = int(st[0])
    reached = st[1]
    done = st[2] != 0.0
    if st[3] == 0.0:
        st[3] = 1.0
        if hypot(p0 - pa[4], p1 - pa[5]) <= pa[1]:
            reached = 1.0
    while not done:
        a0, a1 = pa[4 + 2 * leg], pa[5 + 2 * leg]
        b0, b1 = pa[6 + 2 * leg], pa[7 + 2 * leg]
        s, e = _closest_s(p0, p1, a0, a1, b0, b1)
        L = hypot(b0 - a0, b1 - a1)
        last = leg + 1 == n - 1
        near = hypot(p0 - b0, p1 - b1) <= pa[1]
        if near or (not last and s >= L):
            reached += 1.0
            if last:
                done = True
            else:
                leg += 1
            continue
        break
    a0, a1 = pa[4 + 2 * leg], pa[5 + 2 * leg]
    b0, b1 = pa[6 + 2 * leg], pa[7 + 2 * leg]
    last = leg + 1 == n - 1
    e, g0, g1 = look_ahead_point(p0, p1, a0, a1, b0, b1, pa[0], last)
    # pursuit_command
    dn = g0 - p0
    de = g1 - p1
    psi_d = math.atan2(de, dn)
    ll = hypot(dn, de)
    d = -math.sin(psi) * dn + math.cos(psi) * de
    R = math.inf if d == 0.0 else ll * ll / (2.0 * d)
    if done:
        psi_d = sig[sl[3]]
    st[0] = leg
    st[1] = reached
    st[2] = 1.0 if done else 0.0
    sig[sl[3]] = psi_d
    sig[sl[4]] = max(-1e6, min(1e6, R))
    sig[sl[5]] = e
    sig[sl[6]] = float(leg)
    sig[sl[7]] = reached
    sig[sl[8]] = g0
    sig[sl[9]] = g1
    sig[sl[10]] = 1.0 if done else 0.0
    if done and pa[2] != 0.0:
        sig[sl[11]] = 1.0
