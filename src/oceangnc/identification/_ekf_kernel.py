"""Compiled kernel of the augmented EKF (see :mod:`oceangnc.identification.ekf` for the equations).

This file is a *template*: the model functions are the module globals ``_f`` (dx/dt), ``_h``
(measurements), ``_jac`` (analytic Jacobian or a placeholder) and ``_fjac`` / ``_hjac`` (the Jacobian
strategy), bound by :func:`oceangnc.identification.ekf.kernel_for` in a private copy of this file per
(model, Jacobian mode). Numba resolves globals when it compiles, so each copy is compiled once against
its own model with direct calls, and its machine code is cached on disk next to the copy (numba
cannot cache functions that receive other compiled functions as arguments, which would otherwise
cost a full recompilation of this loop in every process).

Everything here is allocation-free inside the sample loop; the matrices are small (n = n_s + n_a).
"""

import math

import numpy as np
from numba import njit

_f = None  # f(x, p, u, out): dx/dt
_h = None  # h(x, p, out): predicted measurements
_jac = None  # jac(x, p, u, J): J = [df/dx, df/dp] (analytic) or placeholder
_fjac = None  # one of fjac_analytic / fjac_cs / fjac_fd below
_hjac = None  # one of hjac_cs / hjac_fd below

OK, NONFINITE, NOT_PD, BOUND = 0, 1, 2, 3
CS_STEP = 1e-20  # complex step, relative to max(|y|, 1e-3)
FD_STEP = 1e-6  # central-difference step, relative to max(|y|, 1e-3)


@njit(cache=True)
def fjac_analytic(x, p, u, cols, J, Jfull, xc, pc, oc, o1, o2, xr, pr):
    """Columns ``cols`` (indices into [x, p]) of df/d[x, p] from the model's analytic Jacobian."""
    _jac(x, p, u, Jfull)
    ns = x.size
    for c in range(cols.size):
        for i in range(ns):
            J[i, c] = Jfull[i, cols[c]]


@njit(cache=True)
def fjac_cs(x, p, u, cols, J, Jfull, xc, pc, oc, o1, o2, xr, pr):
    """Columns ``cols`` of df/d[x, p] by complex step, Im f(y + i h e_j) / h (exact to rounding)."""
    ns = x.size
    for i in range(ns):
        xc[i] = x[i]
    for i in range(p.size):
        pc[i] = p[i]
    for c in range(cols.size):
        j = cols[c]
        if j < ns:
            hh = CS_STEP * max(abs(x[j]), 1e-3)
            xc[j] = x[j] + 1j * hh
        else:
            hh = CS_STEP * max(abs(p[j - ns]), 1e-3)
            pc[j - ns] = p[j - ns] + 1j * hh
        _f(xc, pc, u, oc)
        for i in range(ns):
            J[i, c] = oc[i].imag / hh
        if j < ns:
            xc[j] = x[j]
        else:
            pc[j - ns] = p[j - ns]


@njit(cache=True)
def fjac_fd(x, p, u, cols, J, Jfull, xc, pc, oc, o1, o2, xr, pr):
    """Columns ``cols`` of df/d[x, p] by central differences (approximate; a fallback only)."""
    ns = x.size
    for i in range(ns):
        xr[i] = x[i]
    for i in range(p.size):
        pr[i] = p[i]
    for c in range(cols.size):
        j = cols[c]
        if j < ns:
            hh = FD_STEP * max(abs(x[j]), 1e-3)
            xr[j] = x[j] + hh
            _f(xr, pr, u, o1)
            xr[j] = x[j] - hh
            _f(xr, pr, u, o2)
            xr[j] = x[j]
        else:
            hh = FD_STEP * max(abs(p[j - ns]), 1e-3)
            pr[j - ns] = p[j - ns] + hh
            _f(xr, pr, u, o1)
            pr[j - ns] = p[j - ns] - hh
            _f(xr, pr, u, o2)
            pr[j - ns] = p[j - ns]
        for i in range(ns):
            J[i, c] = (o1[i] - o2[i]) / (2.0 * hh)


@njit(cache=True)
def hjac_cs(x, p, cols, H, xc, pc, oc, o1, o2, xr, pr):
    """Columns ``cols`` of dh/d[x, p] by complex step."""
    ns = x.size
    nz = H.shape[0]
    for i in range(ns):
        xc[i] = x[i]
    for i in range(p.size):
        pc[i] = p[i]
    for c in range(cols.size):
        j = cols[c]
        if j < ns:
            hh = CS_STEP * max(abs(x[j]), 1e-3)
            xc[j] = x[j] + 1j * hh
        else:
            hh = CS_STEP * max(abs(p[j - ns]), 1e-3)
            pc[j - ns] = p[j - ns] + 1j * hh
        _h(xc, pc, oc)
        for i in range(nz):
            H[i, c] = oc[i].imag / hh
        if j < ns:
            xc[j] = x[j]
        else:
            pc[j - ns] = p[j - ns]


@njit(cache=True)
def hjac_fd(x, p, cols, H, xc, pc, oc, o1, o2, xr, pr):
    """Columns ``cols`` of dh/d[x, p] by central differences (fallback)."""
    ns = x.size
    nz = H.shape[0]
    for i in range(ns):
        xr[i] = x[i]
    for i in range(p.size):
        pr[i] = p[i]
    for c in range(cols.size):
        j = cols[c]
        if j < ns:
            hh = FD_STEP * max(abs(x[j]), 1e-3)
            xr[j] = x[j] + hh
            _h(xr, pr, o1)
            xr[j] = x[j] - hh
            _h(xr, pr, o2)
            xr[j] = x[j]
        else:
            hh = FD_STEP * max(abs(p[j - ns]), 1e-3)
            pr[j - ns] = p[j - ns] + hh
            _h(xr, pr, o1)
            pr[j - ns] = p[j - ns] - hh
            _h(xr, pr, o2)
            pr[j - ns] = p[j - ns]
        for i in range(nz):
            H[i, c] = (o1[i] - o2[i]) / (2.0 * hh)


@njit(cache=True)
def jacobians(x, p, u, cols, nz):
    """(F, H): df/d[x, p] and dh/d[x, p] restricted to ``cols`` (for tests and linearisation)."""
    ns = x.size
    n = cols.size
    F = np.zeros((ns, n))
    H = np.zeros((nz, n))
    Jfull = np.zeros((ns, ns + p.size))
    m = max(ns, nz)
    xc = np.zeros(ns, dtype=np.complex128)
    pc = np.zeros(p.size, dtype=np.complex128)
    oc = np.zeros(m, dtype=np.complex128)
    o1 = np.zeros(m)
    o2 = np.zeros(m)
    xr = np.zeros(ns)
    pr = np.zeros(p.size)
    _fjac(x, p, u, cols, F, Jfull, xc, pc, oc, o1, o2, xr, pr)
    _hjac(x, p, cols, H, xc, pc, oc, o1, o2, xr, pr)
    return F, H


@njit(cache=True)
def _deriv(x, p, u, cols, F, Jfull, xc, pc, oc, o1, o2, xr, pr, P, Q, dx, dP, G):
    """dx = f(x), dP = F P + P F^T + Q for the augmented state (the parameter rows of F are zero)."""
    ns = x.size
    n = P.shape[0]
    _f(x, p, u, dx)
    _fjac(x, p, u, cols, F, Jfull, xc, pc, oc, o1, o2, xr, pr)
    for i in range(ns):
        for j in range(n):
            s = 0.0
            for k in range(n):
                s += F[i, k] * P[k, j]
            G[i, j] = s
    for i in range(n):
        for j in range(n):
            v = Q[i, j]
            if i < ns:
                v += G[i, j]
            if j < ns:
                v += G[j, i]
            dP[i, j] = v


@njit(cache=True)
def _symmetrize(P):
    n = P.shape[0]
    for i in range(n):
        for j in range(i + 1, n):
            m = 0.5 * (P[i, j] + P[j, i])
            P[i, j] = m
            P[j, i] = m


@njit(cache=True)
def ekf_loop(X0, P0, Q, R, p0, est_idx, t, Z, U, substeps, bound, Xout, Sout, NIS, P):
    """Run the continuous-discrete augmented EKF over all samples (002 table 3.1).

    ``X0`` = [x_s0, alpha0] (n = n_s + n_a); ``est_idx`` the indices of alpha in ``p0``; ``t`` (N,),
    ``Z`` (N, n_z) measurements (NaN = missing component), ``U`` (N, n_u) inputs held over
    [t_k, t_k+1). Writes the updated estimate, its standard deviations and the normalised innovation
    squared of each sample into ``Xout``, ``Sout``, ``NIS`` and the final covariance into ``P``.
    Returns (status, k): status 0 or the failure code, k the last sample processed.
    """
    n = X0.size
    na = est_idx.size
    ns = n - na
    nz = Z.shape[1]
    N = t.size
    p = p0.copy()
    X = X0.copy()
    for i in range(n):
        for j in range(n):
            P[i, j] = P0[i, j]
    cols = np.empty(n, dtype=np.int64)
    for i in range(ns):
        cols[i] = i
    for i in range(na):
        cols[ns + i] = ns + est_idx[i]
    m = max(ns, nz)
    F = np.zeros((ns, n))
    Jfull = np.zeros((ns, ns + p.size))
    xc = np.zeros(ns, dtype=np.complex128)
    pc = np.zeros(p.size, dtype=np.complex128)
    oc = np.zeros(m, dtype=np.complex128)
    o1 = np.zeros(m)
    o2 = np.zeros(m)
    xr = np.zeros(ns)
    pr = np.zeros(p.size)
    G = np.zeros((ns, n))
    kx = np.zeros((4, ns))
    kP = np.zeros((4, n, n))
    xs = np.zeros(ns)
    Ps = np.zeros((n, n))
    H = np.zeros((nz, n))
    hx = np.zeros(nz)
    vi = np.zeros(nz, dtype=np.int64)
    y = np.zeros(nz)
    S = np.zeros((nz, nz))
    Lc = np.zeros((nz, nz))
    PHt = np.zeros((n, nz))
    K = np.zeros((n, nz))
    A = np.zeros((n, n))
    T = np.zeros((n, n))
    KR = np.zeros((n, nz))
    for k in range(N):
        # ---- propagation from t[k-1] to t[k] with U[k-1] held (RK4 on x and P together) --------
        if k > 0:
            u = U[k - 1]
            hstep = (t[k] - t[k - 1]) / substeps
            for i in range(na):
                p[est_idx[i]] = X[ns + i]
            for _s in range(substeps):
                for stage in range(4):
                    c = 0.0 if stage == 0 else (0.5 * hstep if stage < 3 else hstep)
                    for i in range(ns):
                        xs[i] = X[i] + (c * kx[stage - 1, i] if stage > 0 else 0.0)
                    for i in range(n):
                        for j in range(n):
                            Ps[i, j] = P[i, j] + (c * kP[stage - 1, i, j] if stage > 0 else 0.0)
                    _deriv(xs, p, u, cols, F, Jfull, xc, pc, oc, o1, o2, xr, pr, Ps, Q, kx[stage], kP[stage], G)
                w6 = hstep / 6.0
                for i in range(ns):
                    X[i] += w6 * (kx[0, i] + 2.0 * kx[1, i] + 2.0 * kx[2, i] + kx[3, i])
                for i in range(n):
                    for j in range(n):
                        P[i, j] += w6 * (kP[0, i, j] + 2.0 * kP[1, i, j] + 2.0 * kP[2, i, j] + kP[3, i, j])
            _symmetrize(P)
        # ---- update with the finite components of Z[k] -------------------------------------------
        for i in range(na):
            p[est_idx[i]] = X[ns + i]
        nv = 0
        for i in range(nz):
            if np.isfinite(Z[k, i]):
                vi[nv] = i
                nv += 1
        nis = np.nan
        if nv > 0:
            for i in range(ns):
                xs[i] = X[i]
            _h(xs, p, hx)
            _hjac(xs, p, cols, H, xc, pc, oc, o1, o2, xr, pr)
            for a in range(nv):
                y[a] = Z[k, vi[a]] - hx[vi[a]]
            # PHt = P H^T, S = H P H^T + R (valid rows only)
            for i in range(n):
                for a in range(nv):
                    s = 0.0
                    for j in range(n):
                        s += P[i, j] * H[vi[a], j]
                    PHt[i, a] = s
            for a in range(nv):
                for b in range(nv):
                    s = R[vi[a], vi[b]]
                    for j in range(n):
                        s += H[vi[a], j] * PHt[j, b]
                    S[a, b] = s
            # Cholesky S = L L^T; failure means the covariance lost positive definiteness
            for i in range(nv):
                for j in range(i + 1):
                    s = 0.5 * (S[i, j] + S[j, i])
                    for l in range(j):
                        s -= Lc[i, l] * Lc[j, l]
                    if i == j:
                        if not (s > 0.0):
                            return NOT_PD, k
                        Lc[i, i] = math.sqrt(s)
                    else:
                        Lc[i, j] = s / Lc[j, j]
            # K = PHt S^-1: solve L L^T K^T = PHt^T column by column (row i of K)
            for i in range(n):
                for a in range(nv):  # forward
                    s = PHt[i, a]
                    for b in range(a):
                        s -= Lc[a, b] * K[i, b]
                    K[i, a] = s / Lc[a, a]
                for a in range(nv - 1, -1, -1):  # backward
                    s = K[i, a]
                    for b in range(a + 1, nv):
                        s -= Lc[b, a] * K[i, b]
                    K[i, a] = s / Lc[a, a]
            # NIS = y^T S^-1 y = |L^-1 y|^2
            nis = 0.0
            for a in range(nv):
                s = y[a]
                for b in range(a):
                    s -= Lc[a, b] * o1[b]
                o1[a] = s / Lc[a, a]
                nis += o1[a] * o1[a]
            for i in range(n):
                s = 0.0
                for a in range(nv):
                    s += K[i, a] * y[a]
                X[i] += s
            # Joseph form P = (I - K H) P (I - K H)^T + K R K^T
            for i in range(n):
                for j in range(n):
                    s = 1.0 if i == j else 0.0
                    for a in range(nv):
                        s -= K[i, a] * H[vi[a], j]
                    A[i, j] = s
            for i in range(n):
                for j in range(n):
                    s = 0.0
                    for l in range(n):
                        s += A[i, l] * P[l, j]
                    T[i, j] = s
                for a in range(nv):
                    s = 0.0
                    for b in range(nv):
                        s += K[i, b] * R[vi[b], vi[a]]
                    KR[i, a] = s
            for i in range(n):
                for j in range(i, n):
                    s = 0.0
                    for l in range(n):
                        s += T[i, l] * A[j, l]
                    for a in range(nv):
                        s += KR[i, a] * K[j, a]
                    P[i, j] = s
                    P[j, i] = s
        # ---- checks and output -------------------------------------------------------------------
        for i in range(n):
            if not np.isfinite(X[i]):
                return NONFINITE, k
            if not (P[i, i] > 0.0) or not np.isfinite(P[i, i]):
                return NOT_PD, k
            if abs(X[i]) > bound[i]:
                return BOUND, k
            Xout[k, i] = X[i]
            Sout[k, i] = math.sqrt(P[i, i])
        NIS[k] = nis
    return OK, N - 1
