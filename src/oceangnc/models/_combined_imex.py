"""The combined plant's "imex" integrator: a ROS2 Rosenbrock W-method with the cable's axial stiffness
and damping implicit (block-tridiagonal Jacobian, factored and solved in O(n) per step).
"""

from __future__ import annotations

import math

from numba import njit

from ._combined_layout import (
    tow_frame,
    cross_add,
    rot_add,
    H_N,
    H_TOP,
    H_ATT,
    H_L0,
    H_EA,
    H_CV,
    H_PO,
    H_VO,
    H_WIN,
    H_WO,
    H_SEA,
    H_BRI,
    P_SCR,
    P_UUV,
    top_l0,
    _inv3,
)
from ._combined_bridle import B_SAVE
from ._combined_kernels import combined_rhs
from ._combined_events import track_events
from .uuv import P_RC
from ._combined_winch import remesh
from ._sea_layout import S_WF, W_XO, lever_ned, top_heave
from .cable import segment

ROS2_GAMMA = 1.0 + 1.0 / math.sqrt(2.0)


# feature switches (oceangnc.core.variants): True here, so the functions as written handle every
# configuration (the runtime flags in p decide); ._combined_variants compiles copies with the features
# a plant does not use switched off, whose code numba then never compiles
SEA = WINCH = BRIDLE = True


@njit(cache=True, inline="always")
def _imex_base(n):
    return P_SCR + 40 * (n + 1)


@njit(cache=True)
def _imex_factor(x, p, n, gh):
    """Assemble and factor (M + gh C + gh^2 K) for the interior nodes 1..n-1 (block Thomas, O(n)).

    Uses the node positions and mass matrices left in the scratch by the last :func:`combined_rhs` call
    (at x_n). Per taut segment s (nodes s-1, s): tangent stiffness K_s = EA/l0 t t^T + T/l (I - t t^T)
    (axial spring plus the geometric stiffness of the tension T = EA (l - l0) / l0, the latter for taut
    segments only), damping C_s = C_v t t^T. Stores K_s (6), S_s = gh C_s + gh^2 K_s (6) per
    segment, the node mass matrices M_i (6) and the inverted modified diagonal blocks D_i^-1 (9).
    The top node and the UUV's tow point are not unknowns: the segments that join them add their S to
    the diagonal of nodes 1 and n-1 only.
    """
    m = 3 * (n + 1)
    pos = p[P_SCR : P_SCR + m]
    Mn = p[P_SCR + 3 * m : P_SCR + 5 * m]
    base = _imex_base(n)
    K = p[base : base + 6 * (n + 1)]
    S = p[base + 6 * (n + 1) : base + 12 * (n + 1)]
    Ms = p[base + 12 * (n + 1) : base + 18 * (n + 1)]
    Di = p[base + 18 * (n + 1) : base + 27 * (n + 1)]
    lt = top_l0(x, p, n)
    cv = p[H_CV]
    gh2 = gh * gh
    for s in range(1, n + 1):
        l0 = lt if s == 1 else p[H_L0]
        ea_l0 = p[H_EA] / l0
        dx, dy, dz, ln = segment(pos, s)
        c = 6 * s
        if s == 1:  # winch: dF_1/dL and dF_1/ds (top segment taut), known-stage terms of the solve
            G = p[base + 30 * (n + 1) + 30 : base + 30 * (n + 1) + 36]
            for k in range(6):
                G[k] = 0.0
            if WINCH and p[H_WIN] > 0.5 and ln > l0:
                gl = p[H_EA] * ln / (l0 * l0)
                gs = cv * ln / l0
                G[0] = gl * dx / ln
                G[1] = gl * dy / ln
                G[2] = gl * dz / ln
                G[3] = gs * dx / ln
                G[4] = gs * dy / ln
                G[5] = gs * dz / ln
        if ln > 0.0:
            # the axial stiffness and damping are kept in J while the segment is slack too: a segment that
            # becomes taut within the step must not meet an explicit stiff spring (W-method: any J keeps the
            # order; for a slack segment this only filters the relative axial velocity increments)
            tx = dx / ln
            ty = dy / ln
            tz = dz / ln
            g = ea_l0 * (ln - l0) / ln if ln > l0 else 0.0  # T / l (geometric stiffness, taut only)
            ka = ea_l0 - g
            K[c] = ka * tx * tx + g
            K[c + 1] = ka * tx * ty
            K[c + 2] = ka * tx * tz
            K[c + 3] = ka * ty * ty + g
            K[c + 4] = ka * ty * tz
            K[c + 5] = ka * tz * tz + g
            ghc = gh * cv
            S[c] = gh2 * K[c] + ghc * tx * tx
            S[c + 1] = gh2 * K[c + 1] + ghc * tx * ty
            S[c + 2] = gh2 * K[c + 2] + ghc * tx * tz
            S[c + 3] = gh2 * K[c + 3] + ghc * ty * ty
            S[c + 4] = gh2 * K[c + 4] + ghc * ty * tz
            S[c + 5] = gh2 * K[c + 5] + ghc * tz * tz
        else:
            for k in range(6):
                K[c + k] = 0.0
                S[c + k] = 0.0
    for k in range(6 * (n + 1)):
        Ms[k] = Mn[k]
    # forward elimination: D_1 = A_11; D_i = A_ii - S_i D_{i-1}^-1 S_i
    for i in range(1, n):
        cm = 6 * i
        ca = 6 * i  # segment i (above node i)
        cb = 6 * (i + 1)  # segment i+1 (below)
        a00 = Ms[cm] + S[ca] + S[cb]
        a01 = Ms[cm + 1] + S[ca + 1] + S[cb + 1]
        a02 = Ms[cm + 2] + S[ca + 2] + S[cb + 2]
        a11 = Ms[cm + 3] + S[ca + 3] + S[cb + 3]
        a12 = Ms[cm + 4] + S[ca + 4] + S[cb + 4]
        a22 = Ms[cm + 5] + S[ca + 5] + S[cb + 5]
        A = (a00, a01, a02, a01, a11, a12, a02, a12, a22)
        if i > 1:
            q = 9 * (i - 1)
            s00, s01, s02, s11, s12, s22 = S[ca], S[ca + 1], S[ca + 2], S[ca + 3], S[ca + 4], S[ca + 5]
            # W = D^-1 S (3x3), then S W
            w = p[base + 30 * (n + 1) + 12 : base + 30 * (n + 1) + 21]
            for r in range(3):
                d0 = Di[q + 3 * r]
                d1 = Di[q + 3 * r + 1]
                d2 = Di[q + 3 * r + 2]
                w[3 * r] = d0 * s00 + d1 * s01 + d2 * s02
                w[3 * r + 1] = d0 * s01 + d1 * s11 + d2 * s12
                w[3 * r + 2] = d0 * s02 + d1 * s12 + d2 * s22
            srow = (s00, s01, s02, s01, s11, s12, s02, s12, s22)
            A2 = p[base + 30 * (n + 1) + 21 : base + 30 * (n + 1) + 30]
            for r in range(3):
                for cc in range(3):
                    A2[3 * r + cc] = A[3 * r + cc] - (
                        srow[3 * r] * w[cc] + srow[3 * r + 1] * w[3 + cc] + srow[3 * r + 2] * w[6 + cc]
                    )
            _inv3(A2, 0, Di, 9 * i)
        else:
            A2 = p[base + 30 * (n + 1) + 21 : base + 30 * (n + 1) + 30]
            for k in range(9):
                A2[k] = A[k]
            _inv3(A2, 0, Di, 9 * i)


@njit(cache=True, inline="always")
def _imex_end_increments(x, k, p, n, e, t=0.0, kt=0.0):
    """Stage increments of the two end nodes (not unknowns of the implicit solve) into ``e`` (12):
    position part a_0, velocity part b_0 of the top node, then a_n, b_n of the UUV's tow point.

    They are the end nodes' positions/velocities linearised in the vehicles' states times the vehicles'
    stage vectors (which the implicit solve does not change): the J columns of the vehicles' states
    enter the cable rows as known terms, so the nodes next to the ends follow the vehicles' motion
    within the step instead of lagging by ~ gamma h v (which would be a first-order error).

    A heaving top point (issue 29) moves with time, not with a state: time is the state with the stage
    increment ``kt`` (+1 in the first ROS2 stage, 1 - 2 = -1 in the second), and the top node's
    increments get its heave velocity and acceleration at ``t`` times ``kt``.
    """
    if p[H_TOP] > 0.5:
        for j in range(6):
            e[j] = 0.0
    else:
        c = math.cos(x[2])
        s = math.sin(x[2])
        ax = p[H_ATT]
        ay = p[H_ATT + 1]
        kp = k[2]
        e[0] = k[0] + (-s * ax - c * ay) * kp
        e[1] = k[1] + (c * ax - s * ay) * kp
        e[2] = 0.0
        ub, vb = x[3] - x[5] * ay, x[4] + x[5] * ax  # as in _ends, and its stage increment
        kub, kvb = k[3] - k[5] * ay, k[4] + k[5] * ax
        e[3] = c * kub - s * kvb + (-s * ub - c * vb) * kp
        e[4] = s * kub + c * kvb + (c * ub - s * vb) * kp
        e[5] = 0.0
    if SEA and p[H_SEA] > 0.0:
        sb = int(p[H_SEA])
        _, wz, az = top_heave(p, sb, t)
        e[2] += kt * wz
        e[5] += kt * az
        w = int(p[sb + S_WF])
        if w > 0 and p[H_TOP] < 0.5:  # the USV's wave-frequency motion moves the top node (part B)
            ow = int(p[w + W_XO])
            dn, de, dd = lever_ned(k, ow, w, p, x[2])
            e[0] += dn
            e[1] += de
            e[2] += dd
            dn, de, dd = lever_ned(k, ow + 6, w, p, x[2])
            e[3] += dn
            e[4] += de
            e[5] += dd
    o, R, cx, cy, cz = tow_frame(x, p)
    # a_n = k_eta1 + R (Omega x r_c), Omega ~ the Euler-angle increments (small-angle rate map)
    bx, by, bz = cross_add(0.0, 0.0, 0.0, k[o + 3], k[o + 4], k[o + 5], cx, cy, cz)
    e[6], e[7], e[8] = rot_add(R, k[o], k[o + 1], k[o + 2], bx, by, bz)
    # b_n = R (k_v + k_omega x r_c)
    bu, bv, bw = cross_add(k[o + 6], k[o + 7], k[o + 8], k[o + 9], k[o + 10], k[o + 11], cx, cy, cz)
    e[9], e[10], e[11] = rot_add(R, 0.0, 0.0, 0.0, bu, bv, bw)


@njit(cache=True)
def _imex_solve(x, p, n, k, gh, t=0.0, kt=0.0):
    """Replace the cable part of the stage vector ``k`` by (I - gh J)^-1 k (J: cable axial Jacobian).

    With k = (a, q) (node velocities a, node accelerations q) the block system is
    (M + gh C + gh^2 K) b = M q - gh K a, then a' = a + gh b (see :func:`_imex_factor`).
    """
    if n < 2:
        return
    base = _imex_base(n)
    K = p[base : base + 6 * (n + 1)]
    S = p[base + 6 * (n + 1) : base + 12 * (n + 1)]
    Ms = p[base + 12 * (n + 1) : base + 18 * (n + 1)]
    Di = p[base + 18 * (n + 1) : base + 27 * (n + 1)]
    R = p[base + 27 * (n + 1) : base + 30 * (n + 1)]
    e = p[base + 30 * (n + 1) : base + 30 * (n + 1) + 12]
    _imex_end_increments(x, k, p, n, e, t, kt)
    gh2 = gh * gh
    po = int(p[H_PO])
    vo = int(p[H_VO])
    # right-hand side and forward sweep
    for i in range(1, n):
        j = 3 * (i - 1)
        ax = k[po + j]
        ay = k[po + j + 1]
        az = k[po + j + 2]
        qx = k[vo + j]
        qy = k[vo + j + 1]
        qz = k[vo + j + 2]
        cm = 6 * i
        r0 = Ms[cm] * qx + Ms[cm + 1] * qy + Ms[cm + 2] * qz
        r1 = Ms[cm + 1] * qx + Ms[cm + 3] * qy + Ms[cm + 4] * qz
        r2 = Ms[cm + 2] * qx + Ms[cm + 4] * qy + Ms[cm + 5] * qz
        # (K a)_i = K_i (a_i - a_{i-1}) + K_{i+1} (a_i - a_{i+1}), a_0 = a_n = 0
        dx = ax
        dy = ay
        dz = az
        if i > 1:
            dx -= k[po + j - 3]
            dy -= k[po + j - 2]
            dz -= k[po + j - 1]
        c = 6 * i
        r0 -= gh * (K[c] * dx + K[c + 1] * dy + K[c + 2] * dz)
        r1 -= gh * (K[c + 1] * dx + K[c + 3] * dy + K[c + 4] * dz)
        r2 -= gh * (K[c + 2] * dx + K[c + 4] * dy + K[c + 5] * dz)
        dx = ax
        dy = ay
        dz = az
        if i < n - 1:
            dx -= k[po + j + 3]
            dy -= k[po + j + 4]
            dz -= k[po + j + 5]
        c = 6 * (i + 1)
        r0 -= gh * (K[c] * dx + K[c + 1] * dy + K[c + 2] * dz)
        r1 -= gh * (K[c + 1] * dx + K[c + 3] * dy + K[c + 4] * dz)
        r2 -= gh * (K[c + 2] * dx + K[c + 4] * dy + K[c + 5] * dz)
        # known end nodes j (top for i = 1, tow point for i = n - 1):
        # + gh K_s a_j + gh C_s b_j = K_s (gh a_j - gh^2 b_j) + S_s b_j
        for end in range(2):
            if (end == 0 and i != 1) or (end == 1 and i != n - 1):
                continue
            c = 6 if end == 0 else 6 * n
            eo = 6 * end
            ax_ = gh * e[eo] - gh2 * e[eo + 3]
            ay_ = gh * e[eo + 1] - gh2 * e[eo + 4]
            az_ = gh * e[eo + 2] - gh2 * e[eo + 5]
            bx_ = e[eo + 3]
            by_ = e[eo + 4]
            bz_ = e[eo + 5]
            r0 += K[c] * ax_ + K[c + 1] * ay_ + K[c + 2] * az_ + S[c] * bx_ + S[c + 1] * by_ + S[c + 2] * bz_
            r1 += K[c + 1] * ax_ + K[c + 3] * ay_ + K[c + 4] * az_ + S[c + 1] * bx_ + S[c + 3] * by_ + S[c + 4] * bz_
            r2 += K[c + 2] * ax_ + K[c + 4] * ay_ + K[c + 5] * az_ + S[c + 2] * bx_ + S[c + 4] * by_ + S[c + 5] * bz_
        if WINCH and i == 1 and p[H_WIN] > 0.5:  # + gh (dF_1/dL k_L + dF_1/ds k_s), the winch's stage known
            G = p[base + 30 * (n + 1) + 30 : base + 30 * (n + 1) + 36]
            wo = int(p[H_WO])
            kl = gh * k[wo]
            ks = gh * k[wo + 1]
            r0 += G[0] * kl + G[3] * ks
            r1 += G[1] * kl + G[4] * ks
            r2 += G[2] * kl + G[5] * ks
        if i > 1:  # r_i += S_i D_{i-1}^-1 r_{i-1}
            q = 9 * (i - 1)
            ro = 3 * (i - 1)
            y0 = Di[q] * R[ro] + Di[q + 1] * R[ro + 1] + Di[q + 2] * R[ro + 2]
            y1 = Di[q + 3] * R[ro] + Di[q + 4] * R[ro + 1] + Di[q + 5] * R[ro + 2]
            y2 = Di[q + 6] * R[ro] + Di[q + 7] * R[ro + 1] + Di[q + 8] * R[ro + 2]
            c = 6 * i
            r0 += S[c] * y0 + S[c + 1] * y1 + S[c + 2] * y2
            r1 += S[c + 1] * y0 + S[c + 3] * y1 + S[c + 4] * y2
            r2 += S[c + 2] * y0 + S[c + 4] * y1 + S[c + 5] * y2
        R[3 * i] = r0
        R[3 * i + 1] = r1
        R[3 * i + 2] = r2
    # back substitution: b_i = D_i^-1 (r_i + S_{i+1} b_{i+1})
    b0 = 0.0
    b1 = 0.0
    b2 = 0.0
    for i in range(n - 1, 0, -1):
        r0 = R[3 * i]
        r1 = R[3 * i + 1]
        r2 = R[3 * i + 2]
        if i < n - 1:
            c = 6 * (i + 1)
            r0 += S[c] * b0 + S[c + 1] * b1 + S[c + 2] * b2
            r1 += S[c + 1] * b0 + S[c + 3] * b1 + S[c + 4] * b2
            r2 += S[c + 2] * b0 + S[c + 4] * b1 + S[c + 5] * b2
        q = 9 * i
        b0 = Di[q] * r0 + Di[q + 1] * r1 + Di[q + 2] * r2
        b1 = Di[q + 3] * r0 + Di[q + 4] * r1 + Di[q + 5] * r2
        b2 = Di[q + 6] * r0 + Di[q + 7] * r1 + Di[q + 8] * r2
        j = 3 * (i - 1)
        k[vo + j] = b0
        k[vo + j + 1] = b1
        k[vo + j + 2] = b2
        k[po + j] += gh * b0
        k[po + j + 1] += gh * b1
        k[po + j + 2] += gh * b2


@njit(cache=True)
def imex_advance(t, x, u, p, dt, nsteps, work, bound):
    """ROS2 steps (Verwer et al. 1999, a second-order L-stable Rosenbrock W-method, gamma = 1 + 1/sqrt 2)
    with the cable's axial stiffness and damping as the implicit part:

        (I - gamma h J) k1 = f(x_n)
        (I - gamma h J) k2 = f(x_n + h k1) - 2 k1
        x_{n+1} = x_n + 3/2 h k1 + 1/2 h k2

    f is the full right-hand side (:func:`combined_rhs`: drag, weight, added mass, both vehicles, all
    explicit); J is the Jacobian of the interior nodes' axial forces only (tangent stiffness and C_v,
    block tridiagonal, :func:`_imex_factor`), so each step costs two RHS evaluations, one block-Thomas
    factorisation and two O(n) solves. Second order for any J (W-method); with J = 0 it is Heun's
    method. Equilibria f(x) = 0 are fixed points for every h. Returns the new time, or -1 - k if the
    state became non-finite or exceeded ``bound`` at step k.
    """
    k1 = work[0]
    k2 = work[1]
    xt = work[4]
    m = x.size
    winch = p[H_WIN] > 0.5
    for s in range(nsteps):
        n = int(p[H_N])
        gh = ROS2_GAMMA * dt
        combined_rhs(t, x, u, p, k1)
        if n >= 2:
            _imex_factor(x, p, n, gh)
            _imex_solve(x, p, n, k1, gh, t, 1.0)
        bri = int(p[H_BRI])
        if BRIDLE and bri > 0:  # the bridle's junction at x_n: both stages' end increments use it (one J)
            for i in range(3):
                p[bri + B_SAVE + i] = p[P_UUV + P_RC + i]
        for i in range(m):
            xt[i] = x[i] + dt * k1[i]
        combined_rhs(t + dt, xt, u, p, k2)
        for i in range(m):
            k2[i] -= 2.0 * k1[i]
        if BRIDLE and bri > 0:
            for i in range(3):
                p[P_UUV + P_RC + i] = p[bri + B_SAVE + i]
        if n >= 2:
            _imex_solve(x, p, n, k2, gh, t, -1.0)
        ok = True
        for i in range(m):
            x[i] += dt * (1.5 * k1[i] + 0.5 * k2[i])
            if not (abs(x[i]) <= bound):
                ok = False
        if not ok:
            return -1.0 - s
        if WINCH and winch:
            remesh(x, p)
        t += dt
        if SEA and p[H_SEA] > 0.0:  # slack and snap events on every step (._combined_events)
            track_events(t, x, u, p)
    return t
