"""Compiled forms of the controllers (issue 19, the fused closed loop; see :mod:`oceangnc.core.fused`).

Each kernel is ``kernel(t, sig, sl, st, pa)``: ``sig`` the float64 signal array of the fused loop,
``sl`` the slot numbers of the signals it reads and writes (in the order its block's ``compiled``
method lists them), ``st`` its state and ``pa`` its parameters (flat float64 arrays). The kernels
repeat the Python blocks' arithmetic operation for operation, so both paths give the same numbers
(tested in ``tests/test_fused.py``). A slot of -1 is an optional input nobody writes: the Python
block's default is used.

PID state layout (5 floats): integral, e_prev, has_e_prev, v, u; parameters (6): kp, ki, kd,
u_min, u_max, kw (the anti-windup PID of 003 eq. 3.10, :class:`oceangnc.control.pid.PID`).
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit

PID_STATE = 5
PID_PARAMS = 6


def pid_state(pid) -> list[float]:
    """The 5-float state of a :class:`~oceangnc.control.pid.PID`."""
    has = pid._e_prev is not None
    return [pid.integral, pid._e_prev if has else 0.0, 1.0 if has else 0.0, pid.v, pid.u]


def pid_params(pid) -> list[float]:
    """The 6-float parameters of a :class:`~oceangnc.control.pid.PID`."""
    return [pid.kp, pid.ki, pid.kd, pid.u_min, pid.u_max, pid.kw]


@njit(cache=True)
def pid_step(st, o, pa, q, e, dt, e_dot, has_e_dot, ff, u_min, u_max):
    """:meth:`oceangnc.control.pid.PID.step` on state ``st[o:o+5]``, gains ``pa[q:q+6]``, limits given."""
    if not has_e_dot:
        e_dot = 0.0 if st[o + 2] == 0.0 else (e - st[o + 1]) / dt
    st[o + 1] = e
    st[o + 2] = 1.0
    v = pa[q] * e + st[o] + pa[q + 2] * e_dot + ff
    u = min(u_max, max(u_min, v))
    st[o] += dt * pa[q + 1] * (e + pa[q + 5] * (u - v))
    st[o + 3] = v
    st[o + 4] = u
    return u


@njit(cache=True)
def _wrap(a):
    return (a + math.pi) % (2.0 * math.pi) - math.pi


@njit(cache=True)
def usv_control_step(t, sig, sl, st, pa):
    """:class:`oceangnc.control.usv_control.USVController` (autopilot mode).

    slots: u, psi, r, ?usv.u_d, ?guidance.psi_d | thrust_port_cmd, thrust_stbd_cmd, usv_ctrl.u_d,
    usv_ctrl.psi_d, usv_ctrl.u_speed, usv_ctrl.u_heading. state: speed PID, heading PID.
    params: speed PID, heading PID, h, u_d default, t_max, t_min, 0.5 d11 (or 0: no feed-forward).
    """
    h = pa[12]
    u = sig[sl[0]]
    psi = sig[sl[1]]
    r = sig[sl[2]]
    u_d = sig[sl[3]] if sl[3] >= 0 else pa[13]
    psi_d = sig[sl[4]] if sl[4] >= 0 else psi
    u_h = pid_step(st, 5, pa, 6, _wrap(psi_d - psi), h, -r, True, 0.0, pa[9], pa[10])
    t_max = pa[14]
    t_min = pa[15]
    s_max = max(0.0, t_max - abs(u_h))
    s_min = min(0.0, t_min + abs(u_h))
    ff = pa[16] * u_d
    u_s = pid_step(st, 0, pa, 0, u_d - u, h, 0.0, False, ff, s_min, s_max)
    sig[sl[5]] = u_s + u_h
    sig[sl[6]] = u_s - u_h
    sig[sl[7]] = u_d
    sig[sl[8]] = psi_d
    sig[sl[9]] = u_s
    sig[sl[10]] = u_h


@njit(cache=True)
def uuv_pid_step(t, sig, sl, st, pa):
    """:class:`oceangnc.control.uuv_control.UUVPIDController`.

    slots: lf.e_x, r_uuv, lf.outside, lf.rel_heading_err, r_usv, psi_usv, lf.los_err, lf.los |
    uuv.thrust_port_cmd, uuv.thrust_stbd_cmd, uuv.thrust_bow_cmd, uuv_ctrl.psi_d, uuv_ctrl.loop.
    state: pos PID, ang PID, los PID, active loop, e1_prev, has_e1_prev, low-pass y, has_y.
    params: pos, ang, los PIDs, h, low-pass a, mode (1: relative-angle only).
    """
    h = pa[18]
    e1 = sig[sl[0]]
    d = 0.0 if st[17] == 0.0 else (e1 - st[16]) / h
    st[16] = e1
    st[17] = 1.0
    if st[19] == 0.0:
        st[18] = d
        st[19] = 1.0
    else:
        st[18] = st[18] + pa[19] * (d - st[18])
    u1 = pid_step(st, 0, pa, 0, e1, h, st[18], True, 0.0, pa[3], pa[4])
    r_uuv = sig[sl[1]]
    outside = sig[sl[2]] > 0.5 and pa[20] == 0.0
    loop = 3.0 if outside else 2.0
    if loop != st[15]:
        if loop == 3.0:
            st[10] = st[5]
            st[12] = 0.0
        else:
            st[5] = st[10]
            st[7] = 0.0
        st[15] = loop
    if loop == 2.0:
        ub = pid_step(st, 5, pa, 6, sig[sl[3]], h, sig[sl[4]] - r_uuv, True, 0.0, pa[9], pa[10])
        psi_d = sig[sl[5]]
    else:
        ub = pid_step(st, 10, pa, 12, sig[sl[6]], h, -r_uuv, True, 0.0, pa[15], pa[16])
        psi_d = sig[sl[7]]
    sig[sl[8]] = u1
    sig[sl[9]] = u1
    sig[sl[10]] = ub
    sig[sl[11]] = psi_d
    sig[sl[12]] = loop


@njit(cache=True)
def backstepping_step(t, sig, sl, st, pa):
    """:class:`oceangnc.control.backstepping.UUVBackstepping` (errors + control_law, 003 eq. 3.24-3.41).

    slots: xl, yl, psil, ul, vl, rl, xf, yf, psif, uf, vf, rf | uuv.thrust_port_cmd,
    uuv.thrust_stbd_cmd, uuv.thrust_bow_cmd, uuv_bs.V, uuv_bs.Vdot, uuv_bs.eps1, uuv_bs.eps2,
    uuv_bs.tau_u, uuv_bs.tau_r, uuv_ctrl.psi_d.
    state: prev (3), has_prev, acc (3). params: period, a_lp, cx, cy, h, k1, k2, k6, k7, m11, m22,
    m33, Xu, Yv, Nr, Xuu, Yvv, Nrr, bow_arm, sway_from_bow, hi, lo.
    """
    g0 = sig[sl[0]] if sl[0] >= 0 else 0.0
    xl = g0
    yl = sig[sl[1]] if sl[1] >= 0 else 0.0
    psil = sig[sl[2]] if sl[2] >= 0 else 0.0
    ul = sig[sl[3]] if sl[3] >= 0 else 0.0
    vl = sig[sl[4]] if sl[4] >= 0 else 0.0
    rl = sig[sl[5]] if sl[5] >= 0 else 0.0
    xf = sig[sl[6]] if sl[6] >= 0 else 0.0
    yf = sig[sl[7]] if sl[7] >= 0 else 0.0
    psif = sig[sl[8]] if sl[8] >= 0 else 0.0
    u = sig[sl[9]] if sl[9] >= 0 else 0.0
    v = sig[sl[10]] if sl[10] >= 0 else 0.0
    r = sig[sl[11]] if sl[11] >= 0 else 0.0
    period = pa[0]
    if st[3] != 0.0:
        d = (ul - st[0]) / period
        st[4] += pa[1] * (d - st[4])
        d = (vl - st[1]) / period
        st[5] += pa[1] * (d - st[5])
        d = (rl - st[2]) / period
        st[6] += pa[1] * (d - st[6])
    st[0] = ul
    st[1] = vl
    st[2] = rl
    st[3] = 1.0
    cx = pa[2]
    cy = pa[3]
    h = pa[4]
    # errors()
    cl, sl_ = math.cos(psil), math.sin(psil)
    tn = xl + cl * cx - sl_ * cy
    te = yl + sl_ * cx + cl * cy
    cf, sf = math.cos(psif), math.sin(psif)
    hn = xf + h * cf
    he = yf + h * sf
    dn, de = hn - tn, he - te
    e_psi = (psil - psif + math.pi) % (2 * math.pi) - math.pi
    eps1 = cf * dn + sf * de
    eps2 = -sf * dn + cf * de
    # control_law()
    k1, k2, k6, k7 = pa[5], pa[6], pa[7], pa[8]
    m11, m22, m33 = pa[9], pa[10], pa[11]
    dul, dvl, drl = st[4], st[5], st[6]
    cs, sn = math.cos(e_psi), math.sin(e_psi)
    z1 = -ul + rl * cy
    z2 = -vl - rl * cx
    dz1 = -dul + drl * cy
    dz2 = -dvl - drl * cx
    a = z1 * cs - z2 * sn
    b = z1 * sn + z2 * cs
    de_psi = rl - r
    da = dz1 * cs - dz2 * sn - b * de_psi
    db = dz1 * sn + dz2 * cs + a * de_psi
    deps1 = u + a + r * eps2
    deps2 = v + h * r + b - r * eps1
    alpha_u = -k1 * eps1 - a
    alpha_r = (-k2 * eps2 - b - v) / h
    u_e = u - alpha_u
    r_e = r - alpha_r
    d11 = -pa[12] - pa[15] * abs(u)
    d22 = -pa[13] - pa[16] * abs(v)
    d33 = -pa[14] - pa[17] * abs(r)
    dalpha_u = -k1 * deps1 - da
    tau_u = m11 * (dalpha_u - k6 * u_e - eps1) - m22 * v * r + d11 * u
    dv0 = (-m11 * u * r - d22 * v) / m22
    dalpha_r0 = (-k2 * deps2 - db - dv0) / h
    cb = pa[19] / (h * pa[18] * m22)
    tau_r = (dalpha_r0 - k7 * r_e - h * eps2 + ((m22 - m11) * u * v + d33 * r) / m33) / (1.0 / m33 + cb)
    V = 0.5 * (eps1 * eps1 + eps2 * eps2 + u_e * u_e + r_e * r_e)
    Vdot = -k1 * eps1 * eps1 - k2 * eps2 * eps2 - k6 * u_e * u_e - k7 * r_e * r_e
    hi, lo = pa[20], pa[21]
    ts = min(hi, max(lo, 0.5 * tau_u))
    tb = min(hi, max(lo, tau_r / pa[18]))
    sig[sl[12]] = ts
    sig[sl[13]] = ts
    sig[sl[14]] = tb
    sig[sl[15]] = V
    sig[sl[16]] = Vdot
    sig[sl[17]] = eps1
    sig[sl[18]] = eps2
    sig[sl[19]] = tau_u
    sig[sl[20]] = tau_r
    sig[sl[21]] = psil


def arr(values) -> np.ndarray:
    return np.array([float(v) for v in values], dtype=np.float64)


@njit(cache=True)
def tow_straight_step(t, sig, sl, st, pa):
    """:class:`oceangnc.scenarios.cable.TowStraightControl` (003 ch. 4 a).

    slots: usv.u, usv.psi, usv.r, uuv.u, uuv.psi, uuv.r | usv.thrust_port_cmd, usv.thrust_stbd_cmd,
    uuv.thrust_port_cmd, uuv.thrust_stbd_cmd, uuv.thrust_bow_cmd. state: 4 PIDs (USV speed, USV
    heading, UUV speed, UUV heading). params: the 4 PIDs, h, psi_d, start_s, USV speed, UUV speed,
    USV feed-forward, UUV feed-forward.
    """
    h = pa[24]
    psi_d = pa[25]
    if t < pa[26]:
        for i in range(5):
            sig[sl[6 + i]] = 0.0
        return
    tot = pid_step(st, 0, pa, 0, pa[27] - sig[sl[0]], h, 0.0, False, pa[29], pa[3], pa[4])
    e = (psi_d - sig[sl[1]] + math.pi) % (2 * math.pi) - math.pi
    dif = pid_step(st, 5, pa, 6, e, h, -sig[sl[2]], True, 0.0, pa[9], pa[10])
    sig[sl[6]] = 0.5 * tot + 0.5 * dif
    sig[sl[7]] = 0.5 * tot - 0.5 * dif
    totu = pid_step(st, 10, pa, 12, pa[28] - sig[sl[3]], h, 0.0, False, pa[30], pa[15], pa[16])
    sig[sl[8]] = 0.5 * totu
    sig[sl[9]] = 0.5 * totu
    eu = (psi_d - sig[sl[4]] + math.pi) % (2 * math.pi) - math.pi
    sig[sl[10]] = pid_step(st, 15, pa, 18, eu, h, -sig[sl[5]], True, 0.0, pa[21], pa[22])
