"""Can this log identify these parameters at all? ``oceangnc identify ekf`` refuses a log that cannot.

A filter run on a log without excitation (a straight run, the stern plane never moved) still returns
numbers, and an over-confident covariance: 8 to 17 times off with a 1-sigma of 0.00 % on the log of the
issue-41 review. Before the filter runs, the log is checked as ``identify first-order`` checks its fits
(:mod:`oceangnc.identification.first_order_checks`), from the parameters' effect on the measurements:

* the model is simulated open-loop from the log's first sample over the log's inputs (held over each
  sample interval, :meth:`oceangnc.core.model.Model.simulate`), at the initial guess and with each estimated
  parameter a_j moved by a relative step (:data:`REL_STEP`); the columns of the sensitivity matrix are
  S_j = a_j dz/da_j / sigma_z, stacked over the samples and the measured channels (sigma_z the measurement
  noise of each channel), so S^T S is the Fisher information of the relative parameters;
* ``excitation``: the Cramer-Rao bound of each relative parameter, sqrt(diag((S^T S)^-1)), is at most
  :data:`MAX_REL_SIGMA` (10: the log cannot tell a_j from 10 a_j, the 8-17 times of the review; a column of
  zeros - nothing the parameter does shows in the log, e.g. the stern-plane coefficients of a log whose plane
  never moved - is infinite). Above :data:`WEAK_REL_SIGMA` (1) the parameter is reported as weakly identified
  (a warning, not a refusal: 002's own 10-5 zig-zag with all ten coefficients gives Zqdot 1.9, measured);
* ``condition``: the condition number of the equilibrated S^T S (unit columns,
  :func:`~oceangnc.identification.first_order_checks.equilibrated_condition`) is at most
  :data:`MAX_CONDITION_EKF` (1e12: the effects are linearly dependent to rounding). Above
  :data:`~oceangnc.identification.first_order_checks.MAX_CONDITION` (1e6, the first-order fit's refusal) it
  is a warning: the ten coefficients of 002's zig-zag give 3.0e9 (measured), correlated pairs such as Zq and
  Zqdot that the filter still bounds jointly.

The open-loop simulation is the local (linearised) identifiability of the parameters along the logged
trajectory: it neglects the filter's process noise, which only lowers the information, so the test refuses
only logs that cannot identify the parameters even in the best case. A model that diverges open-loop at the
initial guess on the log's inputs is not checked (a warning says so).
"""

from __future__ import annotations

import math

import numpy as np

from ..errors import InputError
from .first_order_checks import MAX_CONDITION, equilibrated_condition

#: the largest Cramer-Rao 1-sigma of a relative parameter accepted (10: the log cannot tell a_j from 10 a_j)
MAX_REL_SIGMA = 10.0
#: above this relative Cramer-Rao 1-sigma a parameter is reported as weakly identified (a warning)
WEAK_REL_SIGMA = 1.0
#: the largest condition number of the equilibrated information matrix accepted (above MAX_CONDITION: a warning)
MAX_CONDITION_EKF = 1e12
#: relative step of the finite-difference sensitivities
REL_STEP = 1e-6
#: at most this many samples enter the check (the log is thinned evenly above it)
MAX_SAMPLES = 20000


def _measured(model, X: np.ndarray, U: np.ndarray, p: np.ndarray) -> np.ndarray:
    if model.h is None:
        return X
    return np.array([model.output(X[k], U[k], p) for k in range(X.shape[0])])


def sensitivity(model, t, Z, U, idx, a0, sd) -> np.ndarray:
    """S (samples x channels, parameters): a_j dz/da_j / sigma_z along the open-loop response from Z[0]."""
    t = np.asarray(t, float)
    step = max(1, int(math.ceil(t.size / MAX_SAMPLES)))
    t, U = t[::step], np.asarray(U, float)[::step]
    p0 = np.array(model.params, dtype=np.float64)
    p0[idx] = a0
    x0 = np.asarray(Z[0], float)[: model.nx]
    base = _measured(model, model.simulate(t, U, x0, substeps=step, p=p0), U, p0)  # the log's own step
    cols = []
    for j, i in enumerate(idx):
        p = p0.copy()
        h = REL_STEP * abs(a0[j])
        p[i] += h
        zj = _measured(model, model.simulate(t, U, x0, substeps=step, p=p), U, p)
        cols.append(((zj - base) * (a0[j] / h) / sd).ravel())
    return np.column_stack(cols) * math.sqrt(step)  # a thinned log: each kept sample stands for `step`


def identifiability(model, t, Z, U, idx, names, a0, sd) -> tuple[dict, list[str]]:
    """The check values (``condition``, ``rel_sigma`` per parameter) and the failures as one-line messages;
    ``({"skipped": reason}, [])`` when the model diverges open-loop at the initial guess."""
    try:
        S = sensitivity(model, t, Z, U, idx, a0, sd)
    except InputError as e:
        return {"skipped": f"the open-loop model diverges at the initial guess ({e})"}, []
    if not np.all(np.isfinite(S)):
        return {"skipped": "the open-loop model's sensitivities are not finite at the initial guess"}, []
    moved = np.any(S != 0.0, axis=0)  # a zero column fails `excitation`; the conditioning is of the others
    cond = equilibrated_condition(S[:, moved]) if moved.any() else math.inf
    info = S.T @ S
    try:
        cov = np.linalg.inv(info) if moved.all() and cond < 1e15 else None
    except np.linalg.LinAlgError:
        cov = None
    if cov is None:
        rel = {
            k: (math.inf if not np.any(S[:, j]) else float(1.0 / math.sqrt(info[j, j]))) for j, k in enumerate(names)
        }
    else:
        rel = {k: float(math.sqrt(max(cov[j, j], 0.0))) for j, k in enumerate(names)}
    checks = {"condition": float(cond), "rel_sigma": rel, "max_rel_sigma": MAX_REL_SIGMA}
    fails, warns = [], []
    weak = [k for k, v in rel.items() if not v <= MAX_REL_SIGMA]
    if weak:
        worst = max(weak, key=lambda k: rel[k])
        fails.append(
            f"excitation: the log does not move the measurements enough to identify {', '.join(weak)} "
            f"(Cramer-Rao 1-sigma of {worst} {rel[worst]:.3g} times its value > {MAX_REL_SIGMA:g}); "
            "log a manoeuvre that excites them (e.g. the ekf-zigzag scenario's zig-zag)"
        )
    if not cond <= MAX_CONDITION_EKF:
        fails.append(
            f"condition: the information matrix of {', '.join(names)} is singular (condition number "
            f"{cond:.3g} > {MAX_CONDITION_EKF:.0e}): the log cannot tell their effects apart; estimate fewer"
        )
    elif cond > MAX_CONDITION:
        warns.append(f"information matrix ill-conditioned ({cond:.3g} > {MAX_CONDITION:.0e}): correlated estimates")
    poor = [f"{k} ({rel[k]:.2g})" for k in names if WEAK_REL_SIGMA < rel[k] <= MAX_REL_SIGMA]
    if poor:
        warns.append(
            f"weakly identified by this log (Cramer-Rao 1-sigma / value > {WEAK_REL_SIGMA:g}): {', '.join(poor)}"
        )
    checks["warnings"] = warns
    return checks, fails
