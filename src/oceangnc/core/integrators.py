"""Fixed-step integrators for the continuous physics, compiled with numba.

A right-hand side is a numba-compiled function ``f(t, x, u, p, out)`` that writes dx/dt into ``out``
(no allocation): ``x`` the flat state, ``u`` the inputs held constant over the step (zero-order
hold from the discrete blocks), ``p`` the flat parameter array. :func:`rk4_advance` takes ``n``
classical Runge-Kutta steps of size ``dt`` in place, which is the only integrator document 003 names
("Runge-Kutta"); it is fourth-order accurate (tested in ``tests/test_core.py``).
"""

from __future__ import annotations

import numpy as np
from numba import njit


def rk4_workspace(n_states: int) -> np.ndarray:
    """Scratch memory for :func:`rk4_advance` (5 x n_states float64), allocated once per plant."""
    return np.zeros((5, n_states))


@njit(cache=True)
def rk4_advance(f, t, x, u, p, dt, n, work):
    """Advance ``x`` in place by ``n`` RK4 steps of ``dt`` seconds; returns the new time (s).

    Stops early and returns ``-1 - k`` (k the step index) if the state becomes non-finite, so that the
    caller can report where the simulation diverged without wasting the remaining steps.
    """
    k1 = work[0]
    k2 = work[1]
    k3 = work[2]
    k4 = work[3]
    xt = work[4]
    m = x.size
    for s in range(n):
        f(t, x, u, p, k1)
        for i in range(m):
            xt[i] = x[i] + 0.5 * dt * k1[i]
        f(t + 0.5 * dt, xt, u, p, k2)
        for i in range(m):
            xt[i] = x[i] + 0.5 * dt * k2[i]
        f(t + 0.5 * dt, xt, u, p, k3)
        for i in range(m):
            xt[i] = x[i] + dt * k3[i]
        f(t + dt, xt, u, p, k4)
        ok = True
        for i in range(m):
            x[i] += dt / 6.0 * (k1[i] + 2.0 * k2[i] + 2.0 * k3[i] + k4[i])
            if not np.isfinite(x[i]):
                ok = False
        t += dt
        if not ok:
            return -1.0 - s
    return t


@njit(cache=True)
def euler_advance(f, t, x, u, p, dt, n, work):
    """Advance ``x`` in place by ``n`` explicit Euler steps (first order; for convergence tests)."""
    k1 = work[0]
    m = x.size
    for s in range(n):
        f(t, x, u, p, k1)
        for i in range(m):
            x[i] += dt * k1[i]
        t += dt
    return t
