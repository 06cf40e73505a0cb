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

from .pid import pid_step  # noqa: F401 (the one PID law, for the kernels not yet on LawBlock)

PID_STATE = 5
PID_PARAMS = 6


def pid_state(pid) -> list[float]:
    """The 5-float state of a :class:`~oceangnc.control.pid.PID` (:data:`oceangnc.control.pid.PID_STATE`)."""
    return [float(x) for x in pid.st]


def pid_params(pid) -> list[float]:
    """The 6-float parameters of a :class:`~oceangnc.control.pid.PID` (:data:`oceangnc.control.pid.PID_PARAMS`)."""
    return [float(x) for x in pid.pa]


def arr(values) -> np.ndarray:
    return np.array([float(v) for v in values], dtype=np.float64)
