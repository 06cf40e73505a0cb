"""Continuous-discrete extended Kalman filter with augmented state, for any model.

Document 002 (``002_05c842517d8c1175.txt`` ch. 3, eq. 3.1-3.5 and table 3.1) identifies the
hydrodynamic coefficients alpha of a submarine by appending them to the state as constants::

    X = [x_s; alpha],   x_s' = f(x_s, alpha, u) + w(t),   alpha' = 0,   z_k = h(x_s(t_k)) + v_k

with w ~ N(0, Q) (continuous, spectral density), v_k ~ N(0, R), X(0) ~ N(X_0, P_0), and the filter
of table 3.1:

* propagation between measurements: X' = f(X), P' = F P + P F^T + Q, F = df/dX at the estimate,
  both integrated together with classical RK4 (``substeps`` steps per sample interval, the input
  held constant over the interval: zero-order hold of the logged input);
* update at t_k: K = P H^T (H P H^T + R)^-1, X += K (z - h(X)), and the covariance in Joseph form
  P = (I - K H) P (I - K H)^T + K R K^T (the table's (I - K H) P is algebraically equal but loses
  symmetry and positive definiteness in floating point).

The filter is generic: a model is a :class:`~oceangnc.core.model.Model` (the project's one system
contract: ``f(t, x, u, p, out)``, optional ``h(t, x, u, p, out)``, declared names and units, a
generated parameter layout), so any plant of the project (:func:`get_model`: ``usv``, ``uuv``,
``ship``, ``first-order``, ``submarine-vertical``) is identified by naming the parameters to
estimate (the others stay at their nominal values). The older :class:`EKFModel` (``f(x, p, u,
out)``, ``h(x, p, out)``) is still accepted and wrapped (:func:`as_model`). Jacobians are exact and
come from :mod:`oceangnc.core.linearize` (the one implementation, shared with ``linearize``/``trim``):

* ``"analytic"``: the model's own ``jac`` (J[:, :n_s] = df/dx, J[:, n_s + j] = df/dp_j);
* ``"complex-step"`` (default when no analytic Jacobian is given): df/dy_j = Im f(y + i h e_j) / h
  with h ~ 1e-20 |y_j|, exact to rounding because nothing is subtracted. It needs ``f`` and ``h``
  written for complex arithmetic (numpy functions or :mod:`oceangnc.core.csmath`, branches on
  real parts);
* ``"finite-difference"`` (central, for models that are neither): O(h^2) approximate, a fallback.

The whole filter loop is one numba function; 200 s of 100 Hz data with 3 states and 10 parameters
takes well under a second on one core (``benchmarks/bench_ekf.py``).
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
from dataclasses import dataclass, field

import numpy as np

from ..core.linearize import _call, default_mode, jacobian_columns
from ..core.model import Model, ModelNames, Param, ParamLayout, get_model  # noqa: F401  (get_model re-exported)
from ..errors import ConfigError, InputError
from ..models.submarine_vertical import filter_model


class FilterDivergedError(InputError):
    """The filter diverged (non-finite estimate, covariance no longer positive definite, estimate out
    of bounds). Treated as bad input (exit code 2): the remedy is a better tuning (Q, R, P0) or
    better initial guesses, not a code fix."""


# -- compiled kernels -------------------------------------------------------------------------------------

_ADAPTERS: dict[tuple, tuple] = {}


def as_model(model) -> Model:
    """A :class:`~oceangnc.core.model.Model` for ``model`` (a Model already, or a legacy :class:`EKFModel`
    whose ``f(x, p, u, out)``, ``h(x, p, out)`` and ``jac(x, p, u, J)`` are wrapped into the
    ``(t, x, u, p, out)`` contract by thin compiled adapters)."""
    if isinstance(model, Model):
        return model
    from ..core.linearize import cached_closure

    f0, h0, j0 = model.f, model.h, model.jac
    key = (f0, h0, j0)
    if key not in _ADAPTERS:

        @cached_closure
        def f(t, x, u, p, out):
            f0(x, p, u, out)

        @cached_closure
        def h(t, x, u, p, out):
            h0(x, p, out)

        jac = None
        if j0 is not None:

            @cached_closure
            def jac(t, x, u, p, J):
                j0(x, p, u, J)

        _ADAPTERS[key] = (f, h, jac)
    f, h, jac = _ADAPTERS[key]
    return Model(
        model.name,
        f,
        [(k, "1") for k in model.state_names],
        [(k, "1") for k in model.input_names],
        ParamLayout([Param(k) for k in model.param_names]),
        model.params,
        h=h,
        outputs=[(k, "1") for k in model.measurement_names],
        jac=jac,
        bound=model.bound,
        description=model.description,
    )


def model_jacobians(model, x, u, estimate=(), jacobian: str | None = None, params=None):
    """(F, H) of ``model`` at state ``x``, input ``u``: derivatives of f and h with respect to
    [x, estimated parameters], by the filter's own Jacobian code (:mod:`oceangnc.core.linearize`)."""
    m = as_model(model)
    idx = resolve_estimate(m, estimate) if len(estimate) else np.zeros(0, dtype=np.int64)
    cols = np.concatenate([np.arange(m.nx), m.nx + idx]).astype(np.int64)
    return jacobian_columns(m, x, u, cols, p=params, jacobian=jacobian)


# -- the Python interface -------------------------------------------------------------------------------


@dataclass
class EKFModel:
    """A model the augmented EKF can identify.

    Attributes
    ----------
    name : str
    f : numba dispatcher
        ``f(x, p, u, out)``: writes dx/dt of the ``len(state_names)`` states.
    h : numba dispatcher
        ``h(x, p, out)``: writes the ``len(measurement_names)`` predicted measurements.
    state_names, param_names, input_names, measurement_names : sequences of str
    params : array
        Nominal values of all parameters (those not estimated stay at these values).
    jac : numba dispatcher, optional
        ``jac(x, p, u, J)``: analytic Jacobian, J (n_s, n_s + n_p) = [df/dx, df/dp].
    bound : float
        An estimate component above this in magnitude counts as divergence.
    """

    name: str
    f: Callable
    h: Callable
    state_names: Sequence[str]
    param_names: Sequence[str]
    input_names: Sequence[str]
    measurement_names: Sequence[str]
    params: np.ndarray
    jac: Callable | None = None
    bound: float = 1e6
    description: str = ""


@dataclass
class EKFResult:
    """Filter output.

    Attributes
    ----------
    t : (N,) s
    names : state names then estimated parameter names
    X : (N, n) estimates after each update
    sigma : (N, n) their standard deviations sqrt(diag P)
    nis : (N,) normalised innovation squared of each update (chi-square with n_z dof if consistent)
    P : (n, n) final covariance
    """

    t: np.ndarray
    names: list[str]
    X: np.ndarray
    sigma: np.ndarray
    nis: np.ndarray
    P: np.ndarray
    estimate: list[str] = field(default_factory=list)

    def final(self) -> dict[str, tuple[float, float]]:
        """Estimated parameter -> (final estimate, final 1-sigma)."""
        ns = len(self.names) - len(self.estimate)
        return {k: (float(self.X[-1, ns + i]), float(self.sigma[-1, ns + i])) for i, k in enumerate(self.estimate)}


def _as_matrix(v, n: int, what: str) -> np.ndarray:
    """A covariance given as a scalar, a vector of variances (diagonal) or an n x n matrix."""
    a = np.asarray(v, dtype=np.float64)
    if a.ndim == 0:
        a = np.full(n, float(a))
    if a.ndim == 1:
        if a.size != n:
            raise ConfigError(f"{what}: expected {n} variances, got {a.size}")
        a = np.diag(a)
    if a.shape != (n, n):
        raise ConfigError(f"{what}: expected a {n}x{n} matrix, got shape {a.shape}")
    if not np.all(np.isfinite(a)):
        raise ConfigError(f"{what}: non-finite entries")
    if not np.allclose(a, a.T, rtol=1e-10, atol=0.0):
        raise ConfigError(f"{what}: not symmetric")
    return np.ascontiguousarray(a)


def check_covariance(a: np.ndarray, what: str, definite: bool = True) -> None:
    """Raise ConfigError unless ``a`` is positive definite (or semi-definite when ``definite`` is False)."""
    ev = np.linalg.eigvalsh(a) if a.size else np.zeros(0)
    lo = float(ev.min()) if ev.size else 0.0
    scale = float(np.abs(ev).max()) if ev.size else 0.0
    if definite and not lo > 0.0:
        raise ConfigError(f"{what} is not positive definite (smallest eigenvalue {lo:.3g}); give positive variances")
    if not definite and lo < -1e-12 * max(scale, 1e-300):
        raise ConfigError(f"{what} is not positive semi-definite (smallest eigenvalue {lo:.3g})")


def resolve_estimate(model: EKFModel, estimate: Sequence[str] | str) -> np.ndarray:
    """Parameter names -> indices in ``model.params``; unknown or repeated names give InputError."""
    if isinstance(estimate, str):
        estimate = [s.strip() for s in estimate.split(",") if s.strip()]
    estimate = list(estimate)
    if not estimate:
        raise InputError("no parameter to estimate; give e.g. --estimate " + ",".join(model.param_names[:3]))
    names = list(model.param_names)
    bad = [e for e in estimate if e not in names]
    if bad:
        raise InputError(f"unknown parameter(s) {', '.join(bad)} for model {model.name}; known: {', '.join(names)}")
    dup = sorted({e for e in estimate if estimate.count(e) > 1})
    if dup:
        raise InputError(f"parameter(s) listed twice: {', '.join(dup)}")
    layout = getattr(model, "layout", None)
    if layout is not None:
        derived = [e for e in estimate if layout.derived[names.index(e)]]
        if derived:
            raise InputError(
                f"parameter(s) {', '.join(derived)} of model {model.name} are derived from others "
                "(e.g. an inverse mass matrix) and cannot be estimated"
            )
    return np.array([names.index(e) for e in estimate], dtype=np.int64)


def run_ekf(
    model: Model | EKFModel,
    t,
    Z,
    U,
    estimate: Sequence[str] | str,
    x0,
    alpha0,
    P0,
    Q,
    R,
    substeps: int = 1,
    jacobian: str | None = None,
    params=None,
) -> EKFResult:
    """Identify ``estimate`` (parameter names of ``model``) from measurements by the augmented EKF.

    Parameters
    ----------
    model : Model (any model of the project, :func:`get_model`) or a legacy EKFModel
    t : (N,) s, strictly increasing sample times
    Z : (N, n_z) measurements (NaN marks a missing component)
    U : (N, n_u) inputs; ``U[k]`` is held over [t_k, t_k+1)
    estimate : names (or a comma-separated string) of the parameters to estimate
    x0 : (n_s,) initial state estimate;  alpha0 : (n_a,) initial parameter guesses
    P0 : initial covariance of [x_s, alpha]: scalar, variances (n,) or (n, n) matrix, positive definite
    Q : process-noise spectral density of [x_s, alpha] (per second), positive semi-definite
    R : measurement-noise covariance (n_z,) or (n_z, n_z), positive definite
    substeps : RK4 steps per sample interval
    jacobian : "analytic", "complex-step" or "finite-difference"; default analytic if the model has
        one, else complex step
    params : full parameter vector to use instead of ``model.params`` for the fixed parameters

    Raises
    ------
    InputError : unknown parameter names, inconsistent shapes, non-finite inputs or times
    ConfigError : a covariance that is not (semi-)definite, a bad Jacobian mode
    FilterDivergedError : the filter diverged (with the time and the reason)
    """
    model = as_model(model)
    idx = resolve_estimate(model, estimate)
    est_names = [model.param_names[i] for i in idx]
    ns = len(model.state_names)
    nz = len(model.measurement_names)
    na = idx.size
    n = ns + na
    # fresh, writeable, C-contiguous copies: one compiled signature whatever the caller passes
    t = np.array(t, dtype=np.float64, order="C", copy=True).ravel()
    Z = np.array(np.atleast_2d(np.asarray(Z, dtype=np.float64)), order="C", copy=True)
    U = np.array(np.asarray(U, dtype=np.float64).reshape(t.size, -1), order="C", copy=True)
    if t.ndim != 1 or t.size < 2:
        raise InputError("need at least two samples")
    if Z.shape != (t.size, nz):
        raise InputError(f"measurements: expected shape ({t.size}, {nz}), got {Z.shape}")
    if U.shape[1] != len(model.input_names):
        raise InputError(f"inputs: expected {len(model.input_names)} column(s), got {U.shape[1]}")
    if not np.all(np.isfinite(t)) or np.any(np.diff(t) <= 0):
        raise InputError("sample times must be finite and strictly increasing")
    if not np.all(np.isfinite(U)):
        raise InputError("inputs contain NaN or infinite values")
    if np.all(~np.isfinite(Z)):
        raise InputError("no finite measurement")
    x0 = np.asarray(x0, dtype=np.float64).ravel()
    alpha0 = np.asarray(alpha0, dtype=np.float64).ravel()
    if x0.size != ns or alpha0.size != na:
        raise InputError(f"initial state needs {ns} values and initial guesses {na}, got {x0.size} and {alpha0.size}")
    if not (np.all(np.isfinite(x0)) and np.all(np.isfinite(alpha0))):
        raise InputError("initial state or guesses are not finite")
    P0m = _as_matrix(P0, n, "P0")
    Qm = _as_matrix(Q, n, "Q")
    Rm = _as_matrix(R, nz, "R")
    check_covariance(P0m, "P0")
    check_covariance(Qm, "Q", definite=False)
    check_covariance(Rm, "R")
    if int(substeps) < 1:
        raise ConfigError("substeps must be >= 1")
    mode = default_mode(model, jacobian)
    p = np.array(model.params if params is None else params, dtype=np.float64)
    if p.size != len(model.param_names):
        raise InputError(f"params: expected {len(model.param_names)} values, got {p.size}")
    X0 = np.array(np.concatenate([x0, alpha0]), order="C")
    bound = np.full(n, float(model.bound))
    Xout = np.full((t.size, n), np.nan)
    Sout = np.full((t.size, n), np.nan)
    NIS = np.full(t.size, np.nan)
    P = np.zeros((n, n))
    from ._ekf_kernel import make_kernel

    loop = make_kernel(model.f, model.h, model.jac, mode)
    status, k = _call(
        loop, X0, P0m, Qm, Rm, p, idx, t, Z, U, int(substeps), bound, Xout, Sout, NIS, P, model=model, mode=mode
    )
    if status != 0:
        why = {
            1: "non-finite estimate",
            2: "covariance no longer positive definite",
            3: f"an estimate exceeded {model.bound:g} in magnitude",
        }[status]
        raise FilterDivergedError(
            f"EKF diverged at t={t[k]:.3f} s (sample {k}): {why}; check Q, R, P0 and the initial guesses"
        )
    return EKFResult(t=t, names=[*model.state_names, *est_names], X=Xout, sigma=Sout, nis=NIS, P=P, estimate=est_names)


# -- models known by name (CLI): the one model registry of oceangnc.core.model -------------------------

MODELS = ModelNames()

#: the heave-pitch submarine of document 002 (filter states w, theta, q; analytic Jacobian)
submarine_vertical_model = filter_model


def nees(err: np.ndarray, P: np.ndarray) -> float:
    """Normalised estimation error squared e^T P^-1 e (chi-square with len(e) dof if consistent)."""
    e = np.asarray(err, dtype=np.float64)
    return float(e @ np.linalg.solve(P, e))
