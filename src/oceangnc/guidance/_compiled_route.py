"""Compiled route pilot of the console's USV (003 ch. 3.1 table 3-1, eq. 3.5; ch. 5.4 remote mode)
for the fused loop (issue 19; kernel convention: :mod:`oceangnc.control._compiled`).

:func:`route_pilot_law` is the one home of the pilot's law: :class:`~oceangnc.guidance.route_pilot.RoutePilot`
calls it from Python and :func:`route_pilot_step` from the fused loop. The pure-pursuit geometry
repeats :func:`~oceangnc.guidance.pure_pursuit.closest_point`,
:func:`~oceangnc.guidance.pure_pursuit.look_ahead_point` and
:func:`~oceangnc.guidance.pure_pursuit.pursuit_command` operation for operation.

Route state ``rs`` (4 floats): index of the waypoint steered to, has a leg start (1/0), the leg
start (north, east, m); the route is done when the index reaches the number of waypoints.
Parameters ``pa`` (7): max speed, max reverse speed (m/s), r_max (rad/s), heading gain (1/s),
cruise speed (m/s), look-ahead l (m), acceptance radius (m).
"""

from __future__ import annotations

import math

from numba import njit

from ..core.rotations import hypot, wrap
from ._compiled import look_ahead_point


@njit(cache=True)
def _pursuit(x, y, psi, route, n, rs, lookahead, accept):
    """Pure pursuit on the current leg: (psi_d rad, cross-track m); psi_d NaN once the route is done."""
    while True:
        if rs[1] == 0.0:
            rs[1] = 1.0
            rs[2] = x
            rs[3] = y
        k = int(rs[0])
        b0, b1 = route[2 * k], route[2 * k + 1]
        a0, a1 = rs[2], rs[3]
        leg = math.hypot(b0 - a0, b1 - a1)
        dist = math.hypot(b0 - x, b1 - y)
        along = 0.0
        if leg > 1e-9:
            L = hypot(b0 - a0, b1 - a1)
            t0 = (b0 - a0) / L
            t1 = (b1 - a1) / L
            along = (x - a0) * t0 + (y - a1) * t1
        if dist < accept or leg <= 1e-9 or along > leg:
            rs[2] = b0
            rs[3] = b1
            rs[0] = k + 1
            if k + 1 >= n:
                return math.nan, 0.0
            continue
        last = k == n - 1
        e, g0, g1 = look_ahead_point(x, y, a0, a1, b0, b1, lookahead, last)
        return math.atan2(g1 - y, g0 - x), e


@njit(cache=True)
def route_pilot_law(remote, surge, yaw, x, y, psi, route, n, rs, pa):
    """``(u_d m/s, r_d rad/s, psi_d rad, cross-track m)`` of the route pilot; ``rs`` updated in place."""
    surge = max(-1.0, min(1.0, surge))
    yaw = max(-1.0, min(1.0, yaw))
    r_max = pa[2]
    psi_d = math.nan
    xte = 0.0
    if remote:
        u_d = surge * (pa[0] if surge >= 0 else pa[1])
        r_d = yaw * r_max
    elif rs[0] >= n:
        u_d, r_d = 0.0, 0.0
    else:
        psi_d, xte = _pursuit(x, y, psi, route, n, rs, pa[5], pa[6])
        if rs[0] >= n:
            u_d, r_d = 0.0, 0.0
        else:
            err = wrap(psi_d - psi)
            r_d = max(-r_max, min(r_max, pa[3] * err))
            u_d = pa[4] * max(0.0, math.cos(err))
    return u_d, r_d, (psi_d if math.isfinite(psi_d) else psi), xte


@njit(cache=True)
def route_pilot_step(t, sig, sl, st, pa):
    """:class:`oceangnc.guidance.route_pilot.RoutePilot`.

    slots: usv.psi, usv.x, usv.y, console.mode (code 0: remote; -1: absent, the default),
    joystick.surge, joystick.yaw (absent: 0), ?gps.x, ?gps.y | usv.u_d, usv.r_d, guidance.psi_d,
    guidance.cross_track, guidance.wp_index.
    state: the route state (module docstring). params: the law's 7, the default mode's code, n,
    the route (2n).
    """
    code = sig[sl[3]] if sig[sl[3]] >= 0.0 else pa[7]
    surge = sig[sl[4]]
    yaw = sig[sl[5]]
    x = sig[sl[6]] if sl[6] >= 0 else sig[sl[1]]
    y = sig[sl[7]] if sl[7] >= 0 else sig[sl[2]]
    n = int(pa[8])
    u_d, r_d, psi_d, xte = route_pilot_law(code == 0.0, surge, yaw, x, y, sig[sl[0]], pa[9 : 9 + 2 * n], n, st, pa)
    sig[sl[8]] = u_d
    sig[sl[9]] = r_d
    sig[sl[10]] = psi_d
    sig[sl[11]] = xte
    sig[sl[12]] = st[0]
