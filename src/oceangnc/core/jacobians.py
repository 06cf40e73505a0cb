"""The Jacobian functions of the project (complex step, analytic, finite differences) and the
on-disk cache of the closures that make them; :mod:`oceangnc.core.linearize` describes the modes and
uses them, as does the EKF (:mod:`oceangnc.identification._ekf_kernel`).
"""

from __future__ import annotations

import numpy as np
from numba import njit

from ..errors import ConfigError

JACOBIAN_MODES = ("analytic", "complex-step", "finite-difference")
CS_STEP = 1e-20  # complex step, relative to max(|y|, 1e-3)
FD_STEP = 1e-6  # central-difference step, relative to max(|y|, 1e-3)

_FUNCS: dict[tuple, tuple] = {}


@njit(cache=True)
def _stack_get(x, p, u, j):
    """Element ``j`` of the stacked vector [x | p | u]."""
    ns = x.size
    if j < ns:
        return x[j]
    if j < ns + p.size:
        return p[j - ns]
    return u[j - ns - p.size]


@njit(cache=True)
def _stack_step(x, p, u, j, rel):
    """(y_j, h_j): element ``j`` of [x | p | u] and its differentiation step rel * max(|y_j|, 1e-3)."""
    y = _stack_get(x, p, u, j)
    return y, rel * max(abs(y), 1e-3)


@njit(cache=True)
def _stack_set(xw, pw, uw, j, v):
    """Set element ``j`` of the stacked work vector [xw | pw | uw] to ``v``."""
    ns = xw.size
    if j < ns:
        xw[j] = v
    elif j < ns + pw.size:
        pw[j - ns] = v
    else:
        uw[j - ns - pw.size] = v


@njit(cache=True)
def _stack_load(x, p, u, xw, pw, uw):
    """Copy x, p, u into the work vectors (real or complex)."""
    for i in range(x.size):
        xw[i] = x[i]
    for i in range(p.size):
        pw[i] = p[i]
    for i in range(u.size):
        uw[i] = u[i]


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

    Edits to functions in *other* files than the closed-over ones are covered by the cache folder's
    code key (:mod:`oceangnc.core.caches`).
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
            _stack_load(x, p, u, xc, pc, uc)
            m = J.shape[0]
            for c in range(cols.size):
                j = cols[c]
                y, hh = _stack_step(x, p, u, j, CS_STEP)
                _stack_set(xc, pc, uc, j, y + 1j * hh)
                g(t, xc, uc, pc, oc)
                for i in range(m):
                    J[i, c] = oc[i].imag / hh
                _stack_set(xc, pc, uc, j, y + 0j)

        return gjac_cs

    def make_fd(g):
        @cached_closure
        def gjac_fd(t, x, p, u, cols, J, Jfull, xc, pc, uc, oc, o1, o2, xr, pr, ur):
            _stack_load(x, p, u, xr, pr, ur)
            m = J.shape[0]
            for c in range(cols.size):
                j = cols[c]
                y, hh = _stack_step(x, p, u, j, FD_STEP)
                _stack_set(xr, pr, ur, j, y + hh)
                g(t, xr, ur, pr, o1)
                _stack_set(xr, pr, ur, j, y - hh)
                g(t, xr, ur, pr, o2)
                _stack_set(xr, pr, ur, j, y)
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
