"""Rigid-body kinetics shared by every 6-DOF model (Fossen 2011 ch. 3 and 6): a row product on a flat
6 x 6 matrix and the Coriolis-centripetal force of a mass matrix in Kirchhoff's momentum form.

Used by the 003 UUV (:mod:`oceangnc.models.uuv`) and the generic vehicle of a TOML file
(:mod:`oceangnc.models.vehicle`); written for real or complex arguments (complex-step Jacobians).
"""

from __future__ import annotations

from numba import njit

from ..core.csmath import ccos, csin
from ..core.rotations import rzyx_entries


@njit(cache=True, inline="always")
def row6(p, k, n0, n1, n2, n3, n4, n5):
    """Row product sum_j p[k + j] nu_j of a row-major matrix stored in ``p`` from offset ``k``."""
    return p[k] * n0 + p[k + 1] * n1 + p[k + 2] * n2 + p[k + 3] * n3 + p[k + 4] * n4 + p[k + 5] * n5


@njit(cache=True)
def kirchhoff(p, off, nu0, nu1, nu2, nu3, nu4, nu5):
    """Generalised Coriolis force -C(nu) nu = -[w x p1; v x p1 + w x p2], p = M nu (M at p[off:off+36]).

    Fossen 2011 eq. 6.43/6.44 (003 A-8, A-10): skew-symmetric, so it does no work. For a symmetric
    rigid-body mass matrix about any origin (M_RB = H^T M_CG H) it is C_RB(nu) nu; for an added-mass
    matrix C_A(nu_r) nu_r with its Munk moments.
    """
    m0 = row6(p, off, nu0, nu1, nu2, nu3, nu4, nu5)
    m1 = row6(p, off + 6, nu0, nu1, nu2, nu3, nu4, nu5)
    m2 = row6(p, off + 12, nu0, nu1, nu2, nu3, nu4, nu5)
    m3 = row6(p, off + 18, nu0, nu1, nu2, nu3, nu4, nu5)
    m4 = row6(p, off + 24, nu0, nu1, nu2, nu3, nu4, nu5)
    m5 = row6(p, off + 30, nu0, nu1, nu2, nu3, nu4, nu5)
    # omega = (nu3, nu4, nu5), v = (nu0, nu1, nu2)
    f0 = -(nu4 * m2 - nu5 * m1)
    f1 = -(nu5 * m0 - nu3 * m2)
    f2 = -(nu3 * m1 - nu4 * m0)
    f3 = -(nu1 * m2 - nu2 * m1) - (nu4 * m5 - nu5 * m4)
    f4 = -(nu2 * m0 - nu0 * m2) - (nu5 * m3 - nu3 * m5)
    f5 = -(nu0 * m1 - nu1 * m0) - (nu3 * m4 - nu4 * m3)
    return f0, f1, f2, f3, f4, f5


@njit(cache=True, inline="always")
def euler_kinematics(x, out):
    """eta' = J(eta) nu of the 6-DOF state ``x = [x, y, z, phi, theta, psi, u, v, w, p, q, r]`` (zyx Euler
    angles; Fossen 2011 eq. 2.40, 003 eq. 2.13, A-1, A-2) into ``out[0:6]``. Returns the nine entries of
    R_b^n (Fossen eq. 2.18) and cos/sin of roll and pitch, which the forces reuse."""
    phi = x[3]
    th = x[4]
    u = x[6]
    v = x[7]
    w = x[8]
    pp = x[9]
    q = x[10]
    r = x[11]
    cf = ccos(phi)
    sf = csin(phi)
    ct = ccos(th)
    st = csin(th)
    r00, r01, r02, r10, r11, r12, r20, r21, r22 = rzyx_entries(phi, th, x[5])
    out[0] = r00 * u + r01 * v + r02 * w
    out[1] = r10 * u + r11 * v + r12 * w
    out[2] = r20 * u + r21 * v + r22 * w
    out[3] = pp + (sf * q + cf * r) * st / ct
    out[4] = cf * q - sf * r
    out[5] = (sf * q + cf * r) / ct
    return r00, r01, r02, r10, r11, r12, r20, r21, r22, cf, sf, ct, st


@njit(cache=True, inline="always")
def restoring(p, off_w, off_b, off_rg, off_rb, cf, sf, ct, st):
    """g(eta) of weight W = p[off_w] at r_g = p[off_rg:+3] and buoyancy B = p[off_b] at r_b = p[off_rb:+3]
    (Fossen 2011 eq. 4.6, 003 A-13), given cos/sin of roll and pitch; it enters as M nu' + ... + g = tau."""
    W = p[off_w]
    B = p[off_b]
    xg = p[off_rg]
    yg = p[off_rg + 1]
    zg = p[off_rg + 2]
    xb = p[off_rb]
    yb = p[off_rb + 1]
    zb = p[off_rb + 2]
    wb = W - B
    return (
        wb * st,
        -(wb * ct * sf),
        -(wb * ct * cf),
        -(yg * W - yb * B) * ct * cf + (zg * W - zb * B) * ct * sf,
        (zg * W - zb * B) * st + (xg * W - xb * B) * ct * cf,
        -(xg * W - xb * B) * ct * sf - (yg * W - yb * B) * st,
    )
