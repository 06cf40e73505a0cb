"""Control surfaces of a vehicle file (``[[fins]]``): rudders and stern planes driven by an angle command.

The fin model of Fossen's REMUS 100 (Fossen 2021 section 8.4.2; his Python Vehicle Simulator's
``remus100.py``, which follows Prestero 2001): fin j at r_j from CO, of area A, lift curve slope C_L,delta
(1/rad) and largest angle delta_max. Its angle is a state lagging the command with the time constant T_delta,

    delta' = (delta_c - delta) / T_delta,        delta_c saturated to [-delta_max, delta_max]

(``time_constant = 0``: the command at once). A *rudder* works in the horizontal plane, a *stern plane* in
the vertical plane; with U_p^2 the square of the relative flow speed in the fin's plane (u_r^2 + v_r^2 for a
rudder, u_r^2 + w_r^2 for a stern plane) the lift and the induced drag are

    L = -1/2 rho U_p^2 A C_L,delta delta   (along body y for a rudder, body z for a stern plane)
    X = -1/2 rho U_p^2 A C_L,delta delta^2

acting at r_j (moment r_j x F). The lift is linear in the angle up to the saturation (no stall: the
angle is limited to delta_max, 15 deg on the REMUS 100, inside the fins' linear range). A positive rudder
angle gives a force to port (-y) at the stern, so a yaw to starboard (+r) for a rudder aft of CO;
a positive stern-plane angle gives an upward force (-z) at the stern, bow down.

Written for real or complex arguments (complex-step Jacobians): comparisons on the real part.
"""

from __future__ import annotations

import math
from typing import Literal

from numba import njit
from pydantic import Field

from ..core.config import StrictModel

#: values per fin in the parameter table, after the thrusters
FIN_FIELDS = ("x", "y", "z", "plane", "area", "cl_delta", "max_angle", "time_constant")
NFIN = len(FIN_FIELDS)
F_X, F_Y, F_Z, F_PLANE, F_AREA, F_CL, F_MAX, F_TAU = range(NFIN)
RUDDER, STERN = 0.0, 1.0


class Fin(StrictModel):
    """One control surface (module docstring)."""

    name: str = Field(min_length=1, max_length=40)
    plane: Literal["rudder", "stern"] = Field(description="rudder: lift along y (horizontal plane); stern: along z")
    position: tuple[float, float, float] = Field(description="centre of pressure from CO, body axes, m")
    area: float = Field(gt=0, le=100, description="fin area A (all fins of the pair together), m^2")
    cl_delta: float = Field(gt=0, le=20, description="lift curve slope C_L,delta, 1/rad")
    max_angle_deg: float = Field(gt=0, le=60, description="largest angle delta_max (saturation), deg")
    time_constant: float = Field(0.0, ge=0, le=100, description="first-order lag of the angle, s (0: none)")

    def row(self) -> list[float]:
        """The fin's values in the parameter table (:data:`FIN_FIELDS`), SI (angle in rad)."""
        plane = RUDDER if self.plane == "rudder" else STERN
        lim = math.radians(self.max_angle_deg)
        return [*self.position, plane, self.area, self.cl_delta, lim, self.time_constant]


@njit(cache=True, inline="always")
def fin_step(p, k, cmd, delta_state):
    """The fin at ``p[k:]``: (delta' (rad/s), the angle acting (rad)) from the command and the state."""
    lim = p[k + F_MAX]
    if cmd.real > lim.real:
        cmd = lim + 0.0 * cmd
    elif cmd.real < -lim.real:
        cmd = -lim + 0.0 * cmd
    if p[k + F_TAU].real > 0.0:
        return (cmd - delta_state) / p[k + F_TAU], delta_state
    return 0.0 * cmd, cmd


@njit(cache=True, inline="always")
def fin_force(p, k, delta, rho, ur, vr, wr):
    """Body-axis force (X, Y, Z) (N) of the fin at ``p[k:]`` at angle ``delta`` (rad) in the relative flow
    (u_r, v_r, w_r) (m/s), water density ``rho``: the module docstring's lift and drag."""
    if p[k + F_PLANE].real == 0.0:
        up2 = ur * ur + vr * vr
    else:
        up2 = ur * ur + wr * wr
    q = 0.5 * rho * up2 * p[k + F_AREA] * p[k + F_CL]
    lift = -q * delta
    drag = -q * delta * delta
    if p[k + F_PLANE].real == 0.0:
        return drag, lift, 0.0 * lift
    return drag, 0.0 * lift, lift
