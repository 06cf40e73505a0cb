"""Compiled forms of the first-order USV's blocks (000): the pole-placed autopilots, the rudder and
engine, and step commands (issue 19, the fused closed loop; kernel convention:
:mod:`oceangnc.control._compiled`).

The scalar laws (:func:`heading_pd_law`, :func:`speed_p_law`, :func:`saturate_rudder_engine`,
:func:`step_value`) are the one home of their equations: the Python blocks
(:class:`~oceangnc.control.pole_placement.HeadingAutopilot`,
:class:`~oceangnc.control.pole_placement.SpeedAutopilot`,
:class:`~oceangnc.models.first_order.FirstOrderActuators`,
:class:`~oceangnc.control.commands.StepCommand`) call them as the kernels do, so both paths give
the same bits. The gains are scheduled with :func:`oceangnc.models.first_order.schedule` (000
table 2); a design with ``2 zeta w_n T <= 1`` (refused by the scenario at build time, and by the
Python block with a ConfigError) makes the kernel write NaN, which the fused loop reports as a
divergence.
"""

from __future__ import annotations

import math

from numba import njit

from ..core.rotations import wrap
from ..models.first_order import schedule


@njit(cache=True)
def pole_placed_k1(K, T, zeta, wn):
    """K1 = (2 zeta w_n T - 1) / K (000 eq. 26 and 31); NaN when 2 zeta w_n T <= 1 or K = 0."""
    a = 2.0 * zeta * wn * T
    if a <= 1.0 or K == 0.0:
        return math.nan
    return (a - 1.0) / K


@njit(cache=True)
def heading_pd_law(K, T, zeta, wn, psi_cmd, psi, r):
    """(delta_S_cmd rad, K1, K2) of the heading PD ``K1 (K2 wrap(psi_c - psi) - r)`` (000 eq. 22, 26, 27)."""
    a = 2.0 * zeta * wn * T
    k1 = pole_placed_k1(K, T, zeta, wn)
    k2 = wn * wn * T / (a - 1.0)
    e = wrap(psi_cmd - psi)
    return k1 * (k2 * e - r), k1, k2


@njit(cache=True)
def speed_p_law(K, T, zeta, wn, vc, v):
    """(delta_T_cmd, K1) of the speed P controller ``K1 (v_c - v)`` (000 eq. 28, 31)."""
    k1 = pole_placed_k1(K, T, zeta, wn)
    return k1 * (vc - v), k1


@njit(cache=True)
def step_value(t, t_step, before, after):
    """``after`` from ``t_step`` on (with 1 ns of slack for the clock's k dt), ``before`` until then."""
    return after if t >= t_step - 1e-9 else before


@njit(cache=True)
def heading_pd_step(t, sig, sl, st, pa):
    """:class:`~oceangnc.control.pole_placement.HeadingAutopilot` on the first-order schedule.

    slots: psi_cmd, psi, r, u | delta_s_cmd, hdg_k1, hdg_k2. params: zeta, wn, schedule params (000 table 2).
    """
    kv, tv, kr, tr = schedule(sig[sl[3]], pa[2:])
    d, k1, k2 = heading_pd_law(kr, tr, pa[0], pa[1], sig[sl[0]], sig[sl[1]], sig[sl[2]])
    sig[sl[4]] = d
    sig[sl[5]] = k1
    sig[sl[6]] = k2


@njit(cache=True)
def speed_p_step(t, sig, sl, st, pa):
    """:class:`~oceangnc.control.pole_placement.SpeedAutopilot` on the first-order schedule (designed at u_cmd).

    slots: u_cmd, u | rpm_cmd, spd_k1. params: zeta, wn, schedule params (000 table 2).
    """
    vc = sig[sl[0]]
    kv, tv, kr, tr = schedule(vc, pa[2:])
    n, k1 = speed_p_law(kv, tv, pa[0], pa[1], vc, sig[sl[1]])
    sig[sl[2]] = n
    sig[sl[3]] = k1


@njit(cache=True)
def step_command_step(t, sig, sl, st, pa):
    """:class:`~oceangnc.control.commands.StepCommand`: slots out_0..out_{m-1};
    params t_step, then (before, after) per output."""
    for i in range(sl.size):
        sig[sl[i]] = step_value(t, pa[0], pa[1 + 2 * i], pa[2 + 2 * i])


@njit(cache=True)
def differential_step(t, sig, sl, st, pa):
    """:class:`~oceangnc.control.commands.DifferentialThrust`: slots ?steer | port, stbd; params: mean (N)."""
    steer = sig[sl[0]] if sl[0] >= 0 else 0.0
    sig[sl[1]] = pa[0] + steer
    sig[sl[2]] = pa[0] - steer
