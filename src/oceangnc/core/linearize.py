"""Jacobians, linearisation and trim of a :class:`~oceangnc.core.model.Model` (one implementation).

The Jacobian code here is the only one of the project: :func:`linearize`, :func:`trim` and the
augmented-state EKF (:mod:`oceangnc.identification._ekf_kernel`) all call the functions made by
:func:`jacobian_functions`. Columns are indices into the stacked vector ``[x | p | u]`` (states,
parameters, inputs), so the EKF asks for ``[x | estimated p]`` and :func:`linearize` for
``[x | u]``.

* ``"complex-step"``: df/dy_j = Im f(y + i h e_j) / h with h = 1e-20 max(|y_j|, 1e-3); exact to
  rounding because nothing is subtracted (Squire & Trapp 1998; Martins et al. 2003). ``f`` must run
  in complex arithmetic (:mod:`oceangnc.core.csmath`).
* ``"analytic"``: the model's ``jac(t, x, u, p, J)``, ``J = [df/dx, df/dp]``; input columns and
  ``dh`` by complex step.
* ``"finite-difference"``: central differences, step 1e-6 max(|y_j|, 1e-3), O(h^2): a fallback
  for a model that is neither.

The functions are made per (f, h, jac, mode) by closing over the model's compiled functions, and
compiled with :func:`cached_closure`: numba's own on-disk cache, keyed on a stable fingerprint of
the closed-over functions (module, name, bytecode, source file stamp) instead of numba's default
pickle of the closure cells (which holds each dispatcher's per-process id, so it never hits).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..errors import ConfigError, InputError
from .caches import python_body
from .jacobians import (  # noqa: F401  (re-exported: the EKF and user code import them from here)
    CS_STEP,
    FD_STEP,
    JACOBIAN_MODES,
    _fingerprint,
    cached_closure,
    h_states,
    jacobian_functions,
    workspace,
)


def default_mode(model, jacobian: str | None = None) -> str:
    """The Jacobian mode to use: the one asked, else analytic if the model has one, else complex step."""
    mode = jacobian or ("analytic" if model.jac is not None else "complex-step")
    if mode not in JACOBIAN_MODES:
        raise ConfigError(f"jacobian = {mode!r}: allowed values: {', '.join(JACOBIAN_MODES)}")
    if mode == "analytic" and model.jac is None:
        raise ConfigError(f"model {model.name} has no analytic Jacobian; use 'complex-step'")
    return mode


def _call(fn, *args, model=None, mode=""):
    try:
        return fn(*args)
    except Exception as e:  # numba typing errors: a model that cannot run in complex arithmetic
        if type(e).__module__.startswith("numba") and mode != "finite-difference":
            raise InputError(
                f"model {getattr(model, 'name', '?')}: f/h cannot be evaluated in complex arithmetic "
                "(use numpy functions such as np.sin or oceangnc.core.csmath, give an analytic jac, "
                "or use jacobian='finite-difference')"
            ) from None
        raise


def jacobian_columns(
    model,
    x,
    u,
    cols,
    p=None,
    t: float = 0.0,
    jacobian: str | None = None,
    outputs: bool = True,
    uncompiled=False,
    interpreted=False,
):
    """(F, H): columns ``cols`` (indices into [x | p | u]) of df and dh at (t, x, u); H is None when not
    ``outputs``. ``uncompiled``: run the Jacobian function's Python body (the same code, calling the
    compiled model: the same numbers) instead of compiling it, for a few calls (a trim's Newton steps).
    ``interpreted``: run the model's Python body too (:func:`oceangnc.core.caches.python_body`: compiling
    nothing; the numbers agree with the compiled model's to rounding)."""
    mode = default_mode(model, jacobian)
    fjac, hjac = jacobian_functions(model.f, model.h, model.jac, mode)
    if interpreted:
        fjac, hjac = python_body(fjac), python_body(hjac)
    elif uncompiled:
        fjac, hjac = fjac.py_func, hjac.py_func
    x = np.ascontiguousarray(x, dtype=np.float64)
    u = np.ascontiguousarray(np.atleast_1d(u), dtype=np.float64)
    p = np.ascontiguousarray(model.p if p is None else p, dtype=np.float64)
    cols = np.ascontiguousarray(cols, dtype=np.int64)
    nz = len(model.output_names)
    w = workspace(x.size, p.size, u.size, nz)
    F = np.zeros((x.size, cols.size))
    H = np.zeros((nz, cols.size))
    _call(fjac, float(t), x, p, u, cols, F, *w, model=model, mode=mode)
    if not outputs:
        return F, None
    _call(hjac, float(t), x, p, u, cols, H, *w, model=model, mode=mode)
    return F, H


@dataclass
class Linearization:
    """x' ~ A dx + B du, y ~ C dx + D du about (x, u); names of the states, inputs and outputs."""

    A: np.ndarray
    B: np.ndarray
    C: np.ndarray
    D: np.ndarray
    x: np.ndarray
    u: np.ndarray
    state_names: tuple
    input_names: tuple
    output_names: tuple

    def eigenvalues(self) -> np.ndarray:
        """Eigenvalues of A (1/s)."""
        return np.linalg.eigvals(self.A)


def linearize(model, x, u, p=None, t: float = 0.0, jacobian: str | None = None) -> Linearization:
    """A, B, C, D of ``model`` at state ``x`` and input ``u`` (complex step unless told otherwise)."""
    x = np.asarray(x, dtype=np.float64)
    u = np.atleast_1d(np.asarray(u, dtype=np.float64))
    nx, nu, npar = model.nx, model.nu, model.layout.size
    if x.size != nx or u.size != nu:
        raise InputError(f"linearize {model.name}: need {nx} states and {nu} inputs, got {x.size} and {u.size}")
    cols = np.concatenate([np.arange(nx), nx + npar + np.arange(nu)])
    F, H = jacobian_columns(model, x, u, cols, p=p, t=t, jacobian=jacobian)
    return Linearization(
        F[:, :nx],
        F[:, nx:],
        H[:, :nx],
        H[:, nx:],
        x.copy(),
        u.copy(),
        model.state_names,
        model.input_names,
        model.output_names,
    )


@dataclass
class Trim:
    """Result of :func:`trim`: the state and input, the residual of the zeroed derivatives, iterations."""

    x: np.ndarray
    u: np.ndarray
    residual: float
    iterations: int

    def state(self, model) -> dict[str, float]:
        return dict(zip(model.state_names, map(float, self.x)))


def trim(
    model,
    x0,
    u0,
    free,
    zero,
    p=None,
    t: float = 0.0,
    tol: float = 1e-10,
    max_iter: int = 100,
    jacobian: str | None = None,
    interpreted: bool = False,
) -> Trim:
    """Equilibrium of ``model``: the derivatives of the states ``zero`` vanish, varying ``free``.

    ``free`` names states and/or inputs (as many as ``zero``); the others keep their values from
    ``x0`` / ``u0``. Newton's method with the model's exact Jacobian (the same code as
    :func:`linearize`) and a backtracking line search on |residual|; raises :class:`InputError`
    if it does not converge (|residual| > ``tol`` x max(1, |residual at start|)).

    ``interpreted``: run the model's Python body and a finite-difference Jacobian's
    (:func:`oceangnc.core.caches.python_body`), compiling nothing: for a few solves of a small model
    at start-up, where compiling the model costs seconds and its Python body milliseconds (the root
    agrees with the compiled model's to rounding).

    Example: the USV running straight at thrust T, ``trim(m, x, [T, T, 0, 0, 0, 0], free=("u", "v",
    "r"), zero=("u", "v", "r"))``; positions and heading keep moving (not zeroed).
    """
    x = np.array(x0, dtype=np.float64)
    u = np.atleast_1d(np.array(u0, dtype=np.float64))
    free, zero = list(free), list(zero)
    if len(free) != len(zero):
        raise InputError(f"trim: {len(free)} free variables for {len(zero)} equations")
    nx, npar = model.nx, model.layout.size
    col_list: list[int] = []
    fs: list[tuple[str, int]] = []
    for k in free:
        if k in model.state_names:
            i = model.state_names.index(k)
            col_list.append(i)
            fs.append(("x", i))
        elif k in model.input_names:
            i = model.input_names.index(k)
            col_list.append(nx + npar + i)
            fs.append(("u", i))
        else:
            raise InputError(f"trim: '{k}' is neither a state nor an input of {model.name}")
    row_list: list[int] = []
    for k in zero:
        if k not in model.state_names:
            raise InputError(f"trim: '{k}' is not a state of {model.name}")
        row_list.append(model.state_names.index(k))
    cols = np.array(col_list, dtype=np.int64)
    rows = np.array(row_list, dtype=np.int64)
    pp = model.p if p is None else np.asarray(p, dtype=np.float64)
    mode = default_mode(model, jacobian)
    if interpreted and mode != "finite-difference":
        raise InputError(f"trim: interpreted=True needs jacobian='finite-difference', got {mode!r}")
    f = python_body(model.f) if interpreted else model.f

    def resid(xx, uu):
        out = np.zeros(nx)
        f(float(t), np.asarray(xx, dtype=np.float64), np.asarray(uu, dtype=np.float64), pp, out)
        return out[rows]

    def apply(xx, uu, dz):
        xx, uu = xx.copy(), uu.copy()
        for (kind, i), d in zip(fs, dz):
            if kind == "x":
                xx[i] += d
            else:
                uu[i] += d
        return xx, uu

    r = resid(x, u)
    r0 = max(1.0, float(np.max(np.abs(r))))
    it = 0
    for it in range(1, max_iter + 1):
        if float(np.max(np.abs(r))) <= tol * r0:
            break
        # a finite-difference Jacobian uncompiled: a first run compiles only the model (issue 25)
        F, _ = jacobian_columns(
            model,
            x,
            u,
            cols,
            p=pp,
            t=t,
            jacobian=jacobian,
            outputs=False,
            uncompiled=mode == "finite-difference",
            interpreted=interpreted,
        )
        try:
            dz = np.linalg.solve(F[rows], -r)
        except np.linalg.LinAlgError:
            raise InputError(f"trim {model.name}: singular Jacobian at iteration {it}") from None
        step = 1.0
        n0 = float(np.linalg.norm(r))
        while True:
            xn, un = apply(x, u, step * dz)
            rn = resid(xn, un)
            if np.all(np.isfinite(rn)) and (np.linalg.norm(rn) < n0 or step < 1e-4):
                break
            step *= 0.5
        x, u, r = xn, un, rn
    res = float(np.max(np.abs(r)))
    if not res <= tol * r0:
        raise InputError(f"trim {model.name}: no equilibrium found (residual {res:.3g} after {it} iterations)")
    return Trim(x, u, res, it)
