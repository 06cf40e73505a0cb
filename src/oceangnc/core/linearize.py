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
from numba import njit

from ..errors import ConfigError, InputError

JACOBIAN_MODES = ("analytic", "complex-step", "finite-difference")
CS_STEP = 1e-20  # complex step, relative to max(|y|, 1e-3)
FD_STEP = 1e-6  # central-difference step, relative to max(|y|, 1e-3)

_FUNCS: dict[tuple, tuple] = {}


def _fingerprint(obj) -> str:
    """A string that changes when a closed-over compiled function (or what it closes over) changes."""
    import hashlib
    import os
    import pickle

    from numba.core.dispatcher import Dispatcher

    if isinstance(obj, Dispatcher):
        py = obj.py_func
        try:
            src = py.__code__.co_filename
            st = os.stat(src)
            stamp = f"{src}:{st.st_mtime_ns}:{st.st_size}"
        except OSError:
            stamp = f"<no file {id(py)}>"
        parts = [py.__module__, py.__qualname__, hashlib.sha256(py.__code__.co_code).hexdigest(), stamp]
        parts += [_fingerprint(c.cell_contents) for c in (py.__closure__ or ())]
        return "(" + ",".join(parts) + ")"
    try:
        return hashlib.sha256(pickle.dumps(obj)).hexdigest()
    except (pickle.PicklingError, TypeError, AttributeError):
        return f"<{type(obj).__name__} {id(obj)}>"


def cached_closure(fn):
    """``njit(fn)`` for a closure over other compiled functions, cached on disk by numba.

    Three things make numba's cache safe for such closures:

    * the index key: numba pickles the closure cells, and a dispatcher pickles with a per-process
      id, so the key would never match in a new process; here it is a hash of :func:`_fingerprint`
      of the cells (module, name, bytecode, source-file stamp of each closed-over function);
    * the symbol names: numba names compiled code after the function's qualified name plus a
      per-process counter, so closures compiled in *different* processes (the USV's and the
      first-order model's kernel) can carry the same symbol, and loading both cached libraries in
      one process binds one's calls to the other's code. The closure's ``__qualname__`` therefore
      gets the fingerprint hash appended;
    * the files: each (closure, fingerprint) has its own index and data files, so processes
      compiling different models at once never write into each other's files.

    As with any numba cache, edits to functions in *other* files than the closed-over ones are not
    seen (clear ``<cache>/numba-<version>``, see :mod:`oceangnc.jitcache`, after such an edit).
    """
    import hashlib

    from numba.core.caching import FunctionCache, IndexDataCacheFile

    cells = "".join(_fingerprint(c.cell_contents) for c in (fn.__closure__ or ()))
    cells_hash = hashlib.sha256((cells + fn.__qualname__).encode()).hexdigest()
    fn.__qualname__ = f"{fn.__qualname__}_{cells_hash[:16]}"

    class _ClosureCache(FunctionCache):
        def __init__(self, py_func):
            super().__init__(py_func)
            self._cache_file = IndexDataCacheFile(
                cache_path=self._cache_path,
                filename_base=f"{self._impl.filename_base}-{cells_hash[:20]}",
                source_stamp=self._impl.locator.get_source_stamp(),
            )

        def _index_key(self, sig, codegen):
            return (
                sig,
                codegen.magic_tuple(),
                (hashlib.sha256(self._py_func.__code__.co_code).hexdigest(), cells_hash),
            )

    d = njit(fn)
    try:
        d._cache = _ClosureCache(fn)
    except RuntimeError:  # numba found no writable cache location: compile once per process
        return d
    return d


@njit(cache=True)
def h_states(t, x, u, p, out):
    """Output function "outputs = the first len(out) states" (models without their own h)."""
    for i in range(out.size):
        out[i] = x[i]


def jacobian_functions(f, h, jac, mode: str):
    """Compiled ``(fjac, hjac)`` of ``f(t, x, u, p, out)`` and ``h(t, x, u, p, out)`` for ``mode``.

    ``fjac(t, x, p, u, cols, J, Jfull, xc, pc, uc, oc, o1, o2, xr, pr, ur)`` writes the columns
    ``cols`` (indices into [x | p | u]) of df/d[x, p, u] into ``J``; ``hjac(t, x, p, u, cols, H, ...)``
    the same for h. The trailing arrays are work space (see :func:`workspace`), so the EKF loop
    allocates nothing per sample.
    """
    if mode not in JACOBIAN_MODES:
        raise ConfigError(f"jacobian = {mode!r}: allowed values: {', '.join(JACOBIAN_MODES)}")
    key = (f, h, jac, mode)
    if key in _FUNCS:
        return _FUNCS[key]

    def make_cs(g):
        @cached_closure
        def gjac_cs(t, x, p, u, cols, J, Jfull, xc, pc, uc, oc, o1, o2, xr, pr, ur):
            ns = x.size
            npar = p.size
            for i in range(ns):
                xc[i] = x[i]
            for i in range(npar):
                pc[i] = p[i]
            for i in range(u.size):
                uc[i] = u[i]
            m = J.shape[0]
            for c in range(cols.size):
                j = cols[c]
                if j < ns:
                    hh = CS_STEP * max(abs(x[j]), 1e-3)
                    xc[j] = x[j] + 1j * hh
                elif j < ns + npar:
                    hh = CS_STEP * max(abs(p[j - ns]), 1e-3)
                    pc[j - ns] = p[j - ns] + 1j * hh
                else:
                    hh = CS_STEP * max(abs(u[j - ns - npar]), 1e-3)
                    uc[j - ns - npar] = u[j - ns - npar] + 1j * hh
                g(t, xc, uc, pc, oc)
                for i in range(m):
                    J[i, c] = oc[i].imag / hh
                if j < ns:
                    xc[j] = x[j]
                elif j < ns + npar:
                    pc[j - ns] = p[j - ns]
                else:
                    uc[j - ns - npar] = u[j - ns - npar]

        return gjac_cs

    def make_fd(g):
        @cached_closure
        def gjac_fd(t, x, p, u, cols, J, Jfull, xc, pc, uc, oc, o1, o2, xr, pr, ur):
            ns = x.size
            npar = p.size
            for i in range(ns):
                xr[i] = x[i]
            for i in range(npar):
                pr[i] = p[i]
            for i in range(u.size):
                ur[i] = u[i]
            m = J.shape[0]
            for c in range(cols.size):
                j = cols[c]
                if j < ns:
                    y = x[j]
                elif j < ns + npar:
                    y = p[j - ns]
                else:
                    y = u[j - ns - npar]
                hh = FD_STEP * max(abs(y), 1e-3)
                for side in range(2):
                    v = y + hh if side == 0 else y - hh
                    if j < ns:
                        xr[j] = v
                    elif j < ns + npar:
                        pr[j - ns] = v
                    else:
                        ur[j - ns - npar] = v
                    if side == 0:
                        g(t, xr, ur, pr, o1)
                    else:
                        g(t, xr, ur, pr, o2)
                if j < ns:
                    xr[j] = y
                elif j < ns + npar:
                    pr[j - ns] = y
                else:
                    ur[j - ns - npar] = y
                for i in range(m):
                    J[i, c] = (o1[i] - o2[i]) / (2.0 * hh)

        return gjac_fd

    hh = h if h is not None else h_states
    if mode == "finite-difference":
        fjac, hjac = make_fd(f), make_fd(hh)
    elif mode == "complex-step":
        fjac, hjac = make_cs(f), make_cs(hh)
    else:
        if jac is None:
            raise ConfigError("this model has no analytic Jacobian; use 'complex-step'")
        f_cs = make_cs(f)

        @cached_closure
        def fjac(t, x, p, u, cols, J, Jfull, xc, pc, uc, oc, o1, o2, xr, pr, ur):
            jac(t, x, u, p, Jfull)
            ns = x.size
            ncol = Jfull.shape[1]
            for c in range(cols.size):
                if cols[c] < ncol:
                    for i in range(ns):
                        J[i, c] = Jfull[i, cols[c]]
                else:  # input columns: complex step on that column alone
                    f_cs(t, x, p, u, cols[c : c + 1], J[:, c : c + 1], Jfull, xc, pc, uc, oc, o1, o2, xr, pr, ur)

        hjac = make_cs(hh)
    _FUNCS[key] = (fjac, hjac)
    return fjac, hjac


def workspace(nx: int, npar: int, nu: int, nz: int):
    """Work arrays of the Jacobian functions: (Jfull, xc, pc, uc, oc, o1, o2, xr, pr, ur)."""
    m = max(nx, nz)
    return (
        np.zeros((nx, nx + npar)),
        np.zeros(nx, np.complex128),
        np.zeros(npar, np.complex128),
        np.zeros(max(nu, 1), np.complex128)[:nu],
        np.zeros(m, np.complex128),
        np.zeros(m),
        np.zeros(m),
        np.zeros(nx),
        np.zeros(npar),
        np.zeros(max(nu, 1))[:nu],
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


def jacobian_columns(model, x, u, cols, p=None, t: float = 0.0, jacobian: str | None = None):
    """(F, H): columns ``cols`` (indices into [x | p | u]) of df and dh at (t, x, u)."""
    mode = default_mode(model, jacobian)
    fjac, hjac = jacobian_functions(model.f, model.h, model.jac, mode)
    x = np.ascontiguousarray(x, dtype=np.float64)
    u = np.ascontiguousarray(np.atleast_1d(u), dtype=np.float64)
    p = np.ascontiguousarray(model.p if p is None else p, dtype=np.float64)
    cols = np.ascontiguousarray(cols, dtype=np.int64)
    nz = len(model.output_names)
    w = workspace(x.size, p.size, u.size, nz)
    F = np.zeros((x.size, cols.size))
    H = np.zeros((nz, cols.size))
    _call(fjac, float(t), x, p, u, cols, F, *w, model=model, mode=mode)
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
) -> Trim:
    """Equilibrium of ``model``: the derivatives of the states ``zero`` vanish, varying ``free``.

    ``free`` names states and/or inputs (as many as ``zero``); the others keep their values from
    ``x0`` / ``u0``. Newton's method with the model's exact Jacobian (the same code as
    :func:`linearize`) and a backtracking line search on |residual|; raises :class:`InputError`
    if it does not converge (|residual| > ``tol`` x max(1, |residual at start|)).

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

    def resid(xx, uu):
        return model.deriv(xx, uu, pp, t)[rows]

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
        F, _ = jacobian_columns(model, x, u, cols, p=pp, t=t, jacobian=jacobian)
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
