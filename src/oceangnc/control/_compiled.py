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

import numpy as np
from numba import njit

from ..sensors.filters import lowpass_step
from .pid import pid_integral, pid_output

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
    v = pid_output(pa[q], pa[q + 2], st[o], e, e_dot, ff)
    u = min(u_max, max(u_min, v))
    st[o] = pid_integral(st[o], dt, pa[q + 1], pa[q + 5], e, u, v)
    st[o + 3] = v
    st[o + 4] = u
    return u


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
        st[18] = lowpass_step(st[18], pa[19], d)
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
    out = (u1, u1, ub, psi_d, loop)
    for i in range(5):
        sig[sl[8 + i]] = out[i]


def arr(values) -> np.ndarray:
    return np.array([float(v) for v in values], dtype=np.float64)
