"""Checks that a first-order fit can be trusted; ``oceangnc identify first-order`` refuses a log that fails one.

Every fitted trial (integral method or zig-zag least squares) is checked four ways, each with a named
threshold below; the values are kept in the report (``checks`` of each trial in identification.json) and
the command exits 2 with one line naming the trial, the check and its value when one fails
(``--skip-check NAME`` accepts a failure knowingly, and prints a warning instead):

``bound``
    The time constant is at the bound of what the fit can give: the zig-zag optimiser's bounds
    (:data:`T_BOUNDS`, e.g. stuck at 0.001 s) or, for either method, below one sample interval (a lag
    shorter than the sampling is not resolved; the integral method gives it as ~0 or negative).
``condition``
    The information matrix is singular or near-singular: the condition number of the equilibrated
    (unit-column) normal matrix ``J^T J`` of (K, T) - the Jacobian of the zig-zag's heading, or the 2x2
    system of eq. 11 + 13 (18 + 20) of the integral method - above :data:`MAX_CONDITION`. For two
    parameters it is (1 + |rho|) / (1 - |rho|) with rho their correlation: 1e6 means |rho| > 0.999998,
    K and T cannot be told apart.
``fit``
    The model does not reproduce the measured output: the fit ``100 (1 - |e| / |y - mean y|)`` %, with
    e the residual of the identified model driven by the measured input (yaw rate or speed of a step
    trial over t1..t3, heading of a zig-zag), below :data:`MIN_FIT_PCT`.
``whiteness``
    The residual is not white noise (the model misses structure): Ljung-Box test on its autocorrelation
    over :func:`lb_lags` lags, at 5 % for the whole log (Bonferroni: 5 % / number of trials per trial).
    The residual is thinned to at most one sample per :data:`WHITENESS_SPACING_S` so that a log resampled
    above its sensors' rates (interpolated samples are correlated) is not refused for that. A residual
    below :data:`NEGLIGIBLE_RESIDUAL` of the output's spread (a fit above 99 %: noise-free data, where
    even the sampling's discretisation error is "coloured") is too small for its colour to matter: not
    tested.
"""

from __future__ import annotations

import math

import numpy as np

#: the zig-zag optimiser's bounds on T, s
T_BOUNDS = (1e-3, 1e3)
#: largest condition number of the equilibrated information matrix accepted
MAX_CONDITION = 1e6
#: smallest fit accepted, %
MIN_FIT_PCT = 50.0
#: significance of the whiteness test for a whole log (split over its trials)
ALPHA = 0.05
#: the residual is thinned to one sample per this spacing at most before the whiteness test, s
WHITENESS_SPACING_S = 0.5
#: a residual rms below this fraction of the output's spread is too small to test for whiteness
NEGLIGIBLE_RESIDUAL = 0.01
#: the checks, in the order they are reported
CHECKS = ("bound", "condition", "fit", "whiteness")


def equilibrated_condition(J) -> float:
    """Condition number of ``J^T J`` with the columns of J scaled to unit norm (inf if a column is zero)."""
    J = np.asarray(J, float)
    n = np.linalg.norm(J, axis=0)
    if not np.all(np.isfinite(J)) or np.any(n == 0):
        return math.inf
    s = np.linalg.svd(J / n, compute_uv=False)
    return float((s[0] / s[-1]) ** 2) if s[-1] > 0 else math.inf


def lb_lags(n: int) -> int:
    """Lags of the Ljung-Box test: min(10, n // 5), at least 1."""
    return max(1, min(10, n // 5))


def ljung_box(e, lags: int | None = None) -> tuple[float, float, int]:
    """Ljung-Box Q of a residual series, its p-value (chi-square with ``lags`` dof) and the lags."""
    from scipy.stats import chi2

    e = np.asarray(e, float)
    e = e - e.mean()
    n = e.size
    h = lags or lb_lags(n)
    d = float(e @ e)
    if n < 3 or d == 0:
        return 0.0, 1.0, h
    rho = np.array([float(e[k:] @ e[:-k]) / d for k in range(1, h + 1)])
    q = float(n * (n + 2) * np.sum(rho**2 / (n - np.arange(1, h + 1))))
    return q, float(chi2.sf(q, h)), h


def fit_pct(y, e) -> float:
    """``100 (1 - |e| / |y - mean y|)``: 100 for a perfect fit, 0 for the mean alone, negative if worse."""
    y = np.asarray(y, float)
    d = float(np.linalg.norm(y - y.mean()))
    if d == 0:
        return -math.inf
    return float(100.0 * (1.0 - np.linalg.norm(e) / d))


def first_order_response(t, w, K, T, y0):
    """``T y' + y = K w`` from y0 at t[0], w held from each sample to the next (exact discretisation)."""
    t = np.asarray(t, float)
    w = np.asarray(w, float)
    y = np.empty(t.size)
    y[0] = y0
    if not (T > 0 and math.isfinite(T)):
        y[1:] = K * w[:-1]  # no lag (or a meaningless one): the static response
        return y
    a = np.exp(-np.diff(t) / T)
    for k in range(t.size - 1):
        y[k + 1] = a[k] * y[k] + (1.0 - a[k]) * K * w[k]
    return y


def assess(t, y, e, K, T, cond, h, at_bound: str | None = None) -> dict:
    """The raw values of the four checks of one fit (the whiteness p-value is judged later, per log)."""
    t = np.asarray(t, float)
    y = np.asarray(y, float)
    e = np.asarray(e, float)
    spread = float(np.linalg.norm(y - y.mean()))
    rms_ratio = float(np.linalg.norm(e) / spread) if spread > 0 else math.inf
    out: dict = {"T": float(T), "sample_s": float(h), "condition": float(cond), "fit_pct": fit_pct(y, e)}
    if at_bound:
        out["bound"] = at_bound
    elif not (T > h):
        out["bound"] = f"T = {T:.4g} s is below one sample interval ({h:.3g} s): the lag is not resolved"
    if rms_ratio < NEGLIGIBLE_RESIDUAL:
        out["whiteness_p"] = None  # a (nearly) exact fit: nothing worth testing
        out["whiteness_note"] = f"residual {rms_ratio:.1e} of the output's spread, below 1 %: not tested"
        return out
    span = float(t[-1] - t[0]) if t.size > 1 else 0.0
    step = max(1, int(round(WHITENESS_SPACING_S / h))) if h > 0 else 1
    ee = e[::step]
    q, p, lags = ljung_box(ee)
    out.update({"whiteness_p": p, "ljung_box_q": q, "lags": lags, "samples": int(ee.size), "span_s": span})
    return out


def judge(fits: list, skip=(), alpha: float = ALPHA) -> list[dict]:
    """Failures of a log's fits: ``fits`` are (label, checks dict) pairs; the whiteness level is
    ``alpha / len(fits)`` per fit (Bonferroni). Returns one dict per failed check (label, check, message),
    in trial order, the skipped ones marked ``skipped``; adds the ``failed`` list to each checks dict."""
    n = max(1, len(fits))
    level = alpha / n
    out = []
    for label, c in fits:
        failed = []
        if c.get("bound"):
            failed.append(("bound", c["bound"]))
        if not (c["condition"] <= MAX_CONDITION):
            failed.append(
                (
                    "condition",
                    f"information matrix near-singular: condition number {c['condition']:.3g} > "
                    f"{MAX_CONDITION:.0e} (K and T cannot be told apart)",
                )
            )
        if not (c["fit_pct"] >= MIN_FIT_PCT):
            failed.append(("fit", f"fit {c['fit_pct']:.1f} % < {MIN_FIT_PCT:g} % (the model does not follow the log)"))
        p = c.get("whiteness_p")
        c["whiteness_level"] = level
        if p is not None and p < level:
            failed.append(
                (
                    "whiteness",
                    f"residual not white: Ljung-Box p = {p:.2g} < {level:.2g} ({c['lags']} lags, "
                    f"{c['samples']} samples; 5 % over {n} trial(s))",
                )
            )
        c["failed"] = [k for k, _ in failed]
        for k, msg in failed:
            out.append({"label": label, "check": k, "message": msg, "skipped": k in skip})
    return out
