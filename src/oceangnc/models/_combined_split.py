"""The combined plant's "rk4-split" integrator: Strang splitting of the cable's axial damping.

:func:`damping_substep` is a backward-Euler step of the axial damping alone (block Thomas algorithm
over the interior nodes), :func:`split_advance` the damping(dt/2) - RK4(dt) - damping(dt/2) steps.
"""

from __future__ import annotations


from numba import njit

from ..core.integrators import rk4_step
from ._combined_layout import (
    H_N,
    H_L0,
    H_CV,
    H_MC,
    H_MA,
    H_SEA,
    P_SCR,
    _gather,
    _inv3,
)
from ._combined_events import track_events
from ._combined_kernels import combined_rhs
from .cable import segment

# feature switch (oceangnc.core.variants): True here; the plain plant's copy never compiles the event tracker
SEA = True


@njit(cache=True)
def damping_substep(x, p, h):
    """Backward-Euler step of length ``h`` of the axial damping alone on the interior node velocities.

    Solves (M + h C) v+ = M v for the block-tridiagonal damping matrix C of the stretched segments
    (C_v t t^T per segment, 003 eq. 2.23) of segments 1..n-1 by the block Thomas algorithm, the top
    node's velocity held (the USV is not loaded by the cable). The last segment's damper stays in the
    explicit RHS, so its reaction acts on the UUV. Unconditionally stable and dissipative.
    """
    n = int(p[H_N])
    cv = p[H_CV]
    if n < 2 or cv == 0.0:
        return
    pos, vel, F, Mn = _gather(x, p, n)
    m3 = 3 * (n + 1)
    base = P_SCR + 15 * (n + 1)
    T = p[base : base + m3]  # tangents of segments 1..n at T[3 i - 3 ...], taut flag folded in (0 vector)
    D = p[base + m3 : base + m3 + 9 * (n + 1)]  # inverted modified diagonal blocks
    R = p[base + m3 + 9 * (n + 1) : base + m3 + 12 * (n + 1)]  # modified right-hand sides
    W = p[base + m3 + 12 * (n + 1) : base + m3 + 21 * (n + 1)]  # work 3x3 blocks
    l0 = p[H_L0]
    mt = 0.5 * (p[H_MC] + p[H_MA])
    ha = 0.5 * p[H_MA]
    for i in range(1, n + 1):
        dx, dy, dz, ln = segment(pos, i)
        k = 3 * (i - 1)
        if ln > l0 and i < n:  # the last segment's damper stays explicit (its reaction acts on the UUV)
            T[k] = dx / ln
            T[k + 1] = dy / ln
            T[k + 2] = dz / ln
        else:
            T[k] = 0.0
            T[k + 1] = 0.0
            T[k + 2] = 0.0
    hc = h * cv
    # forward sweep over interior nodes i = 1..n-1; segment i joins nodes i-1, i
    for i in range(1, n):
        ka = 3 * (i - 1)  # segment i (above)
        kb = 3 * i  # segment i+1 (below)
        tax, tay, taz = T[ka], T[ka + 1], T[ka + 2]
        tbx, tby, tbz = T[kb], T[kb + 1], T[kb + 2]
        # node mass matrix (both adjacent segments, eq. 2.28), with the *current* tangents
        # (slack segments and the last one use a zero tangent here, so their added mass counts
        # isotropically: a small inconsistency with the RHS's mass matrix, see docs/uuv-and-cable.md)
        A = W
        ta = (tax, tay, taz)
        tb = (tbx, tby, tbz)
        ma = ta
        mb = tb
        for r in range(3):
            for c in range(3):
                mm = (2.0 * mt if r == c else 0.0) - ha * (ma[r] * ma[c] + mb[r] * mb[c])
                A[3 * r + c] = mm + hc * (ta[r] * ta[c] + tb[r] * tb[c])
        vi0 = vel[3 * i]
        vi1 = vel[3 * i + 1]
        vi2 = vel[3 * i + 2]
        r0 = 0.0
        r1 = 0.0
        r2 = 0.0
        vv = (vi0, vi1, vi2)
        for r in range(3):
            acc = 0.0
            for c in range(3):
                acc += ((2.0 * mt if r == c else 0.0) - ha * (ma[r] * ma[c] + mb[r] * mb[c])) * vv[c]
            if r == 0:
                r0 = acc
            elif r == 1:
                r1 = acc
            else:
                r2 = acc
        if i == 1:  # top node velocity held: + h c t t^T v_0
            v0 = vel[0] * tax + vel[1] * tay + vel[2] * taz
            r0 += hc * tax * v0
            r1 += hc * tay * v0
            r2 += hc * taz * v0
        if i > 1:
            # L = A_{i,i-1} D_{i-1}^{-1} with A_{i,i-1} = -hc ta ta^T; A' = A - L A_{i-1,i} (= -hc ta ta^T)
            q = 9 * (i - 1)
            # u = D^{-1} ta ; s = ta . D^{-1} ta ; L v = -hc ta (ta^T D^{-1} v)
            u0 = D[q] * tax + D[q + 1] * tay + D[q + 2] * taz
            u1 = D[q + 3] * tax + D[q + 4] * tay + D[q + 5] * taz
            u2 = D[q + 6] * tax + D[q + 7] * tay + D[q + 8] * taz
            w0 = tax * D[q] + tay * D[q + 3] + taz * D[q + 6]
            w1 = tax * D[q + 1] + tay * D[q + 4] + taz * D[q + 7]
            w2 = tax * D[q + 2] + tay * D[q + 5] + taz * D[q + 8]
            sdot = tax * u0 + tay * u1 + taz * u2
            g = hc * hc * sdot
            for r in range(3):
                for c in range(3):
                    A[3 * r + c] -= g * ta[r] * ta[c]
            rp = 3 * (i - 1)
            proj = w0 * R[rp] + w1 * R[rp + 1] + w2 * R[rp + 2]
            r0 += hc * tax * proj
            r1 += hc * tay * proj
            r2 += hc * taz * proj
        _inv3(A, 0, D, 9 * i)
        R[3 * i] = r0
        R[3 * i + 1] = r1
        R[3 * i + 2] = r2
    # back substitution: v_i = D_i^{-1} (R_i - A_{i,i+1} v_{i+1}), A_{i,i+1} = -hc tb tb^T
    vo = 6 + 3 * (n - 1)
    nx0 = 0.0
    nx1 = 0.0
    nx2 = 0.0
    for i in range(n - 1, 0, -1):
        kb = 3 * i
        tbx, tby, tbz = T[kb], T[kb + 1], T[kb + 2]
        b0 = R[3 * i]
        b1 = R[3 * i + 1]
        b2 = R[3 * i + 2]
        if i < n - 1:
            pr = tbx * nx0 + tby * nx1 + tbz * nx2
            b0 += hc * tbx * pr
            b1 += hc * tby * pr
            b2 += hc * tbz * pr
        q = 9 * i
        nx0 = D[q] * b0 + D[q + 1] * b1 + D[q + 2] * b2
        nx1 = D[q + 3] * b0 + D[q + 4] * b1 + D[q + 5] * b2
        nx2 = D[q + 6] * b0 + D[q + 7] * b1 + D[q + 8] * b2
        j = vo + 3 * (i - 1)
        x[j] = nx0
        x[j + 1] = nx1
        x[j + 2] = nx2


@njit(cache=True)
def split_advance(t, x, u, p, dt, nsteps, work, bound):
    """Strang splitting: damping(dt/2, implicit) - RK4(dt, everything else) - damping(dt/2, implicit).

    The closing and opening half steps of consecutive steps are fused into one backward-Euler step of
    dt (exact for the first-order damping flow up to O(dt^2), like the splitting itself). Second order;
    removes the overdamped axial mode (lambda ~ -C_v 4 / m_c) from the explicit part, whose limit is
    then that of the axial springs alone. Returns the new time, or -1 - k if the state became
    non-finite or exceeded ``bound`` in magnitude at step k.
    """
    damping_substep(x, p, 0.5 * dt)
    for s in range(nsteps):
        # the one RK4 step of core.integrators (inlined, so this function stays disk-cached)
        if not rk4_step(combined_rhs, t, x, u, p, dt, work, bound):
            return -1.0 - s
        # the closing half step of this step and the opening half step of the next are fused
        damping_substep(x, p, dt if s < nsteps - 1 else 0.5 * dt)
        t += dt
        if SEA and p[H_SEA] > 0.0:  # slack and snap events on every step (._combined_events)
            track_events(t, x, u, p)
    return t
