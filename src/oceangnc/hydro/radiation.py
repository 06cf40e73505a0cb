r"""State-space model of the radiation memory of Cummins' equation, fitted in the frequency domain.

Cummins' equation (Cummins 1962, *The impulse response function and ship motions*, Schiffstechnik 9;
Fossen 2021, *Handbook of Marine Craft Hydrodynamics and Motion Control*, 2nd ed., ch. 5) of a floating
body's wave-frequency motion xi (6, about the reference point):

    (M + A_inf) xi'' + int_0^t K(t - s) xi'(s) ds + C xi = tau_exc(t)

has the retardation functions K(t) whose transform is (Ogilvie 1964)

    K(iw) = B(w) + i w (A(w) - A_inf).

The convolution is replaced by a linear system with the same transfer function (Perez & Fossen 2008,
*Time- vs. frequency-domain identification of parametric radiation force models for marine structures
at zero speed*, Modeling, Identification and Control 29(1)): K(s) ~ sum_k R_k / (s - p_k), fitted to the
computed K(iw) of every entry at once with **common poles** by vector fitting (Gustavsen & Semlyen
1999, *Rational approximation of frequency domain responses by vector fitting*, IEEE Trans. Power
Delivery 14(3)): poles relocated as the zeros of a weighting function sigma(s) over a few iterations,
unstable poles reflected to the left half plane, then the residues by linear least squares with
K(0) = 0 imposed (B(0) = 0 and A(w) finite at w -> 0, the low-frequency limit the free surface
imposes; a fit that misses it leaves a small negative damping of the slow modes, which grows). The
model is strictly proper (K(iw) -> 0 as w -> inf, as the coefficients' definition requires).

Realisation (:class:`RadiationModel`): per input DOF j a copy of the same pole block,
z_j' = Ar z_j + br xi_j', and the radiation force mu_i = sum_j Cr[i, j] . z_j. A complex pair
p = alpha + i beta with residue c1 + i c2 is the block [[alpha, beta], [-beta, alpha]], b = (2, 0),
c = (c1, c2); a real pole p with residue c is [p], b = 1, c = c.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from .coefficients import HydroCoefficients


@dataclass
class RadiationModel:
    """z_j' = Ar z_j + br xi_j' (j = 1..6), mu_i = sum_j Cr[i, j] . z_j (module docstring)."""

    Ar: np.ndarray  # (ns, ns)
    br: np.ndarray  # (ns,)
    Cr: np.ndarray  # (6, 6, ns)
    poles: np.ndarray  # complex, the upper half of the pairs and the real ones
    error: float  # largest error of the fitted K(iw) over the band, relative to each entry's peak

    @property
    def ns(self) -> int:
        return int(self.br.size)

    def transfer(self, w: np.ndarray) -> np.ndarray:
        """The fitted K(iw) (nw, 6, 6) at the frequencies ``w`` (rad/s)."""
        out = np.zeros((np.size(w), 6, 6), complex)
        eye = np.eye(self.ns)
        for k, wk in enumerate(np.atleast_1d(w)):
            v = np.linalg.solve(1j * wk * eye - self.Ar, self.br)
            out[k] = self.Cr @ v
        return out

    def added_mass_damping(self, w: np.ndarray, A_inf: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """(A(w), B(w)) (nw, 6, 6) that the fitted model implies: B = Re K, A = A_inf + Im K / w."""
        K = self.transfer(w)
        w = np.atleast_1d(w)
        return A_inf[None] + K.imag / w[:, None, None], K.real


def retardation_data(c: HydroCoefficients) -> np.ndarray:
    """K(iw) = B(w) + i w (A(w) - A_inf) (nw, 6, 6) of the coefficient file."""
    return c.B + 1j * c.omega[:, None, None] * (c.A - c.A_inf[None])


def _basis(s: np.ndarray, poles: np.ndarray) -> np.ndarray:
    """Partial-fraction basis (ns columns, real coefficients) at s = iw for the poles (real ones, and
    complex ones given by their upper member)."""
    cols = []
    for p in poles:
        if abs(p.imag) < 1e-12 * max(1.0, abs(p)):
            cols.append(1.0 / (s - p.real))
        else:
            cols.append(1.0 / (s - p) + 1.0 / (s - np.conj(p)))
            cols.append(1j / (s - p) - 1j / (s - np.conj(p)))
    return np.stack(cols, axis=1)


def _blocks(poles: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """(A, b) of the real realisation of the poles (module docstring)."""
    n = sum(1 if abs(p.imag) < 1e-12 * max(1.0, abs(p)) else 2 for p in poles)
    A = np.zeros((n, n))
    b = np.zeros(n)
    k = 0
    for p in poles:
        if abs(p.imag) < 1e-12 * max(1.0, abs(p)):
            A[k, k] = p.real
            b[k] = 1.0
            k += 1
        else:
            A[k : k + 2, k : k + 2] = [[p.real, p.imag], [-p.imag, p.real]]
            b[k] = 2.0
            k += 2
    return A, b


def _new_poles(eigs: np.ndarray) -> np.ndarray:
    """Stable poles from eigenvalues: unstable ones reflected; one of each complex pair kept."""
    eigs = np.where(eigs.real > 0, -np.conj(eigs), eigs)
    out = [p for p in eigs if p.imag >= -1e-12 * max(1.0, abs(p))]
    out = [complex(p.real, 0.0) if abs(p.imag) < 1e-12 * max(1.0, abs(p)) else p for p in out]
    return np.array(out)


def vector_fit(w: np.ndarray, F: np.ndarray, n_pairs: int, iterations: int = 12):
    """Common poles and real residues (ns, m) fitting F (nw, m) at s = iw by a strictly proper sum
    of partial fractions (Gustavsen & Semlyen 1999). Returns (poles, residues, fitted F)."""
    s = 1j * w
    beta = np.linspace(w[0], w[-1], n_pairs)
    poles = -beta / 100.0 + 1j * beta
    m = F.shape[1]
    for _ in range(iterations):
        Phi = _basis(s, poles)
        n = Phi.shape[1]
        # fast VF: per entry, the QR of [Phi, -f Phi] leaves n equations in sigma's residues alone
        rows = []
        rhs = []
        for e in range(m):
            blk = np.hstack([Phi, -F[:, e : e + 1] * Phi])
            blk = np.vstack([blk.real, blk.imag])
            be = np.concatenate([F[:, e].real, F[:, e].imag])
            q, r = np.linalg.qr(blk)
            rows.append(r[n:, n:])
            rhs.append((q.T @ be)[n:])
        Am = np.vstack(rows)
        scale = np.linalg.norm(Am, axis=0)
        scale[scale == 0] = 1.0
        sol = np.linalg.solve((Am / scale).T @ (Am / scale), (Am / scale).T @ np.concatenate(rhs)) / scale
        ct = sol
        A, b = _blocks(poles)
        poles = _new_poles(np.linalg.eigvals(A - np.outer(b, ct)))
    # residues with K(0) = 0 imposed (no damping and no stiffness at zero frequency: B(0) = 0), on the
    # null space of the constraint row
    Phi = _basis(s, poles)
    a0 = _basis(np.array([0j]), poles)[0].real
    N = np.linalg.svd(a0[None, :])[2][1:].T  # (n, n - 1), a0 . N = 0
    PhiR = np.vstack([Phi.real, Phi.imag]) @ N
    q, r = np.linalg.qr(PhiR)
    res = N @ np.linalg.solve(r, q.T @ np.vstack([F.real, F.imag]))
    return poles, res, Phi @ res


def fit_radiation(c: HydroCoefficients, n_pairs: int | None = None, tol: float = 0.02) -> RadiationModel:
    """The state-space radiation model of ``c`` (module docstring). ``n_pairs`` None: the smallest
    number of pole pairs (2..10) whose largest error, relative to each entry's peak |K|, is below
    ``tol``, else the best one tried."""
    K = retardation_data(c)
    w = c.omega
    peak = np.abs(K).max(axis=0)
    big = peak > 1e-6 * peak.max()
    idx = np.argwhere(big)
    F = np.stack([K[:, i, j] / peak[i, j] for i, j in idx], axis=1)
    best = None
    for npairs in [n_pairs] if n_pairs else range(2, 11):
        poles, res, fit = vector_fit(w, F, npairs)
        err = float(np.max(np.abs(fit - F)))
        if best is None or err < best[0]:
            best = (err, poles, res)
        if n_pairs is None and err < tol:
            break
    assert best is not None
    err, poles, res = best
    Ar, br = _blocks(poles)
    Cr = np.zeros((6, 6, br.size))
    for k, (i, j) in enumerate(idx):
        Cr[i, j] = res[:, k] * peak[i, j]
    return RadiationModel(Ar=Ar, br=br, Cr=Cr, poles=poles, error=err)
