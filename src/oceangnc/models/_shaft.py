"""Shaft-speed thrusters of a vehicle file: thrust from propeller revolutions with a first-order shaft lag.

The usual propeller model of Fossen's vehicles (Fossen 2021, ch. 9.1, eq. 9.2-9.7; his Python Vehicle
Simulator's ``otter.py`` and ``remus100.py``): the state of thruster i is its shaft speed n (rad/s), lagging
its command with the time constant T_n,

    n' = (n_c - n) / T_n,        n, n_c saturated to [-n_rev, n_fwd]

and the thrust along its direction d and the torque about it are quadratic in n, with an optional term
linear in the advance speed V_a = (1 - w) U_r (U_r the speed through the water at CO, w the wake fraction;
the linear K_T(J) of ``remus100.py``: K_T = K_T0 + (K_Tmax - K_T0) J / J_max, J = V_a / (n D)):

    T = k_fwd n|n| + k_adv |n| V_a   (n > 0),       T = k_rev n|n|   (n <= 0)
    Q = q_fwd n|n| + q_adv |n| V_a   (n > 0),       Q = q_rev n|n|   (n <= 0)

(for a propeller of diameter D in water of density rho: k_fwd = rho D^4 K_T0 / (2 pi)^2 with n in rad/s).
The command stays a thrust (N), so that every allocation and controller works on any thruster: it is read as
the bollard thrust of the commanded shaft speed, n_c = sign(T_c) sqrt(|T_c| / k), the inverse static law
(``otter.py``'s ``controlAllocation``); :func:`shaft_command` converts a shaft speed to it at the edge (rad/s
or rpm). The shaft-speed limits are the bollard limits, n_fwd = sqrt(max_forward / k_fwd) and n_rev =
sqrt(max_reverse / k_rev) (``otter.py``: n_max = sqrt(0.5 x 24.4 g / k_pos)), unless the file gives them.
"""

from __future__ import annotations

import math
from typing import Literal

import numpy as np
from numba import njit
from pydantic import Field

from ..core.config import StrictModel
from ..core.csmath import cabs, csqrt

RPM = 2.0 * math.pi / 60.0  #: rad/s per rpm

#: the shaft fields of a thruster's row in the parameter table (after max_forward, max_reverse, time_constant);
#: k_fwd = 0 marks a thruster whose state is its thrust (no shaft)
SHAFT_FIELDS = ("k_fwd", "k_rev", "k_adv", "q_fwd", "q_rev", "q_adv", "wake", "n_fwd", "n_rev")


class Shaft(StrictModel):
    """A thruster driven by shaft speed (module docstring). Coefficients per the file's ``unit`` of n."""

    unit: Literal["rad/s", "rpm"] = Field("rad/s", description="unit of n in k_*, q_* and n_* (rpm converted here)")
    k_forward: float = Field(gt=0, le=1e6, description="thrust k_fwd n|n| for n > 0, N per unit(n)^2")
    k_reverse: float = Field(gt=0, le=1e6, description="thrust k_rev n|n| for n < 0, N per unit(n)^2")
    k_advance: float = Field(0.0, ge=-1e6, le=1e6, description="thrust k_adv |n| V_a for n > 0, N s/m per unit(n)")
    q_forward: float = Field(0.0, ge=-1e6, le=1e6, description="torque about the thrust axis q_fwd n|n|, N m")
    q_reverse: float = Field(0.0, ge=-1e6, le=1e6, description="torque q_rev n|n| for n < 0, N m per unit(n)^2")
    q_advance: float = Field(0.0, ge=-1e6, le=1e6, description="torque q_adv |n| V_a for n > 0, N s per unit(n)")
    wake: float = Field(0.0, ge=0.0, lt=1.0, description="wake fraction w: V_a = (1 - w) U_r")
    n_max: float | None = Field(
        None, gt=0, le=1e6, description="largest forward shaft speed (default from max_forward)"
    )
    n_min: float | None = Field(
        None, le=0, ge=-1e6, description="largest reverse shaft speed, <= 0 (default from max_reverse)"
    )

    def row(self, max_forward: float, max_reverse: float) -> list[float]:
        """The :data:`SHAFT_FIELDS` values in SI (n in rad/s)."""
        c = RPM if self.unit == "rpm" else 1.0  # rad/s per unit of n
        kf, kr = self.k_forward / c**2, self.k_reverse / c**2
        n_fwd = self.n_max * c if self.n_max is not None else math.sqrt(max_forward / kf)
        n_rev = -self.n_min * c if self.n_min is not None else math.sqrt(max_reverse / kr)
        return [kf, kr, self.k_advance / c, self.q_forward / c**2, self.q_reverse / c**2, self.q_advance / c,
                self.wake, n_fwd, n_rev]  # fmt: skip


def shaft_command(shaft: Shaft, n: float, unit: str = "rad/s") -> float:
    """The thrust command (N) that drives a shaft-speed thruster at shaft speed ``n`` (rad/s or rpm):
    k n|n| with the forward or reverse coefficient, the inverse of the kernel's n_c = sign(T_c) sqrt(|T_c| / k)."""
    c = RPM if unit == "rpm" else 1.0
    cf = RPM if shaft.unit == "rpm" else 1.0
    n = n * c
    k = (shaft.k_forward if n > 0 else shaft.k_reverse) / cf**2
    return k * n * abs(n)


@njit(cache=True, inline="always")
def shaft_thrust(p, k, cmd, n_state, tau_n, ur, vr, wr):
    """Shaft speed derivative, thrust (N) and torque (N m) of the shaft-speed thruster whose shaft fields start
    at ``p[k]`` (:data:`SHAFT_FIELDS`), for the thrust command ``cmd`` (N, already saturated to the bollard
    limits), the shaft state ``n_state`` (rad/s, used when ``tau_n`` > 0) and the relative velocity at CO."""
    kf = p[k]
    kr = p[k + 1]
    n_fwd = p[k + 7]
    n_rev = p[k + 8]
    if cmd.real >= 0.0:
        nc = csqrt(cmd / kf) if cmd.real > 0.0 else 0.0 * cmd
    else:
        nc = -csqrt(-cmd / kr)
    if nc.real > n_fwd.real:
        nc = n_fwd + 0.0 * cmd
    elif nc.real < -n_rev.real:
        nc = -n_rev + 0.0 * cmd
    if tau_n.real > 0.0:
        n = n_state
        dn = (nc - n) / tau_n
    else:
        n = nc
        dn = 0.0 * nc
    if n.real > n_fwd.real:  # the state is held within the physical limits (otter.py saturates it)
        n = n_fwd + 0.0 * n
    elif n.real < -n_rev.real:
        n = -n_rev + 0.0 * n
    an = cabs(n)
    if n.real > 0.0:
        va = (1.0 - p[k + 6]) * csqrt(ur * ur + vr * vr + wr * wr + 1e-300)
        thrust = kf * n * an + p[k + 2] * an * va
        torque = p[k + 3] * n * an + p[k + 5] * an * va
    else:
        thrust = kr * n * an
        torque = p[k + 4] * n * an
    return dn, thrust, torque


def thrusts_from_states(vf, states: np.ndarray) -> np.ndarray:
    """Thrust (N) of each thruster from the logged thruster states (rows of time, one column per thruster: the
    thrust itself, or the shaft speed in rad/s of a shaft-speed thruster, evaluated at zero advance speed)."""
    states = np.asarray(states, float)
    out = states.copy()
    for i, t in enumerate(vf.thrusters):
        if t.shaft is not None:
            kf, kr = t.shaft.row(t.max_forward, t.max_reverse)[:2]
            n = states[:, i]
            out[:, i] = np.where(n > 0, kf, kr) * n * np.abs(n)
    return out
