"""Compiled forms of the sea-trial blocks (000 sec. 2.2): the ITTC zig-zag and the trial sensors,
for the fused loop (issue 19; kernel convention: :mod:`oceangnc.control._compiled`; sensor kernels
take the block's generator as a 6th argument, :mod:`oceangnc.sensors._compiled`).

:func:`zigzag_law` is the one home of the zig-zag switching rule: :class:`~oceangnc.identification.trials.ZigZag`
calls it from Python as :func:`zigzag_step` does in the fused loop. :func:`trial_sensors_step`
makes the draws of :class:`~oceangnc.identification.trials.TrialSensors` in the same order from the
same generator.
"""

from __future__ import annotations

from numba import njit

from ..core.rotations import wrap


@njit(cache=True)
def zigzag_law(t, psi, st, t_step, psi_z):
    """Sign of the zig-zag command (0 before ``t_step``): ``st`` = [sign, psi0, has psi0], updated.

    The heading change is measured from the heading at the first call, wrapped to (-pi, pi]; the
    command turns to -1 once it reaches +psi_z and back to +1 at -psi_z (rad).
    """
    if st[2] == 0.0:
        st[1] = psi
        st[2] = 1.0
    dpsi = wrap(psi - st[1])
    if t < t_step - 1e-9:
        return 0.0
    if st[0] > 0 and dpsi >= psi_z:
        st[0] = -1.0
    elif st[0] < 0 and dpsi <= -psi_z:
        st[0] = 1.0
    return st[0]


@njit(cache=True)
def zigzag_step(t, sig, sl, st, pa):
    """:class:`oceangnc.identification.trials.ZigZag`: slots usv.psi | key. state: sign, psi0, has psi0.
    params: amp, psi_z (rad), t_step (s), scale."""
    s = zigzag_law(t, sig[sl[0]], st, pa[2], pa[1])
    sig[sl[1]] = 0.0 if s == 0.0 else s * pa[0] * pa[3]


@njit(cache=True)
def _combo(sig, a, b, sign, scale):
    return sig[a] if b < 0 else scale * (sig[a] + sign * sig[b])


@njit(cache=True)
def trial_sensors_step(t, sig, sl, st, pa, rng):
    """:class:`oceangnc.identification.trials.TrialSensors`.

    slots: usv.u, usv.psi, usv.r, steer a, steer b (-1: none), thrust a, thrust b | trial.speed,
    trial.heading, trial.yaw_rate, trial.steer, trial.thrust. params: speed, heading, yaw-rate
    noise std (m/s, rad, rad/s; 0: no draw), steer sign, scale, thrust sign, scale.
    """
    sig[sl[7]] = sig[sl[0]] + (rng.normal(0.0, pa[0]) if pa[0] != 0.0 else 0.0)
    psi = sig[sl[1]] + (rng.normal(0.0, pa[1]) if pa[1] != 0.0 else 0.0)
    sig[sl[8]] = wrap(psi)
    sig[sl[9]] = sig[sl[2]] + (rng.normal(0.0, pa[2]) if pa[2] != 0.0 else 0.0)
    sig[sl[10]] = _combo(sig, sl[3], sl[4], pa[3], pa[4])
    sig[sl[11]] = _combo(sig, sl[5], sl[6], pa[5], pa[6])
