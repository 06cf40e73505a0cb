"""Compiled kernel of the augmented EKF (see :mod:`oceangnc.identification.ekf` for the equations).

:func:`make_kernel` builds the filter loop for one model: it closes over the model's compiled
``f(t, x, u, p, out)`` and ``h(t, x, u, p, out)`` and the Jacobian functions of
:func:`oceangnc.core.linearize.jacobian_functions` (the project's one Jacobian implementation), so
numba compiles the loop with direct calls into the model. Kernels are kept per process and per
(f, h, jac, mode) and cached on disk by numba with a stable key
(:func:`oceangnc.core.linearize.cached_closure`), so only the first run after an edit compiles.

Everything is allocation-free inside the sample loop; the matrices are small (n = n_s + n_a).
"""

import math

import numpy as np
from numba import njit

from ..core.linearize import cached_closure, jacobian_functions

OK, NONFINITE, NOT_PD, BOUND = 0, 1, 2, 3

_KERNELS: dict = {}


@njit(cache=True)
def matmul_rows(A, B, out, rows):
    """out[i, j] = sum_k A[i, k] B[k, j] for the first ``rows`` rows (no allocation)."""
    n = B.shape[0]
    for i in range(rows):
        for j in range(B.shape[1]):
            s = 0.0
            for k in range(n):
                s += A[i, k] * B[k, j]
            out[i, j] = s


@njit(cache=True)
def _symmetrize(P):
    n = P.shape[0]
    for i in range(n):
        for j in range(i + 1, n):
            m = 0.5 * (P[i, j] + P[j, i])
            P[i, j] = m
            P[j, i] = m


def make_kernel(f, h, jac, mode):
    """``ekf_loop`` compiled against the model functions ``f``, ``h`` (None: outputs = states), ``jac``."""
    key = (f, h, jac, mode)
    if key in _KERNELS:
        return _KERNELS[key]
    from ..core.linearize import h_states

    _fjac, _hjac = jacobian_functions(f, h, jac, mode)
    _f = f
    _h = h if h is not None else h_states

    @cached_closure
    def _deriv(tt, x, p, u, cols, F, Jfull, xc, pc, uc, oc, o1, o2, xr, pr, ur, P, Q, dx, dP, G):
        """dx = f(x), dP = F P + P F^T + Q for the augmented state (the parameter rows of F are zero)."""
        ns = x.size
        n = P.shape[0]
        _f(tt, x, u, p, dx)
        _fjac(tt, x, p, u, cols, F, Jfull, xc, pc, uc, oc, o1, o2, xr, pr, ur)
        matmul_rows(F, P, G, ns)  # G = F P (the state rows; the parameter rows of F are zero)
        for i in range(n):
            for j in range(n):
                v = Q[i, j]
                if i < ns:
                    v += G[i, j]
                if j < ns:
                    v += G[j, i]
                dP[i, j] = v

    @cached_closure
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
        nu = U.shape[1]
        uc = np.zeros(nu, dtype=np.complex128)
        ur = np.zeros(nu)
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
                        _deriv(
                            t[k - 1] + _s * hstep + c,
                            xs,
                            p,
                            u,
                            cols,
                            F,
                            Jfull,
                            xc,
                            pc,
                            uc,
                            oc,
                            o1,
                            o2,
                            xr,
                            pr,
                            ur,
                            Ps,
                            Q,
                            kx[stage],
                            kP[stage],
                            G,
                        )
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
                _h(t[k], xs, U[k], p, hx)
                _hjac(t[k], xs, p, U[k], cols, H, Jfull, xc, pc, uc, oc, o1, o2, xr, pr, ur)
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
                matmul_rows(A, P, T, n)  # T = (I - K H) P
                for i in range(n):
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

    _KERNELS[key] = ekf_loop
    return ekf_loop
