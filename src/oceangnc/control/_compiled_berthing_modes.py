"""Compiled forms of the berthing controllers' open-loop and PID modes (001 fig. 3, eq. 39-42) for the
fused loop (issue 19; kernel convention and the PID kernel: :mod:`oceangnc.control._compiled`; the
nonlinear mode: :mod:`oceangnc.control._compiled_berthing`).

:func:`open_loop_law` is the one home of the open-loop stick mapping: the Python
:class:`~oceangnc.control.berthing.OpenLoopController` calls it as the kernel does. An emergency
stop (``_estop``) zeroes every command, as :meth:`oceangnc.control.berthing._Base._write` does.
"""

from __future__ import annotations

from numba import njit

from ._compiled import pid_step


@njit(cache=True)
def open_loop_law(su, sy, n_open_rpm, rudder_open_stick, delta_open, thruster_open, thruster_rpm_max):
    """(rudder rad, propeller rev/s, bow thruster rev/s) from the dead-banded stick (001 fig. 3);
    ``delta_open`` (rad) is reached at ``rudder_open_stick``, the stern thruster runs at minus the bow's."""
    n = su * n_open_rpm / 60.0
    delta = max(-1.0, min(1.0, sy / rudder_open_stick)) * delta_open
    nb = sy * thruster_open * thruster_rpm_max / 60.0
    return delta, n, nb


@njit(cache=True)
def _write(t, sig, sl, o, delta, n, nb, e_u, e_r):
    if sig[sl[o]] != 0.0:  # _estop
        delta = 0.0
        n = 0.0
        nb = 0.0
    sig[sl[o + 1]] = delta
    sig[sl[o + 2]] = n
    sig[sl[o + 3]] = nb
    sig[sl[o + 4]] = -nb
    sig[sl[o + 5]] = e_u
    sig[sl[o + 6]] = e_r


@njit(cache=True)
def open_loop_step(t, sig, sl, st, pa):
    """:class:`oceangnc.control.berthing.OpenLoopController`.

    slots: ship.u, ship.r, cmd.u_d, cmd.r_d, joystick.surge_db, joystick.yaw_db, _estop |
    ship.rudder_cmd, ship.n_prop_cmd, ship.n_bow_cmd, ship.n_stern_cmd, ctrl.e_u, ctrl.e_r.
    params: n_open_rpm, rudder_open_stick, delta_open (rad), thruster_open, thruster_rpm_max.
    """
    delta, n, nb = open_loop_law(sig[sl[4]], sig[sl[5]], pa[0], pa[1], pa[2], pa[3], pa[4])
    _write(t, sig, sl, 6, delta, n, nb, sig[sl[0]] - sig[sl[2]], sig[sl[1]] - sig[sl[3]])


@njit(cache=True)
def berthing_pid_step(t, sig, sl, st, pa):
    """:class:`oceangnc.control.berthing.PIDController` (001 eq. 39-42, n_S = -n_B).

    slots: ship.u, ship.r, cmd.u_d, cmd.r_d, _estop | ship.rudder_cmd, ship.n_prop_cmd,
    ship.n_bow_cmd, ship.n_stern_cmd, ctrl.e_u, ctrl.e_r. state: propeller, rudder, thruster PIDs
    (5 each). params: the three PIDs (6 each), period.
    """
    h = pa[18]
    e_u = sig[sl[0]] - sig[sl[2]]
    e_r = sig[sl[1]] - sig[sl[3]]
    n = pid_step(st, 0, pa, 0, -e_u, h, 0.0, False, 0.0, pa[3], pa[4])
    delta = pid_step(st, 5, pa, 6, -e_r, h, 0.0, False, 0.0, pa[9], pa[10])
    nb = pid_step(st, 10, pa, 12, -e_r, h, 0.0, False, 0.0, pa[15], pa[16])
    _write(t, sig, sl, 4, delta, n, nb, e_u, e_r)


def open_loop_form(block, out):
    """The :class:`~oceangnc.core.fused.CompiledBlock` of an OpenLoopController (``out``: its outputs)."""
    import numpy as np

    from ..core.fused import CompiledBlock

    sig = ["ship.u", "ship.r", "cmd.u_d", "cmd.r_d", "joystick.surge_db", "joystick.yaw_db", "_estop", *out]
    return CompiledBlock(open_loop_step, sig, params=np.array(block._law_params(), dtype=np.float64))


def pid_form(block, out):
    """The :class:`~oceangnc.core.fused.CompiledBlock` of a berthing PIDController."""
    from ..core.fused import CompiledBlock
    from ._compiled import arr, pid_params, pid_state

    pids = (block.pid_n, block.pid_d, block.pid_t)
    st = arr([v for p in pids for v in pid_state(p)])
    pa = arr([v for p in pids for v in pid_params(p)] + [block.period])
    return CompiledBlock(berthing_pid_step, ["ship.u", "ship.r", "cmd.u_d", "cmd.r_d", "_estop", *out], st, pa)
