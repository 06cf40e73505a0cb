"""Rudder / thruster allocation of the yaw demand (document 001 eq. 36-38).

The yaw loop of the nonlinear controller asks the rudder and the thrusters for the weighted moment

    u_rd = c (Y_R + Y_T) + d (N_R + N_T)                                                  (34)

(c, d the (2,1), (2,2) entries of the inverse sway-yaw mass matrix M1^-1, 001 eq. 35). With the
stern thruster run opposite to the bow thruster, n_S = -n_B, the thrusters give
c Y_T + d N_T = K n_B|n_B| with K = c (b_B - b_S) + d (b_B x_TB - b_S x_TS); for b_S = b_B and
x_TS = -x_TB this is 001's ``2 d x_TB b_B n_B|n_B|`` (37; SPEC: read x_TS = -x_TB). The rudder gives

    R(delta) = c Y_R + d N_R = -(c (1 + a_H) + d (x_R + a_H x_H)) F_N(delta) cos(delta)    (37)

with the full rudder model of :mod:`oceangnc.models.ship_lowspeed` (F_N from the present inflow).
The redundancy is resolved by optimisation (001 sec. 3.2):

* speed through the water U >= U_switch (001: "for example 0.4 m/s"): minimise J = n_B^2 =
  |u_rd - R(delta)| / |K| (38) over delta in [-delta_max, delta_max], i.e. use the rudder as far
  as it goes; found numerically by a grid scan then golden-section refinement (001: "varying delta
  numerically");
* below U_switch: minimise J = delta^2, i.e. delta = 0 and thrusters only (001's simulations).

Then n_B = sgn(w/K) sqrt(|w/K|), w = u_rd - R(delta), limited to the thruster's range, n_S = -n_B.
"""

from __future__ import annotations

import math

from numba import njit

from ..models.ship_lowspeed import LAYOUT, rudder_normal_force

#: offsets of the ship parameters used here, from the model's generated layout
(_A_H, _X_H, _X_R, _B_B, _B_S, _X_TB, _X_TS, _DELTA_MAX, _NB_MAX) = LAYOUT.indices(
    "a_H", "x_H", "x_R", "b_B", "b_S", "x_TB", "x_TS", "delta_max", "nB_max"
)


@njit(cache=True)
def thruster_gain(c, d, p):
    """K of c Y_T + d N_T = K n_B|n_B| for n_S = -n_B (N m / rev^2 s^2 weighted by M1^-1)."""
    return c * (p[_B_B] - p[_B_S]) + d * (p[_B_B] * p[_X_TB] - p[_B_S] * p[_X_TS])


@njit(cache=True)
def rudder_term(delta, ur, vr, r, n, c, d, p):
    """R(delta) = c Y_R + d N_R of the rudder at angle ``delta`` (rad) in the present inflow (001 eq. 37)."""
    fn = rudder_normal_force(delta, ur, vr, r, n, p)
    return -(c * (1.0 + p[_A_H]) + d * (p[_X_R] + p[_A_H] * p[_X_H])) * fn * math.cos(delta)


@njit(cache=True)
def cost_nb2(delta, u_rd, ur, vr, r, n, c, d, p):
    """J(delta) = n_B^2 = |u_rd - R(delta)| / |K| (001 eq. 38)."""
    return abs(u_rd - rudder_term(delta, ur, vr, r, n, c, d, p)) / abs(thruster_gain(c, d, p))


@njit(cache=True)
def allocate(u_rd, ur, vr, r, n, c, d, p, u_switch, n_grid, d_lo, d_hi):
    """(delta_c rad, n_B rev/s) realising u_rd (see module docstring); n_S = -n_B.

    The rudder angle is searched over [d_lo, d_hi] (within +-delta_max): the whole range, or the
    angles the rudder can reach before the next update (rate-aware use, see the controller).
    """
    dmax = p[_DELTA_MAX]
    d_lo = max(-dmax, d_lo)
    d_hi = min(dmax, d_hi)
    U = math.sqrt(ur * ur + vr * vr)
    delta = 0.0
    if U < u_switch:
        delta = min(max(0.0, d_lo), d_hi)  # minimise delta^2 (001: thrusters only)
    else:
        best = d_lo
        jbest = 1e300
        h = (d_hi - d_lo) / (n_grid - 1)
        for i in range(n_grid):
            dl = d_lo + i * h
            j = cost_nb2(dl, u_rd, ur, vr, r, n, c, d, p)
            if j < jbest:
                jbest = j
                best = dl
        lo = max(d_lo, best - h)
        hi = min(d_hi, best + h)
        g = 0.5 * (math.sqrt(5.0) - 1.0)
        a = hi - g * (hi - lo)
        b = lo + g * (hi - lo)
        fa = cost_nb2(a, u_rd, ur, vr, r, n, c, d, p)
        fb = cost_nb2(b, u_rd, ur, vr, r, n, c, d, p)
        for _ in range(60):
            if fa < fb:
                hi = b
                b = a
                fb = fa
                a = hi - g * (hi - lo)
                fa = cost_nb2(a, u_rd, ur, vr, r, n, c, d, p)
            else:
                lo = a
                a = b
                fa = fb
                b = lo + g * (hi - lo)
                fb = cost_nb2(b, u_rd, ur, vr, r, n, c, d, p)
        delta = 0.5 * (lo + hi)
        if cost_nb2(delta, u_rd, ur, vr, r, n, c, d, p) > jbest:
            delta = best
    K = thruster_gain(c, d, p)
    w = (u_rd - rudder_term(delta, ur, vr, r, n, c, d, p)) / K
    nb = math.sqrt(abs(w))
    if w < 0.0:
        nb = -nb
    nbmax = p[_NB_MAX]
    if nb > nbmax:
        nb = nbmax
    elif nb < -nbmax:
        nb = -nbmax
    return delta, nb
