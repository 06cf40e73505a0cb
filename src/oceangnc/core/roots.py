"""Small root finders for the cold paths (config-time steady states), without importing scipy.

Importing :mod:`scipy.optimize` costs 0.3-1 s at start-up; a scenario only needs a 3-unknown steady
turn and a scalar root when it is built, so these two numpy-only solvers do it:

* :func:`newton` -- Newton's method with a forward-difference Jacobian and a backtracking line
  search on ``|f|``, for small square systems (the USV/UUV steady turns);
* :func:`bracket_root` -- the Illinois variant of regula falsi on a sign-changing bracket (superlinear,
  never leaves the bracket).
"""

from __future__ import annotations

import math

import numpy as np


def newton(f, x0, xtol: float = 1e-12, ftol: float = 1e-12, maxiter: int = 100):
    """Solve ``f(x) = 0`` (``f``: R^n -> R^n) from ``x0``; returns ``(x, converged)``."""
    x = np.array(x0, dtype=float)
    n = x.size
    fx = np.asarray(f(x), dtype=float)
    J = np.empty((n, n))
    for _ in range(maxiter):
        nf = float(np.linalg.norm(fx))
        if nf <= ftol:
            return x, True
        for j in range(n):
            h = 1.49e-8 * max(1.0, abs(x[j]))
            xp = x.copy()
            xp[j] += h
            J[:, j] = (np.asarray(f(xp), dtype=float) - fx) / h
        try:
            dx = np.linalg.solve(J, -fx)
        except np.linalg.LinAlgError:
            return x, False
        lam = 1.0
        while True:
            xn = x + lam * dx
            fn = np.asarray(f(xn), dtype=float)
            if np.all(np.isfinite(fn)) and float(np.linalg.norm(fn)) < nf or lam < 1e-4:
                break
            lam *= 0.5
        x, fx = xn, fn
        if float(np.linalg.norm(lam * dx)) <= xtol * (1.0 + float(np.linalg.norm(x))):
            return x, bool(np.all(np.isfinite(fx)))
    return x, False


def bracket_root(f, a: float, b: float, xtol: float = 1e-12, maxiter: int = 200) -> float:
    """A root of the scalar ``f`` in ``[a, b]`` (``f(a)``, ``f(b)`` of opposite signs); ValueError if not."""
    fa, fb = float(f(a)), float(f(b))
    if fa == 0.0:
        return a
    if fb == 0.0:
        return b
    if math.copysign(1.0, fa) == math.copysign(1.0, fb):
        raise ValueError(f"bracket_root: f({a:g}) and f({b:g}) have the same sign")
    side = 0
    c = a
    for _ in range(maxiter):
        c = (a * fb - b * fa) / (fb - fa)
        fc = float(f(c))
        if fc == 0.0 or abs(b - a) <= xtol * (1.0 + abs(c)):
            return c
        if math.copysign(1.0, fc) == math.copysign(1.0, fb):
            b, fb = c, fc
            if side == -1:
                fa *= 0.5
            side = -1
        else:
            a, fa = c, fc
            if side == 1:
                fb *= 0.5
            side = 1
    return c
