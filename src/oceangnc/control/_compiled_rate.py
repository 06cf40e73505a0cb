"""Compiled speed / yaw-rate loops of the console's USV (003 eq. 3.10-3.11, ch. 5.4) for the fused
loop (issue 19; kernel convention and the PID kernel: :mod:`oceangnc.control._compiled`)."""

from __future__ import annotations

from numba import njit

from ._compiled import PID_STATE, pid_step


@njit(cache=True)
def _clear(st, o):
    """:meth:`oceangnc.control.pid.PID.reset`: integral, derivative memory and outputs to zero."""
    for i in range(PID_STATE):
        st[o + i] = 0.0


@njit(cache=True)
def rate_control_step(t, sig, sl, st, pa):
    """:class:`oceangnc.control.usv_control.USVRateController`.

    slots: usv.u_d, usv.r_d, usv.u, usv.r, console.mode (code 0: remote; -1: absent, the default),
    console.loop (code 1: open), joystick.surge, joystick.yaw, _estop | usv.thrust_port_cmd,
    usv.thrust_stbd_cmd (external signals absent from the bus read as 0, the Python defaults).
    state: speed PID, yaw PID. params: speed PID (6), yaw PID (6), h, d11, d33, B, open-loop thrust
    ahead, astern, differential (kgf), KGF (N), default mode code, default loop code.
    """
    h = pa[12]
    u_d = sig[sl[0]]
    r_d = sig[sl[1]]
    mode = sig[sl[4]] if sig[sl[4]] >= 0.0 else pa[20]
    loop = sig[sl[5]] if sig[sl[5]] >= 0.0 else pa[21]
    if sig[sl[8]] != 0.0:
        _clear(st, 0)
        _clear(st, 5)
        u_speed = 0.0
        u_head = 0.0
    elif mode == 0.0 and loop == 1.0:
        surge = max(-1.0, min(1.0, sig[sl[6]]))
        yaw = max(-1.0, min(1.0, sig[sl[7]]))
        u_speed = surge * (pa[16] if surge >= 0 else pa[17]) * pa[19]
        u_head = yaw * pa[18] * pa[19]
        _clear(st, 0)
        _clear(st, 5)
    else:
        u_speed = pid_step(st, 0, pa, 0, u_d - sig[sl[2]], h, 0.0, False, 0.5 * pa[13] * u_d, pa[3], pa[4])
        u_head = pid_step(st, 5, pa, 6, r_d - sig[sl[3]], h, 0.0, False, pa[14] * r_d / pa[15], pa[9], pa[10])
    sig[sl[9]] = u_speed + u_head
    sig[sl[10]] = u_speed - u_head
