"""Fixed-step integrators for the continuous physics, compiled with numba.

A right-hand side is a numba-compiled function ``f(t, x, u, p, out)`` that writes dx/dt into ``out``
(no allocation): ``x`` the flat state, ``u`` the inputs held constant over the step (zero-order
hold from the discrete blocks), ``p`` the flat parameter array. :func:`rk4_advance` takes ``n``
classical Runge-Kutta steps of size ``dt`` in place, which is the only integrator document 003 names
("Runge-Kutta"); it is fourth-order accurate (tested in ``tests/test_core.py``).

The integrators take the right-hand side as a first-class function argument and are therefore
compiled once per process and per right-hand side, without numba's disk cache: the cache index of
a function taking dispatchers keeps references to every dispatcher it was specialised for, which
breaks across processes ("underlying object has vanished"). The right-hand sides themselves are
cached.
"""

from __future__ import annotations

import functools

import numpy as np
from numba import njit


def rk4_workspace(n_states: int) -> np.ndarray:
    """Scratch memory for :func:`rk4_advance` (5 x n_states float64), allocated once per plant."""
    return np.zeros((5, n_states))


@njit(cache=False)  # no disk cache: its index would hold references to every rhs it met (see above)
def rk4_step(f, t, x, u, p, dt, work, bound):
    """One classical RK4 step of ``dt`` in place; False if a component became non-finite or above ``bound``."""
    k1 = work[0]
    k2 = work[1]
    k3 = work[2]
    k4 = work[3]
    xt = work[4]
    m = x.size
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
        if not (abs(x[i]) <= bound):  # also catches NaN
            ok = False
    return ok


@njit(cache=False)
def rk4_advance(f, t, x, u, p, dt, n, work):
    """Advance ``x`` in place by ``n`` RK4 steps of ``dt`` seconds; returns the new time (s).

    Stops early and returns ``-1 - k`` (k the step index) if the state becomes non-finite, so that the
    caller can report where the simulation diverged without wasting the remaining steps.
    """
    for s in range(n):
        if not rk4_step(f, t, x, u, p, dt, work, np.inf):
            return -1.0 - s
        t += dt
    return t


@njit(cache=False)
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


@functools.lru_cache(maxsize=None)
def rk4_stepper(rhs):
    """A compiled ``advance(t, x, u, p, dt, n, work, bound)`` specialised to one right-hand side.

    Same scheme as :func:`rk4_advance`, but with ``rhs`` bound at compile time, so a call costs a
    plain numba dispatch (passing a function as an argument costs ~25 us per call in numba's type
    machinery). Returns the new time, or ``-1 - k`` when step ``k`` produced a non-finite state or
    a component above ``bound`` in magnitude. Built once per process and right-hand side.
    """

    @njit(cache=False)
    def advance(t, x, u, p, dt, n, work, bound):
        for s in range(n):
            if not rk4_step(rhs, t, x, u, p, dt, work, bound):
                return -1.0 - s
            t += dt
        return t

    return advance
