"""Hydro- and aerodynamic load shapes shared by the models and the model-based controllers: the
velocity relative to a moving fluid (current, wind), the wind load of 003 eq. 2.6-2.9 and the
linear-plus-quadratic damping coefficient. Written with
:mod:`oceangnc.core.csmath`, so the models stay complex-step differentiable.
"""

from __future__ import annotations

from numba import njit

from ..core.csmath import cabs, catan2, ccos, csin


@njit(cache=True, inline="always")
def damping_coefficient(lin, quad, v):
    """d(v) = -(lin + quad |v|): the velocity-dependent damping of one axis for the SNAME linear and
    quadratic coefficients (lin = X_u, quad = X_u|u|, both <= 0), so that the damping force is -d(v) v
    (003 under eq. 3.32: d11 = -X_u - X_u|u| |u|, ...)."""
    return -lin - quad * cabs(v)


@njit(cache=True, inline="always")
def relative_velocity(c, s, u, v, fn, fe):
    """(u_r, v_r, u_f, v_f): body-frame velocity (m/s) relative to a fluid moving at (fn, fe) (NED, m/s,
    toward), and the fluid's own body-frame velocity; ``c``, ``s`` = cos, sin of the heading."""
    uf = c * fn + s * fe
    vf = -s * fn + c * fe
    return u - uf, v - vf, uf, vf


@njit(cache=True, inline="always")
def wind_load(u, v, psi, wn, we, rho, a_front, a_side, loa, c_x, c_y, c_n):
    """Wind force and moment (X, Y, N) in body axes (003 eq. 2.6-2.9); wn, we the wind's NED velocity."""
    urw, vrw, _, _ = relative_velocity(ccos(psi), csin(psi), u, v, wn, we)
    v2 = urw * urw + vrw * vrw
    if v2 == 0.0:
        return 0.0, 0.0, 0.0
    gamma = -catan2(vrw, urw)
    q = 0.5 * rho * v2
    return (
        -q * c_x * ccos(gamma) * a_front,
        q * c_y * csin(gamma) * a_side,
        q * c_n * csin(2.0 * gamma) * a_side * loa,
    )
