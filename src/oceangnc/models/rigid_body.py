"""Rigid-body kinetics shared by every 6-DOF model (Fossen 2011 ch. 3 and 6): a row product on a flat
6 x 6 matrix and the Coriolis-centripetal force of a mass matrix in Kirchhoff's momentum form.

Used by the 003 UUV (:mod:`oceangnc.models.uuv`) and the generic vehicle of a TOML file
(:mod:`oceangnc.models.vehicle`); written for real or complex arguments (complex-step Jacobians).
"""

from __future__ import annotations

from numba import njit


@njit(cache=True)
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
