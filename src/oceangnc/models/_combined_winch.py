"""The winch inside the combined plant: drum speed command, drum states and re-meshing.

See :mod:`oceangnc.models.winch` for the model; these are the compiled pieces the combined plant's
right-hand side (:func:`_winch_rhs`), its outputs (:func:`winch_command`) and its IMEX integrator
(:func:`remesh`, after each step) call.
"""

from __future__ import annotations

import math

from numba import njit

from ._combined_layout import (
    H_N,
    H_L0,
    H_PO,
    H_VO,
    H_WO,
    H_NMAX,
    H_WV,
    H_WA,
    H_WT,
    H_WCAP,
    H_WMIN,
    H_WTAU,
    P_SCR,
    _ends,
)


@njit(cache=True)
def winch_command(x, u, p, ttop):
    """Drum speed the winch tracks (m/s, + paying out): the command ``u[9]`` saturated to +-v_max;
    paying out at v_max while the top tension exceeds the limit (the winch renders rather than exceed
    it); zero at the drum's capacity (payout) or at the minimum length (haul-in)."""
    vmax = p[H_WV]
    sc = min(max(u[9], -vmax), vmax)
    if ttop > p[H_WT]:
        sc = vmax
    L = x[int(p[H_WO])]
    if L >= p[H_WCAP] and sc > 0.0:
        sc = 0.0
    if L <= p[H_WMIN] and sc < 0.0:
        sc = 0.0
    return sc


@njit(cache=True)
def _winch_rhs(x, u, p, wo, F, out):
    """Winch states: dL/dt = s (paid-out unstretched length), ds/dt = (s_c - s) / tau clipped to
    +-a_max (first-order speed loop with an acceleration limit)."""
    ttop = math.sqrt(F[0] ** 2 + F[1] ** 2 + F[2] ** 2)
    sc = winch_command(x, u, p, ttop)
    s = x[wo + 1]
    acc = (sc - s) / p[H_WTAU]
    amax = p[H_WA]
    out[wo] = s
    out[wo + 1] = min(max(acc, -amax), amax)


@njit(cache=True)
def remesh(x, p):
    """Winch limits and node insertion/removal after a step (see :mod:`oceangnc.models.winch`).

    Clamps the paid-out length to [min_length, capacity] (stopping the drum there), then inserts a node
    when the top segment is longer than 1.5 l0 or removes node 1 when it is shorter than 0.5 l0. Node
    slots are shifted in place (O(n), a few times per metre of payout); returns +1 (inserted), -1
    (removed) or 0.
    """
    wo = int(p[H_WO])
    if x[wo] >= p[H_WCAP]:
        x[wo] = p[H_WCAP]
        x[wo + 1] = min(x[wo + 1], 0.0)
    if x[wo] <= p[H_WMIN]:
        x[wo] = p[H_WMIN]
        x[wo + 1] = max(x[wo + 1], 0.0)
    n = int(p[H_N])
    l0 = p[H_L0]
    lt = x[wo] - (n - 1) * l0
    po = int(p[H_PO])
    vo = int(p[H_VO])
    if lt > 1.5 * l0 and n < int(p[H_NMAX]):
        m = 3 * (n + 1)
        pos = p[P_SCR : P_SCR + m]
        vel = p[P_SCR + m : P_SCR + 2 * m]
        _ends(x, p, n, pos, vel)  # the ends only (node 0 and the tow point)
        for k in range(3 * (n - 1) - 1, -1, -1):  # node i -> i + 1
            x[po + 3 + k] = x[po + k]
            x[vo + 3 + k] = x[vo + k]
        if n >= 2:
            r1x, r1y, r1z = x[po + 3], x[po + 4], x[po + 5]
            v1x, v1y, v1z = x[vo + 3], x[vo + 4], x[vo + 5]
        else:
            b = 3 * n
            r1x, r1y, r1z = pos[b], pos[b + 1], pos[b + 2]
            v1x, v1y, v1z = vel[b], vel[b + 1], vel[b + 2]
        f = (lt - l0) / lt  # the new node's fraction of the way from the sheave
        x[po] = pos[0] + f * (r1x - pos[0])
        x[po + 1] = pos[1] + f * (r1y - pos[1])
        x[po + 2] = pos[2] + f * (r1z - pos[2])
        x[vo] = vel[0] + f * (v1x - vel[0])
        x[vo + 1] = vel[1] + f * (v1y - vel[1])
        x[vo + 2] = vel[2] + f * (v1z - vel[2])
        p[H_N] = n + 1
        return 1
    if lt < 0.5 * l0 and n > 1:
        if n >= 3:  # node 2 takes half of the top segment's mass and its momentum
            m2 = 1.0  # (in units of l0's node mass; all node masses scale with length alike)
            mt = 0.5 * lt / l0
            w = 1.0 / (m2 + mt)
            for a in range(3):
                x[vo + 3 + a] = (m2 * x[vo + 3 + a] + mt * x[vo + a]) * w
        for k in range(3 * (n - 2)):  # node i + 1 -> i
            x[po + k] = x[po + 3 + k]
            x[vo + k] = x[vo + 3 + k]
        for a in range(3):
            x[po + 3 * (n - 2) + a] = 0.0
            x[vo + 3 * (n - 2) + a] = 0.0
        p[H_N] = n - 1
        return -1
    return 0
