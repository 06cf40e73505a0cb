"""Compiled forms of the tow blocks (issue 19, the fused closed loop; see :mod:`oceangnc.core.fused`).

Kernels ``kernel(t, sig, sl, st, pa)`` of :class:`oceangnc.control.tow.TowStraightControl`,
:class:`oceangnc.control.tow.UUVFollow`, :class:`oceangnc.control.winch.WinchDepthController` and
:class:`oceangnc.control.actuators.ThrustersOff`, in the convention of
:mod:`oceangnc.control._compiled` (``sig`` the fused loop's signal array, ``sl`` slot numbers in
the order the block's ``compiled`` method lists them, ``st``/``pa`` flat float64 state and
parameters). The PIDs are :func:`oceangnc.control._compiled.pid_step` (state 5 floats, parameters
6: the layout of :func:`~oceangnc.control._compiled.pid_state` / ``pid_params``).

The scalar laws that are not a PID have one home here and the Python blocks call them too
(issue 17): :func:`profile_reference` (the winch's moving depth target and its rate),
:func:`tension_payout` (the tension override of the winch command) and :func:`bearing_to`
(the UUV's heading toward the USV), :func:`drag_feedforward` (the UUV's surge feed-forward).
"""

from __future__ import annotations

import math

from numba import njit

from ..core.rotations import wrap
from ._compiled import pid_step
from .usv_control import mix


@njit(cache=True)
def profile_reference(t, pt, pz):
    """(z, dz/dt) of the piecewise-linear profile through ``(pt[i], pz[i])`` at ``t`` (m, m/s).

    ``z`` is ``numpy.interp(t, pt, pz)`` operation for operation (held at the end values outside
    the breakpoints); the rate is the slope of the segment containing ``t`` (0 outside, and at a
    breakpoint the slope of the segment that starts there): the feed-forward of the depth loop
    (:class:`oceangnc.control.winch.WinchDepthController`).
    """
    n = pt.size
    # i = numpy.searchsorted(pt, t, side="right"): breakpoints at or before t
    lo, hi = 0, n
    while lo < hi:
        mid = (lo + hi) // 2
        if pt[mid] <= t:
            lo = mid + 1
        else:
            hi = mid
    i = lo
    if t < pt[0]:
        z = pz[0]
    elif t > pt[n - 1] or t == pt[n - 1]:
        z = pz[n - 1]
    else:
        j = i - 1
        if t == pt[j]:
            z = pz[j]
        else:
            slope = (pz[j + 1] - pz[j]) / (pt[j + 1] - pt[j])
            z = slope * (t - pt[j]) + pz[j]
            if math.isnan(z):
                z = slope * (t - pt[j + 1]) + pz[j + 1]
                if math.isnan(z) and pz[j] == pz[j + 1]:
                    z = pz[j]
    rate = 0.0
    if 0 < i < n:
        rate = (pz[i] - pz[i - 1]) / (pt[i] - pt[i - 1])
    return z, rate


@njit(cache=True)
def tension_payout(s, tension, t_margin, gain, s_max):
    """Winch command ``s`` (m/s) raised to at least ``min(s_max, gain (T - T_margin))`` when the top
    tension ``T`` (N) is above ``T_margin``: pay out rather than drive the tension to the limit."""
    if tension > t_margin:
        s = max(s, min(s_max, gain * (tension - t_margin)))
    return s


@njit(cache=True)
def bearing_to(n_to, e_to, n_from, e_from):
    """Bearing (rad) from point ``from`` to point ``to`` (NED north, east in m)."""
    return math.atan2(e_to - e_from, n_to - n_from)


@njit(cache=True)
def drag_feedforward(x_uu, u_d):
    """Surge thrust (N) that balances the UUV's axial quadratic drag at speed ``u_d`` (m/s):
    -X_u|u| u_d |u_d|, ``x_uu`` = X_u|u| (kg/m, negative)."""
    return -x_uu * u_d * abs(u_d)


@njit(cache=True)
def _uuv_loops(sig, sl, i, o, st, so, pa, q, u_d, psi_d, h, x_uu):
    """:func:`oceangnc.control.tow.uuv_loops_step`. Reads ``sl[i:i+3]`` (uuv.u, uuv.psi, uuv.r), writes
    ``sl[o:o+3]`` (uuv.thrust_{port,stbd,bow}_cmd); speed PID at ``st[so]``/``pa[q]``, heading PID
    at ``st[so+5]``/``pa[q+6]``; ``x_uu`` the UUV's total axial quadratic drag X_u|u| (kg/m)."""
    ff = drag_feedforward(x_uu, u_d)
    tot = pid_step(st, so, pa, q, u_d - sig[sl[i]], h, 0.0, False, ff, pa[q + 3], pa[q + 4])
    sig[sl[o]] = 0.5 * tot
    sig[sl[o + 1]] = 0.5 * tot
    e = wrap(psi_d - sig[sl[i + 1]])
    sig[sl[o + 2]] = pid_step(st, so + 5, pa, q + 6, e, h, -sig[sl[i + 2]], True, 0.0, pa[q + 9], pa[q + 10])


@njit(cache=True)
def tow_straight_step(t, sig, sl, st, pa):
    """:class:`oceangnc.control.tow.TowStraightControl` (003 ch. 4 a).

    slots: usv.u, usv.psi, usv.r, uuv.u, uuv.psi, uuv.r | usv.thrust_port_cmd, usv.thrust_stbd_cmd,
    uuv.thrust_port_cmd, uuv.thrust_stbd_cmd, uuv.thrust_bow_cmd. state: 4 PIDs (USV speed, USV
    heading, UUV speed, UUV heading). params: the 4 PIDs, h, psi_d, start_s, USV speed command,
    UUV speed command, d11 of the USV, X_u|u| of the UUV.
    """
    h = pa[24]
    psi_d = pa[25]
    if t < pa[26]:
        for i in range(6, 11):
            sig[sl[i]] = 0.0
        return
    u_d = pa[27]
    ff = pa[29] * u_d
    tot = pid_step(st, 0, pa, 0, u_d - sig[sl[0]], h, 0.0, False, ff, pa[3], pa[4])
    e = wrap(psi_d - sig[sl[1]])
    dif = pid_step(st, 5, pa, 6, e, h, -sig[sl[2]], True, 0.0, pa[9], pa[10])
    sig[sl[6]], sig[sl[7]] = mix(0.5 * tot, 0.5 * dif)  # the one mixer (003 eq. 3.11)
    _uuv_loops(sig, sl, 3, 8, st, 10, pa, 12, pa[28], psi_d, h, pa[30])


@njit(cache=True)
def uuv_follow_step(t, sig, sl, st, pa):
    """:class:`oceangnc.control.tow.UUVFollow`: heading toward the USV, surge speed held.

    slots: usv.x, usv.y, uuv.x, uuv.y, uuv.u, uuv.psi, uuv.r | uuv.thrust_port_cmd,
    uuv.thrust_stbd_cmd, uuv.thrust_bow_cmd. state: 2 PIDs (speed, heading). params: the 2 PIDs,
    speed command, h, X_u|u| of the UUV.
    """
    u_d = pa[12]
    if u_d <= 0.0:
        sig[sl[7]] = 0.0
        sig[sl[8]] = 0.0
        sig[sl[9]] = 0.0
        return
    psi_d = bearing_to(sig[sl[0]], sig[sl[1]], sig[sl[2]], sig[sl[3]])
    _uuv_loops(sig, sl, 4, 7, st, 0, pa, 0, u_d, psi_d, pa[13], pa[14])


@njit(cache=True)
def winch_depth_step(t, sig, sl, st, pa):
    """:class:`oceangnc.control.winch.WinchDepthController`.

    slots: measurement (uuv.z or uuv.altitude), ?cable.top_tension | winch.speed_cmd, winch.target,
    winch.error. state: the PID. params: the PID, period, mode (0 depth, 1 altitude), tension
    margin (N), tension gain, speed_max, constant target, breakpoints count m, then m times t and
    m values z of the profile (m = 0: the constant target).
    """
    m = int(pa[12])
    if m > 0:
        ref, rate = profile_reference(t, pa[13 : 13 + m], pa[13 + m : 13 + 2 * m])
    else:
        ref, rate = pa[11], 0.0
    y = sig[sl[0]]
    if not math.isfinite(y):
        sig[sl[2]] = 0.0
        sig[sl[3]] = ref
        sig[sl[4]] = 0.0
        return
    depth = pa[7] == 0.0
    e = (ref - y) if depth else (y - ref)
    s = pid_step(st, 0, pa, 0, e, pa[6], 0.0, False, rate if depth else 0.0, pa[3], pa[4])
    tension = sig[sl[1]] if sl[1] >= 0 else 0.0
    sig[sl[2]] = tension_payout(s, tension, pa[8], pa[9], pa[10])
    sig[sl[3]] = ref
    sig[sl[4]] = e
