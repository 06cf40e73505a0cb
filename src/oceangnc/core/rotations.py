"""Frames and rotations: NED earth frame, body frame x forward / y starboard / z down.

Implements the planar rotation used by the 3-DOF models (003 eq. 2.1-2.2; 000 eq. 2, whose printed
matrix has a sign misprint: the standard rotation is used here) and the 6-DOF Euler-angle
(zyx, roll phi / pitch theta / yaw psi) kinematics of 003 appendix A (Fossen 2011, eq. 2.18 and 2.29):

    eta_dot = J(eta) nu,  J = diag(R_b^n(Theta), T(Theta)).

All functions are compiled with numba so that vehicle right-hand sides can call them; they accept
and return float64 numpy arrays and angles in radians.
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit

from .csmath import ccos, csin


@njit(cache=True, inline="always")
def hypot(a, b):
    """sqrt(a^2 + b^2), the same bits in Python and in compiled code (libm's and numba's ``hypot`` differ
    in the last bit, which would keep the fused and the Python clock from giving identical logs)."""
    return math.sqrt(a * a + b * b)


@njit(cache=True, inline="always")
def wrap(a):
    """Wrap one angle (rad) to (-pi, pi]: the one home of the angle wrap (compiled; callable from
    Python blocks and from numba right-hand sides). :func:`wrap_array` is the same for arrays."""
    w = (a + math.pi) % (2.0 * math.pi) - math.pi
    if w == -math.pi:
        w = math.pi
    return w


@njit(cache=True, inline="always")
def heading_speed(x, i_psi, i_vel, n_vel):
    """(heading wrapped to (-pi, pi], speed): ``wrap(x[i_psi])`` (rad) and the norm of the ``n_vel``
    velocity states from ``x[i_vel]`` (m/s), summed as sqrt(x0 x0 + x1 x1 + ...), the same bits in the
    plants' Python publish and in the fused kernels."""
    s = 0.0
    for i in range(i_vel, i_vel + n_vel):
        s += x[i] * x[i]
    return wrap(x[i_psi]), math.sqrt(s)


def wrap_array(a):
    """:func:`wrap` of a scalar or an array (rad) to (-pi, pi], vectorised with numpy (for logs)."""
    w = np.mod(np.asarray(a, dtype=np.float64) + np.pi, 2.0 * np.pi) - np.pi
    w = np.where(w == -np.pi, np.pi, w)
    return float(w) if np.ndim(w) == 0 else w


@njit(cache=True)
def rot2(psi):
    """Planar rotation body -> NED, R(psi) (2x2); [x_dot, y_dot] = R(psi) [u, v]."""
    c = math.cos(psi)
    s = math.sin(psi)
    R = np.empty((2, 2))
    R[0, 0] = c
    R[0, 1] = -s
    R[1, 0] = s
    R[1, 1] = c
    return R


@njit(cache=True)
def rot3(psi):
    """3-DOF rotation body -> NED for (x, y, psi) and (u, v, r) (Fossen 2011 eq. 2.39)."""
    R = np.zeros((3, 3))
    R[:2, :2] = rot2(psi)
    R[2, 2] = 1.0
    return R


@njit(cache=True, inline="always")
def rzyx_entries(phi, theta, psi):
    """The nine entries (r00, r01, r02, r10, ..., r22) of R_b^n(phi, theta, psi) (Fossen 2011 eq. 2.18).

    A tuple of scalars, so compiled right-hand sides can rotate without allocating a matrix; real or
    complex angles (:mod:`oceangnc.core.csmath`, for complex-step Jacobians).
    """
    cphi = ccos(phi)
    sphi = csin(phi)
    cth = ccos(theta)
    sth = csin(theta)
    cpsi = ccos(psi)
    spsi = csin(psi)
    return (
        cpsi * cth,
        -spsi * cphi + cpsi * sth * sphi,
        spsi * sphi + cpsi * cphi * sth,
        spsi * cth,
        cpsi * cphi + sphi * sth * spsi,
        -cpsi * sphi + sth * spsi * cphi,
        -sth,
        cth * sphi,
        cth * cphi,
    )


@njit(cache=True)
def rzyx(phi, theta, psi):
    """Euler zyx rotation matrix R_b^n(phi, theta, psi), body -> NED (Fossen 2011 eq. 2.18)."""
    e = rzyx_entries(phi, theta, psi)
    R = np.empty((3, 3))
    for i in range(3):
        for j in range(3):
            R[i, j] = e[3 * i + j]
    return R


@njit(cache=True)
def tzyx(phi, theta):
    """Euler-angle rate transform T(Theta): [phi_dot, theta_dot, psi_dot] = T [p, q, r] (Fossen eq. 2.29).

    Singular at theta = +-pi/2 (the vehicle pointing straight up or down).
    """
    cphi = math.cos(phi)
    sphi = math.sin(phi)
    cth = math.cos(theta)
    sth = math.sin(theta)
    T = np.empty((3, 3))
    T[0, 0] = 1.0
    T[0, 1] = sphi * sth / cth
    T[0, 2] = cphi * sth / cth
    T[1, 0] = 0.0
    T[1, 1] = cphi
    T[1, 2] = -sphi
    T[2, 0] = 0.0
    T[2, 1] = sphi / cth
    T[2, 2] = cphi / cth
    return T


@njit(cache=True)
def skew(a):
    """Skew-symmetric matrix S(a) with S(a) b = a x b."""
    S = np.zeros((3, 3))
    S[0, 1] = -a[2]
    S[0, 2] = a[1]
    S[1, 0] = a[2]
    S[1, 2] = -a[0]
    S[2, 0] = -a[1]
    S[2, 1] = a[0]
    return S


@njit(cache=True)
def euler_from_rotation(R):
    """Recover (phi, theta, psi) from a zyx rotation matrix (inverse of :func:`rzyx`)."""
    theta = -math.asin(max(-1.0, min(1.0, R[2, 0])))
    phi = math.atan2(R[2, 1], R[2, 2])
    psi = math.atan2(R[1, 0], R[0, 0])
    return phi, theta, psi
