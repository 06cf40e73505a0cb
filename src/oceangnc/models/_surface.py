"""A submerged vehicle at the free surface (:mod:`oceangnc.models.vehicle`, ``hydrostatics.height``): the
buoyancy it loses with its emerged volume, and the thrust a thruster loses out of the water.

**Buoyancy.** The hull of height h is taken as a prism of constant horizontal section centred on the
centre of buoyancy (CB): with the CB at depth z_b = z + (R r_b)_z (R = R_b^n, Fossen 2021 eq. 2.18),
the submerged fraction of its volume is the linear ramp

    f = clamp(1/2 + z_b / h, 0, 1)

(1 fully submerged, z_b >= h/2; 0 fully out of the water, z_b <= -h/2). The buoyancy is f B, still acting
at r_b (the shift of the centre of buoyancy of a partly emerged hull is neglected: it changes the
restoring moments near the surface, not the vertical force). A vehicle heavier than what it displaces
(W > f B) therefore cannot float higher than the draft where f B = W: one with W >= B sinks, one with
W < B floats at f = W / B. The generalised force of the lost buoyancy (1 - f) B is that of a weight
(1 - f) B placed at r_b, added to Fossen's g(eta) (eq. 4.6).

**Thrust.** A thruster out of the water gives no thrust (it runs in air; ventilation as it breaks
the surface): its thrust is scaled by its own immersion, the same ramp over a length d (the duct or
propeller diameter, ``hydrostatics.thruster_immersion``) at the thruster's depth z_i = z + (R r_i)_z.
So vertical thrusters cannot lift the vehicle out of the water either: with every thruster above the
surface it has no thrust and falls back.

Not modelled (stated in docs/vehicles.md): added mass, damping and the wave making of the emerged part
(they keep their submerged values), the change of the centre of buoyancy with the draft, spray.
Written for real or complex arguments (complex-step Jacobians): comparisons on the real part.
"""

from __future__ import annotations

from numba import njit


@njit(cache=True, inline="always")
def immersed_fraction(depth, height):
    """clamp(1/2 + depth / height, 0, 1): the submerged share of a length ``height`` (m) centred at
    ``depth`` (m, down positive); 1 when ``height`` <= 0 (no free surface modelled)."""
    if height.real <= 0.0:
        return 1.0 + 0.0 * depth
    f = 0.5 + depth / height
    if f.real >= 1.0:
        return 1.0 + 0.0 * depth
    if f.real <= 0.0:
        return 0.0 * depth
    return f


@njit(cache=True, inline="always")
def lost_buoyancy(d_b, xb, yb, zb, cf, sf, ct, st):
    """g(eta) of the buoyancy ``d_b`` (N) the emerged volume no longer gives: a weight d_b at r_b (Fossen
    2021 eq. 4.6 with W = d_b at r_g = r_b and no buoyancy); it enters as M nu' + ... + g = tau."""
    return (
        d_b * st,
        -(d_b * ct * sf),
        -(d_b * ct * cf),
        -(yb * d_b) * ct * cf + (zb * d_b) * ct * sf,
        (zb * d_b) * st + (xb * d_b) * ct * cf,
        -(xb * d_b) * ct * sf - (yb * d_b) * st,
    )
