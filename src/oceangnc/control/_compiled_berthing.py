"""Compiled form of the berthing chain's scripted pilot (001).

Kernel convention: :mod:`oceangnc.control._compiled` (the pilot and the joystick also take their
block's ``numpy.random.Generator``). The arithmetic follows the Python blocks operation for
operation (:mod:`oceangnc.guidance.scripted_pilot`, :mod:`oceangnc.control.joystick`,
:mod:`oceangnc.control.berthing`).
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit

from ..core.rotations import wrap
from ..sensors.filters import gauss_markov, ring_slot

# pilot parameter layout
_PP = 32  # route data start


@njit(cache=True)
def _project(pa, n, e):
    """Route.project: (s, cross) of (n, e) on the route stored in pa (see pilot_step)."""
    npt = int(pa[_PP - 1])
    nseg = npt - 1
    op = _PP
    ol = op + 2 * npt
    od = ol + nseg
    os_ = od + 2 * nseg
    best = -1
    bd = 0.0
    bt = 0.0
    bf0 = 0.0
    bf1 = 0.0
    for i in range(nseg):
        r0 = n - pa[op + 2 * i]
        r1 = e - pa[op + 2 * i + 1]
        d0 = pa[od + 2 * i]
        d1 = pa[od + 2 * i + 1]
        t = r0 * d0 + r1 * d1
        L = pa[ol + i]
        tc = min(max(t, 0.0), L)
        if i == nseg - 1:
            tc = max(0.0, t) if nseg > 1 else t
        if i == 0 and nseg > 1:
            tc = min(t, L)
        f0 = pa[op + 2 * i] + tc * d0
        f1 = pa[op + 2 * i + 1] + tc * d1
        dist = math.hypot(n - f0, e - f1)
        if best < 0 or dist < bd:
            best = i
            bd = dist
            bt = tc
            bf0 = f0
            bf1 = f1
    i = best
    cross = pa[od + 2 * i] * (e - bf1) - pa[od + 2 * i + 1] * (n - bf0)
    return pa[os_ + i] + bt, cross


@njit(cache=True)
def _point_at(pa, s):
    npt = int(pa[_PP - 1])
    nseg = npt - 1
    op = _PP
    od = op + 2 * npt + nseg
    os_ = od + 2 * nseg
    length = pa[_PP - 2]
    if s >= length:
        j = nseg - 1
        return pa[op + 2 * (npt - 1)] + (s - length) * pa[od + 2 * j], pa[op + 2 * (npt - 1) + 1] + (s - length) * pa[
            od + 2 * j + 1
        ]
    if s <= 0:
        return pa[op] + s * pa[od], pa[op + 1] + s * pa[od + 1]
    i = -1
    for k in range(npt):
        if pa[os_ + k] <= s:
            i = k
    return pa[op + 2 * i] + (s - pa[os_ + i]) * pa[od + 2 * i], pa[op + 2 * i + 1] + (s - pa[os_ + i]) * pa[
        od + 2 * i + 1
    ]


@njit(cache=True)
def _move(pa, cur, want):
    want = max(-1.0, min(1.0, want))
    if pa[20] > 0:
        want = np.rint(want / pa[20]) * pa[20]
    step = max(-pa[21], min(pa[21], want - cur))
    return max(-1.0, min(1.0, cur + step))


@njit(cache=True)
def pilot_step(t, sig, sl, st, pa, rng):
    """:class:`oceangnc.guidance.scripted_pilot.ScriptedPilot`.

    slots: ship.x, ship.y, ship.psi, ship.u, ship.r, ship.v | joystick.surge, joystick.yaw,
    pilot.u_target, pilot.psi_des, pilot.cross_track, pilot.s_remaining, pilot.done, _stop.
    state: stick_u, stick_r, done, err (3), memory count, head, capacity, then (t, 6 obs) x capacity.
    params: see ``ScriptedPilot.compiled``; route from index 32 (points, lengths, directions, s0).
    """
    a = math.exp(-pa[0] / pa[1])
    for i in range(3):
        st[3 + i] = gauss_markov(st[3 + i], a, pa[2 + i], rng.standard_normal())
    x = sig[sl[0]]
    y = sig[sl[1]]
    obs_psi = sig[sl[2]] + st[3]
    obs_u = sig[sl[3]] + st[4]
    obs_r = sig[sl[4]] + st[5]
    obs_v = sig[sl[5]]
    cnt = int(st[6])
    head = int(st[7])
    cap = int(st[8])
    o = 9
    j, cnt, head = ring_slot(cnt, head, cap)
    st[o + 7 * j] = t
    st[o + 7 * j + 1] = x
    st[o + 7 * j + 2] = y
    st[o + 7 * j + 3] = obs_psi
    st[o + 7 * j + 4] = obs_u
    st[o + 7 * j + 5] = obs_r
    st[o + 7 * j + 6] = obs_v
    delay = pa[5]
    while cnt > 1 and st[o + 7 * ((head + 1) % cap)] <= t - delay + 1e-9:
        head = (head + 1) % cap
        cnt -= 1
    st[6] = cnt
    st[7] = head
    b = o + 7 * head
    n, e, psi, u, r, v = st[b + 1], st[b + 2], st[b + 3], st[b + 4], st[b + 5], st[b + 6]
    # _decide
    length = pa[_PP - 2]
    stop_at_end = pa[7] != 0.0
    s, cross = _project(pa, n, e)
    look = pa[6]
    if stop_at_end:
        look = min(look, max(pa[8], 50.0 + 0.5 * (length - s)))
    aim0, aim1 = _point_at(pa, s + look)
    psi_des = math.atan2(aim1 - e, aim0 - n)
    course = psi + math.atan2(v, u) if pa[9] != 0.0 and math.hypot(u, v) > 0.1 else psi
    e_psi = wrap(psi_des - course)
    s_rem = length - s
    u_cruise = pa[10]
    if stop_at_end:
        if s_rem > 0:
            u_t = min(u_cruise, math.sqrt(2 * pa[11] * s_rem), pa[12] * s_rem)
        else:
            u_t = max(-0.2, pa[12] * s_rem)
    else:
        u_t = u_cruise
    if pa[13] == 0.0:  # open loop
        want_u = u_t / (pa[14] * pa[15]) + pa[16] * (u_t - u)
        want_r = pa[17] * (pa[18] * e_psi - r)
    else:
        db = pa[19]
        want_u = (u_t / pa[22] if u_t >= 0 else u_t / pa[23]) + pa[24] * (u_t - u)
        want_u = math.copysign(db + (1 - db) * abs(want_u), want_u) if abs(want_u) > 1e-3 else 0.0
        want_r = pa[18] * e_psi / pa[25]
    st[0] = _move(pa, st[0], want_u)
    st[1] = _move(pa, st[1], want_r)
    true_s, true_cross = _project(pa, x, y)
    rem = length - true_s
    if stop_at_end:
        if abs(rem) < 3.0 and abs(sig[sl[3]]) < 0.03 and abs(sig[sl[5]]) < 0.05:
            st[2] = 1.0
            st[0] = 0.0
            st[1] = 0.0
    elif rem <= 0.0:
        st[2] = 1.0
    sig[sl[6]] = st[0]
    sig[sl[7]] = st[1]
    sig[sl[8]] = u_t
    sig[sl[9]] = psi_des
    sig[sl[10]] = true_cross
    sig[sl[11]] = rem
    sig[sl[12]] = st[2]
    if st[2] != 0.0 and pa[26] != 0.0:
        sig[sl[13]] = 1.0
