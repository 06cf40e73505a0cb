"""Underwater cable of document 003 ch. 2.3: lumped-mass model with n segments and n + 1 nodes.

Each segment i (between nodes i-1 and i, node 0 at the top) is a straight element of unstretched
length l0 = L / n with unit tangent t = (r_i - r_{i-1}) / l. Its loads are lumped half-half on its end
nodes (003 eq. 2.28-2.29):

* **Tension** (003 eq. 2.22) T = EA (l - l0) / l0 in extension only, and **axial damping**
  (eq. 2.23) P = C_v (v_i - v_{i-1}) . t; the axial force max(0, T + P) is applied only while the
  segment is stretched, so a slack cable carries no compression (003's assumption "the cable can
  only resist tension"; tested). Its power is never positive, so the damping only dissipates.
* **Drag** (eq. 2.24) on the segment's relative velocity V = (v_{i-1} + v_i)/2 - v_c (v_c the
  current), with tangential part v_q = V . t and normal part V_p = V - v_q t:
  D = -1/2 rho C_d d l0 |V|^2 (f_p V_p / |V_p| + f_q sgn(v_q) t), where the loading functions
  (eq. 2.25) f_p, f_q are evaluated at the angle eta = atan2(|V_p|, |v_q|) in [0, pi/2] between the
  cable and the flow. The printed polynomials dip slightly below zero (f_p for eta < 6 deg, f_q at
  90 deg, by < 0.003); they are clipped at 0 so drag never pushes. The segment frame of eq.
  2.19-2.21 is replaced by the tangent vector itself: the same normal/tangential split without the
  Euler-angle branches of (2.21).
* **Weight and buoyancy** (eq. 2.26; 003 writes m_c = rho_c g V, a weight): the mass of a segment is
  m_c = rho_c A l0 and its submerged weight (rho_c - rho_w) g A l0, downward (+z).
* **Added mass** (eq. 2.27-2.28) on the two normal axes only: in the earth frame the segment mass
  matrix is R diag(m_c + m_a, m_c + m_a, m_c) R^T = (m_c + m_a) I - m_a t t^T, half to each node;
  m_a = C_a rho_w A l0 with C_a = 1 (potential flow around a circular cylinder; 003 does not print
  m_a). Each interior node solves its 3x3 mass matrix (eq. 2.29).

**The "effective modulus of elasticity 7.5e6" of table 2-6.** 003 prints no unit; (2.22) names E
"the modulus of elasticity" and multiplies it by the cross-section A, so it is read as **E = 7.5e6
Pa**, giving EA = 7.5e6 pi 0.025^2 / 4 = 3.68 kN. The alternative EA = 7.5e6 N would need E = 15 GPa
(steel-like, for a 25 mm umbilical that 003 treats as a soft tether) and would make the cable
inextensible in practice (strain 2e-5 under the UUV) with an explicit stable step ~50 times smaller.
"Effective" modulus is the usual name for the apparent E of a composite umbilical (jacket + cores),
which is of the order of MPa for rubber/polyurethane jackets. The value is the config key
``cable.E`` (Pa); ``cable.EA`` is derived.

**Stable step.** The fastest dynamics are the axial modes of the chain of lumped masses m_c joined
by springs k = EA / l0 and dampers C_v (no added mass along the axis). :func:`axial_stability_limit`
builds the linearised axial chain (top node fixed, bottom node carrying the UUV's surge mass),
computes the eigenvalues lambda of its first-order system and returns the largest h for which every
h lambda lies in the stability region of classical RK4 (|1 + z + z^2/2 + z^3/6 + z^4/24| <= 1).
With table 2-6 (20 segments, EA = 3.68 kN, C_v = 100 N s/m) the highest mode is overdamped and the
limit is about 1.9 ms.
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit

from ..core.integrators import stability_limit

from ._cable_config import *  # noqa: F403  (re-exported: the old import paths keep working)
from ._cable_config import CableConfig
from ._sea_layout import NCOEF, point_kinematics


# feature switch (oceangnc.core.variants): True here, so cable_loads handles waves; the plain combined
# plant compiles a copy without them (models/_combined_variants.py)
SEA = True


@njit(cache=True)
def loading_functions(eta):
    """Loading functions f_p, f_q (003 eq. 2.25) at the cable-to-flow angle eta (rad, 0..pi/2), clipped >= 0."""
    return _loading(math.cos(eta), math.sin(eta), eta)


@njit(cache=True, inline="always")
def atan_ratio(y, x):
    """atan2(y, x) for y, x >= 0 (rad, 0..pi/2) by the polynomial of Abramowitz & Stegun 4.4.49 (|error| < 2e-8)."""
    if y <= x:
        if x == 0.0:
            return 0.0
        a = y / x
        flip = False
    else:
        a = x / y
        flip = True
    a2 = a * a
    r = a * (
        0.9999993329
        + a2
        * (
            -0.3332985605
            + a2
            * (
                0.1994653599
                + a2
                * (-0.1390853351 + a2 * (0.0964200441 + a2 * (-0.0559098861 + a2 * (0.0218612288 - 0.0040540580 * a2))))
            )
        )
    )
    return 0.5 * math.pi - r if flip else r


@njit(cache=True, inline="always")
def _loading(c, s, eta):
    """f_p, f_q of eq. 2.25 from cos(eta), sin(eta) and eta (no trigonometric calls; cos 2eta = c^2 - s^2)."""
    fp = 0.5 - 0.1 * c + 0.1 * s - 0.4 * (c * c - s * s) - 0.22 * s * c
    fq = 0.01 * (2.008 + eta * (-0.3858 + eta * (1.9159 + eta * (-4.1615 + eta * (3.5064 - 1.1873 * eta)))))
    return max(fp, 0.0), max(fq, 0.0)


@njit(cache=True, inline="always")
def segment(pos, i):
    """Vector (m, NED) from node i - 1 to node i of the flat node positions ``pos``, and its length (m)."""
    a = 3 * (i - 1)
    b = 3 * i
    dx = pos[b] - pos[a]
    dy = pos[b + 1] - pos[a + 1]
    dz = pos[b + 2] - pos[a + 2]
    return dx, dy, dz, math.sqrt(dx * dx + dy * dy + dz * dz)


@njit(cache=True)
def cable_loads(
    pos,
    vel,
    F,
    Mn,
    n,
    l0,
    ea,
    cv,
    m_c,
    m_a,
    w_seg,
    kdrag,
    vcn,
    vce,
    cv_last=-1.0,
    law=0,
    kdt=0.0,
    l0_top=-1.0,
    ldot_top=0.0,
    wv=None,
    tau=0.0,
    fk=0.0,
):
    """Accumulate node forces ``F`` (3(n+1)) and node mass matrices ``Mn`` (6(n+1): xx xy xz yy yz zz).

    ``pos``, ``vel``: node positions and velocities (3(n+1), NED, node 0 on top). Loads of each segment
    are shared half-half by its end nodes (003 eq. 2.22-2.29); ``kdrag`` = rho C_d d l0 / 2 (0: no
    drag); ``w_seg`` the submerged weight of one segment (N); ``cv_last`` (if >= 0) replaces C_v for the
    last segment (the split integrator damps the others implicitly). ``law`` 0: loading functions (eq.
    2.25); 1: normal-tangential, normal drag -kdrag |V_p| V_p and tangential -kdt |v_q| v_q t (``kdrag`` =
    rho C_dn d l0 / 2, ``kdt`` = rho C_dt pi d l0 / 2). ``l0_top`` (if > 0) is the unstretched length of
    segment 1 (a winch's top segment): its stiffness EA / l0, mass, added mass, weight and drag scale with
    it; ``ldot_top`` (m/s) is the rate at which that length changes (the winch's line speed): the damper
    acts on the strain rate, C_v l0 d/dt(l / l0) = C_v (dl/dt - (l / l0) dl0/dt), so material paid out
    through the sheave is not "damped".

    **Waves** (issue 29; omitted ``wv``: calm water, the branch is compiled out; an empty ``wv``: calm
    water too, with the same compiled function as in waves): ``wv`` holds, per
    segment of this call, the expansion coefficients of the wave kinematics at its centre
    (:mod:`oceangnc.models._sea_layout`, evaluated at ``tau`` s from the expansion time). The drag then
    acts on the velocity relative to current plus wave orbital velocity, and the Morison inertia force
    (Morison et al. 1950; DNV-RP-C205 sec. 6.2.1) rho_w V a_w + C_a rho_w V a_w,n = ``fk`` a_w +
    m_a (I - t t^T) a_w is added, half to each node: Froude-Krylov on the whole displaced volume (the
    buoyancy is applied to it whole too), added mass on the normal component only (eq. 2.27). A
    segment whose centre is above the wave surface gets no wave kinematics. Allocates nothing.
    """
    for k in range(3 * (n + 1)):
        F[k] = 0.0
    for k in range(6 * (n + 1)):
        Mn[k] = 0.0
    for i in range(1, n + 1):
        sc = l0_top / l0 if (i == 1 and l0_top > 0.0) else 1.0
        l0i = l0 * sc
        half_w = 0.5 * w_seg * sc
        half_k = 0.5 * kdrag * sc
        kdti = kdt * sc
        ea_l0 = ea / l0i
        mt = 0.5 * (m_c + m_a) * sc
        ha = 0.5 * m_a * sc
        a = 3 * (i - 1)
        b = 3 * i
        dx, dy, dz, ln = segment(pos, i)
        if ln > 0.0:
            il = 1.0 / ln
            tx = dx * il
            ty = dy * il
            tz = dz * il
        else:
            tx = 0.0
            ty = 0.0
            tz = 1.0
        # axial force (eq. 2.22-2.23), tension only
        fax = 0.0
        if ln > l0i:
            rel = (vel[b] - vel[a]) * tx + (vel[b + 1] - vel[a + 1]) * ty + (vel[b + 2] - vel[a + 2]) * tz
            c_i = cv_last if (i == n and cv_last >= 0.0) else cv
            if i == 1:
                rel -= ln / l0i * ldot_top
            fax = ea_l0 * (ln - l0i) + c_i * rel
            if fax < 0.0:
                fax = 0.0
        hx = 0.0
        hy = 0.0
        hz = 0.0
        wn = we = wd = an = ae = ad = 0.0
        sea = False
        if SEA and wv is not None:  # wave kinematics at the segment centre (an empty ``wv``: calm water)
            sea = wv.size > 0
            if sea:
                wn, we, wd, an, ae, ad = point_kinematics(wv, NCOEF * (i - 1), tau, 0.5 * (pos[a + 2] + pos[b + 2]))
        # drag (eq. 2.24-2.25) on the relative velocity at the segment centre, half to each node
        if kdrag > 0.0 or kdt > 0.0:
            Vx = 0.5 * (vel[a] + vel[b]) - vcn
            Vy = 0.5 * (vel[a + 1] + vel[b + 1]) - vce
            Vz = 0.5 * (vel[a + 2] + vel[b + 2])
            if sea:
                Vx -= wn
                Vy -= we
                Vz -= wd
            vq = Vx * tx + Vy * ty + Vz * tz
            px = Vx - vq * tx
            py = Vy - vq * ty
            pz = Vz - vq * tz
            vp2 = px * px + py * py + pz * pz
            v2 = vq * vq + vp2
            if law == 1:
                cn = -half_k * math.sqrt(vp2)
                ct = -0.5 * kdti * abs(vq) * vq
                hx = cn * px + ct * tx
                hy = cn * py + ct * ty
                hz = cn * pz + ct * tz
            elif v2 > 0.0:
                vp = math.sqrt(vp2)
                avq = abs(vq)
                ivn = 1.0 / math.sqrt(v2)
                fp, fq = _loading(avq * ivn, vp * ivn, atan_ratio(vp, avq))
                cn = -half_k * v2 * fp / vp if vp > 0.0 else 0.0
                ct = -half_k * v2 * fq * (1.0 if vq > 0.0 else (-1.0 if vq < 0.0 else 0.0))
                hx = cn * px + ct * tx
                hy = cn * py + ct * ty
                hz = cn * pz + ct * tz
        if sea:  # Morison inertia (Froude-Krylov + normal added mass), half to each node
            ta = an * tx + ae * ty + ad * tz
            hfk = 0.5 * fk * sc
            hx += hfk * an + ha * (an - ta * tx)
            hy += hfk * ae + ha * (ae - ta * ty)
            hz += hfk * ad + ha * (ad - ta * tz)
        # tension pulls node i-1 toward i and node i toward i-1; weight minus buoyancy down (+z)
        fx = fax * tx
        fy = fax * ty
        fz = fax * tz
        F[a] += hx + fx
        F[a + 1] += hy + fy
        F[a + 2] += hz + fz + half_w
        F[b] += hx - fx
        F[b + 1] += hy - fy
        F[b + 2] += hz - fz + half_w
        # node mass matrices (eq. 2.27-2.28): 1/2 [(m_c + m_a) I - m_a t t^T] to each end
        mxx = mt - ha * tx * tx
        mxy = -ha * tx * ty
        mxz = -ha * tx * tz
        myy = mt - ha * ty * ty
        myz = -ha * ty * tz
        mzz = mt - ha * tz * tz
        for ce in (6 * (i - 1), 6 * i):
            Mn[ce] += mxx
            Mn[ce + 1] += mxy
            Mn[ce + 2] += mxz
            Mn[ce + 3] += myy
            Mn[ce + 4] += myz
            Mn[ce + 5] += mzz


@njit(cache=True, inline="always")
def solve_sym3(M, c, fx, fy, fz):
    """Solve the symmetric 3x3 system stored at M[c:c+6] (xx xy xz yy yz zz) for (fx, fy, fz)."""
    a = M[c]
    b = M[c + 1]
    d = M[c + 2]
    e = M[c + 3]
    f = M[c + 4]
    g = M[c + 5]
    c00 = e * g - f * f
    c01 = d * f - b * g
    c02 = b * f - d * e
    c11 = a * g - d * d
    c12 = b * d - a * f
    c22 = a * e - b * b
    det = a * c00 + b * c01 + d * c02
    inv = 1.0 / det
    return (
        (c00 * fx + c01 * fy + c02 * fz) * inv,
        (c01 * fx + c11 * fy + c12 * fz) * inv,
        (c02 * fx + c12 * fy + c22 * fz) * inv,
    )


def _rk4_amplification(z):
    return np.abs(1 + z + z * z / 2 + z**3 / 6 + z**4 / 24)


def axial_eigenvalues(cfg: CableConfig, end_mass: float | None = None, last_damper_only: bool = False) -> np.ndarray:
    """Eigenvalues (1/s) of the linearised axial chain: top node fixed, nodes 1..n free.

    Node masses are m_c (interior) and m_c / 2 + ``end_mass`` at the bottom (the UUV's surge mass;
    None: bottom node fixed too); springs EA / l0 and dampers C_v between neighbours
    (``last_damper_only``: only the bottom segment's damper, as in the explicit part of "rk4-split").
    """
    n = cfg.segments
    k = cfg.EA / cfg.l0
    c = cfg.damping
    mc = cfg.segment_mass
    free = n if end_mass is not None else n - 1
    if free < 1:
        # one segment between two fixed ends: no free node; the UUV end alone
        free = 0
    if free == 0:
        return np.zeros(0, complex)
    L = np.zeros((free, free))
    for i in range(free):
        L[i, i] = 2.0
        if i > 0:
            L[i, i - 1] = -1.0
        if i < free - 1:
            L[i, i + 1] = -1.0
    if end_mass is not None:
        L[free - 1, free - 1] = 1.0  # bottom node: one spring only
    m = np.full(free, mc)
    if end_mass is not None:
        m[-1] = 0.5 * mc + end_mass
    Minv = np.diag(1.0 / m)
    A = np.zeros((2 * free, 2 * free))
    A[:free, free:] = np.eye(free)
    A[free:, :free] = -k * Minv @ L
    if last_damper_only:
        Lc = np.zeros((free, free))
        if end_mass is not None:  # damper between nodes n-1 and n (node n is the last free one)
            Lc[free - 1, free - 1] = 1.0
            if free > 1:
                Lc[free - 2, free - 2] = 1.0
                Lc[free - 1, free - 2] = Lc[free - 2, free - 1] = -1.0
        else:  # bottom fixed: damper between node n-1 (last free) and the fixed end
            Lc[free - 1, free - 1] = 1.0
        A[free:, free:] = -c * Minv @ Lc
    else:
        A[free:, free:] = -c * Minv @ L
    return np.linalg.eigvals(A)


def axial_stability_limit(cfg: CableConfig, end_mass: float | None = None, last_damper_only: bool = False) -> float:
    """Largest classical-RK4 step (s) stable for every axial mode of the lumped-mass chain.

    Bisection on h with the RK4 amplification |R(h lambda)| <= 1 for all eigenvalues of
    :func:`axial_eigenvalues`, starting from below (the first h where any mode becomes unstable).
    """
    lam = axial_eigenvalues(cfg, end_mass, last_damper_only)
    lam = lam[np.abs(lam) > 1e-12]
    if lam.size == 0:
        return math.inf
    rmax = float(np.max(np.abs(lam)))
    return stability_limit(lam, _rk4_amplification, 1e-3 / rmax, 10.0 / rmax)


def highest_axial_mode(cfg: CableConfig, end_mass: float | None = None) -> float:
    """|lambda| (1/s) of the fastest axial mode of the lumped-mass chain."""
    lam = axial_eigenvalues(cfg, end_mass)
    return float(np.max(np.abs(lam))) if lam.size else 0.0


def stable_step(limit: float, period: float = 0.01, safety: float = 0.9) -> float:
    """The largest step <= ``safety`` x ``limit`` that divides ``period`` (s) an integer number of times."""
    if not math.isfinite(limit):
        return period
    k = math.ceil(period / (safety * limit) - 1e-12)
    return period / max(k, 1)
