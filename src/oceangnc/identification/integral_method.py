"""The integral method of 000 sec. 2.2 on one step trial (eq. 8-21), and a coefficient's line against
speed (000 table 2); see :mod:`oceangnc.identification.first_order` for the method and its choices."""

from __future__ import annotations

import math

import numpy as np

from ..errors import InputError
from .first_order_checks import assess, equilibrated_condition, first_order_response
from .first_order_results import LinearFit, StepFit


def noise_std(y) -> float:
    """Noise standard deviation of a smooth signal plus white noise, from robust second differences."""
    y = np.asarray(y, float)
    if y.size < 5:
        return 0.0
    d2 = np.diff(y, 2)
    mad = np.median(np.abs(d2 - np.median(d2)))
    return float(1.4826 * mad / math.sqrt(6.0))


def _zoh_integral(t, w, a, b):
    """int_{t_a}^{t_b} w dt with w held from each sample to the next (indices a <= b)."""
    return float(np.sum(w[a:b] * np.diff(t[a : b + 1])))


def _trapz_cum(t, y):
    return np.concatenate([[0.0], np.cumsum(0.5 * np.diff(t) * (y[1:] + y[:-1]))])


def _smooth(y, m):
    """Centred moving average over m samples; the window shrinks at the ends (no padding)."""
    if m <= 1:
        return y
    k = np.ones(m)
    return np.convolve(y, k, mode="same") / np.convolve(np.ones_like(y), k, mode="same")


def detect_points(
    t, w, y, settle_tol: float = 0.01, min_steady_s: float = 3.0, label: str = "trial", out_name: str = "output"
):
    """Sample indices (i1, i2, i3) of the transient (1, 2) and steady (2, 3) intervals of a step trial."""
    n = t.size
    if n < 10:
        raise InputError(f"{label}: only {n} samples; a trial needs at least 10")
    w0 = w[0]
    tail = max(3, n // 5)
    wf = float(np.median(w[-tail:]))
    dw = wf - w0
    if not abs(dw) > 1e-12 * max(1.0, float(np.max(np.abs(w)))):
        raise InputError(f"{label}: the input does not step (it stays at {w0:.4g}); cannot identify K and T")
    moved = np.nonzero(np.abs(w - w0) > 0.01 * abs(dw))[0]
    i1 = int(max(moved[0] - 1, 0))
    h = float(np.median(np.diff(t)))
    sig = noise_std(y)
    yf = float(np.mean(y[-tail:]))
    dy = yf - float(y[i1])
    if sig <= 1e-6 * abs(dy):  # noise-free (numerical noise only): no smoothing, point values
        sig = 0.0
    m = int(round(1.0 / h)) if sig > 0 else 1
    ys = _smooth(y, m)
    y1 = float(np.mean(y[max(0, i1 - m + 1) : i1 + 1]))
    dy = yf - y1
    if not abs(dy) > 5 * sig + 1e-12:
        raise InputError(
            f"{label}: the {out_name} does not respond to the input step (change {dy:.3g}, noise {sig:.3g})"
        )
    tol = settle_tol * abs(dy) + 5.0 * sig / math.sqrt(max(1, m // 2))
    off = np.nonzero(np.abs(ys[i1:] - yf) > tol)[0]
    i2 = i1 + (int(off[-1]) + 1 if off.size else 1)
    i3 = n - 1
    i2 = min(i2, i3)
    # the last stretch must be flat: its linear trend must stay inside the settling band
    k0 = n - tail
    slope = np.polyfit(t[k0:], y[k0:], 1)[0]
    drift = abs(slope) * (t[i3] - t[k0])
    if drift > 2 * tol or i2 >= i3 or t[i3] - t[i2] < min_steady_s:
        raise InputError(
            f"{label}: no steady interval: the {out_name} changes by {100 * drift / abs(dy):.1f} % "
            f"of its step over the last {t[i3] - t[k0]:.1f} s and is within {100 * tol / abs(dy):.1f} % "
            f"of its final value only for the last {t[i3] - t[i2]:.1f} s (need {min_steady_s:g} s); "
            f"lengthen the trial or give the points with --points T1 T2 T3"
        )
    return i1, i2, i3, m, sig


def _local(t, y, i, win):
    """Value of y at sample i from a straight-line fit over the sample window [a, b) (noise averaging)."""
    a, b = win
    if b - a < 3:
        return float(y[i])
    tt = t[a:b] - t[i]
    c = np.polyfit(tt, y[a:b], 1)
    return float(c[1])


def _system(t, w, y, Y, i1, i2, i3, m: int = 1):
    """The 2x2 system ``A (K, T) = b`` of eq. 11 + 13 (18 + 20), and the output's value y_1 at point 1."""
    iw23 = _zoh_integral(t, w, i2, i3)
    iw12 = _zoh_integral(t, w, i1, i2)
    if iw23 == 0.0:
        raise InputError("steady interval has zero input integral; cannot compute K (eq. 12/19)")
    w1 = (max(0, i1 - m + 1), i1 + 1)
    h2 = max(1, m // 2)
    w2 = (max(i1 + 1, i2 - h2), min(i3, i2 + h2 + 1))
    w3 = (max(i2 + 1, i3 - m + 1), i3 + 1)
    y1, y2, y3 = (_local(t, y, i, w) for i, w in ((i1, w1), (i2, w2), (i3, w3)))
    Y1, Y2, Y3 = (_local(t, Y, i, w) for i, w in ((i1, w1), (i2, w2), (i3, w3)))
    if y2 == y1:
        raise InputError("the output does not change over the transient interval; cannot compute T (eq. 14/21)")
    A = np.array([[iw23, -(y3 - y2)], [iw12, -(y2 - y1)]])
    b = np.array([Y3 - Y2, Y2 - Y1])
    return A, b, y1


def integral_estimate(t, w, y, Y, i1, i2, i3, m: int = 1, method: str = "joint"):
    """(K, T) from the integral relations over the intervals (1, 2) and (2, 3) (000 eq. 11-14, 18-21).

    ``method="paper"`` uses eq. 12/19 and 14/21 as printed, i.e. sets y_3 - y_2 = 0 in eq. 11/18;
    ``method="joint"`` (default) solves eq. 11 and 13 (18 and 20) together as a 2x2 linear system,
    which is exact for a first-order system even when the output is still creeping at point 2,
    and reduces to the paper's formulas when y_3 = y_2.
    """
    A, b, _ = _system(t, w, y, Y, i1, i2, i3, m)
    if method == "paper":
        K = b[0] / A[0, 0]
        T = (K * A[1, 0] - b[1]) / -A[1, 1]
        return float(K), float(T)
    K, T = np.linalg.solve(A, b)
    return float(K), float(T)


def identify_step(
    t,
    w,
    y,
    Y=None,
    Y_measured: bool = False,
    kind: str = "turn",
    trial: int = 0,
    speed=None,
    points=None,
    settle_tol: float = 0.01,
    min_steady_s: float = 3.0,
    n_mc: int = 200,
    rng=None,
    out_name: str = "output",
    method: str = "joint",
) -> StepFit:
    """Integral-method fit of one step trial.

    Parameters
    ----------
    t, w, y : arrays
        Time (s), input (delta_S or delta_T) and output (r or v).
    Y : array, optional
        Integral of y (the measured heading for a turning trial); default the trapezoid integral of y.
    Y_measured : bool
        Y is a measurement with its own noise (heading), used for the uncertainty.
    speed : array, optional
        Speed signal (m/s) for the trial's speed (mean over the steady interval); default y.
    points : (t1, t2, t3), optional
        Override of the automatic detection (s).
    """
    t = np.asarray(t, float)
    w = np.asarray(w, float)
    y = np.asarray(y, float)
    label = f"trial {trial} ({kind})"
    if points is not None:
        idx = [int(np.argmin(np.abs(t - p))) for p in points]
        i1, i2, i3 = idx
        if not i1 < i2 < i3:
            raise InputError(f"{label}: --points must satisfy t1 < t2 < t3 inside the trial, got {points}")
        sig = noise_std(y)
        if sig <= 1e-6 * float(np.ptp(y)):
            sig = 0.0
        m = int(round(1.0 / float(np.median(np.diff(t))))) if sig > 0 else 1
    else:
        i1, i2, i3, m, sig = detect_points(t, w, y, settle_tol, min_steady_s, label, out_name)
    Yc = _trapz_cum(t, y) if Y is None else np.asarray(Y, float)
    K, T = integral_estimate(t, w, y, Yc, i1, i2, i3, m, method)
    K_std = T_std = 0.0
    if sig > 0 and n_mc > 1:
        rng = rng if rng is not None else np.random.default_rng(0)
        sigY = noise_std(Yc) if Y_measured else 0.0
        ks, ts = np.empty(n_mc), np.empty(n_mc)
        for j in range(n_mc):
            yn = y + rng.normal(0.0, sig, y.size)
            Yn = _trapz_cum(t, yn) if Y is None else Yc + rng.normal(0.0, sigY, y.size)
            ks[j], ts[j] = integral_estimate(t, w, yn, Yn, i1, i2, i3, m, method)
        K_std, T_std = float(np.std(ks)), float(np.std(ts))
    sp = y if speed is None else np.asarray(speed, float)
    k_sp = max(i2, i3 + 1 - max(3, t.size // 5))  # the trial's speed: mean over the end of the steady interval
    # what the checks need: the system's conditioning and the residual of the model over t1..t3
    A, _, y1 = _system(t, w, y, Yc, i1, i2, i3, m)
    seg = slice(i1, i3 + 1)
    e = y[seg] - first_order_response(t[seg], w[seg], K, T, y1)
    checks = assess(t[seg], y[seg], e, K, T, equilibrated_condition(A), float(np.median(np.diff(t))))
    return StepFit(
        trial,
        kind,
        float(np.mean(sp[k_sp : i3 + 1])),
        K,
        T,
        K_std,
        T_std,
        float(t[i1]),
        float(t[i2]),
        float(t[i3]),
        sig,
        checks,
    )


def fit_vs_speed(name: str, speeds, values) -> LinearFit:
    """Least-squares line ``value = a u + b`` over trials, with residuals and standard errors (000 table 2)."""
    u = np.asarray(speeds, float)
    v = np.asarray(values, float)
    n = u.size
    if n < 2 or np.ptp(u) == 0:
        raise InputError(f"fit of {name} against speed needs trials at >= 2 different speeds, got {n}")
    A = np.column_stack([u, np.ones(n)])
    coef, *_ = np.linalg.lstsq(A, v, rcond=None)
    res = v - A @ coef
    if n > 2:
        s2 = float(res @ res) / (n - 2)
        cov = s2 * np.linalg.inv(A.T @ A)
        sa, sb = math.sqrt(cov[0, 0]), math.sqrt(cov[1, 1])
    else:
        sa = sb = float("nan")
    return LinearFit(
        name, float(coef[0]), float(coef[1]), sa, sb, float(np.sqrt(np.mean(res**2))), res.tolist(), u.tolist(), n
    )
