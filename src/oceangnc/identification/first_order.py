"""Identification of first-order speed and Nomoto models from trials (document 000 eq. 8-21, table 2).

Integral method (000 sec. 2.2). For ``T y' + y = K w`` integrated between two instants (eq. 9-10,
16-17), ``T (y_b - y_a) + Y_b - Y_a = K int_a^b w dt``, with Y the integral of y: the heading psi for
the yaw-rate model (y = r, w = delta_S) and ``int v dt`` for the speed model (y = v, w = delta_T).
A step trial has a transient interval (1, 2) after the input step and a steady interval (2, 3) on
which y is constant, so (eq. 11-12, 18-19; (19) prints delta_S for delta_T, a typo)

    K = (Y_3 - Y_2) / int_2^3 w dt
    T = (K int_1^2 w dt - (Y_2 - Y_1)) / (y_2 - y_1)      (eq. 14 prints psi_2 - psi_2: read psi_2 - psi_1; eq. 21)

These drop the term T (y_3 - y_2) of eq. 11/18, exact only if the output is exactly constant from
point 2 on. By default we keep it and solve eq. 11 and 13 (18 and 20) together for (K, T), a 2x2
linear system that is exact for a first-order system and equals the printed formulas when
y_3 = y_2 (``method="paper"`` gives the printed ones).

The instants are found automatically: point 1 is the last sample before the input leaves its initial
value (the step); point 3 is the last sample; point 2 is the first sample after which the (smoothed)
output stays within ``settle_tol`` of its final value (plus 4 standard deviations of the smoothed
noise). A trial whose output has not settled (drifting over the last part, or settling too late to
leave ``min_steady_s`` of steady data) is refused with an :class:`~oceangnc.errors.InputError`
naming the trial. ``points=(t1, t2, t3)`` overrides the detection.

Inputs are commands, integrated with a zero-order hold (the logged value at t_k applied until
t_{k+1}, which is how the simulator and a microcontroller apply them); outputs with the trapezoid
rule. Noise: the output's noise level is estimated from its second differences (robust MAD); point
values y_1, y_2 are averaged over about a second when the data are noisy; the uncertainty of K and T
is the spread of the estimates over ``n_mc`` replicas of the data with that much extra noise added
(a parametric bootstrap).

Speed dependence (000 table 2, figs 11-14): each coefficient is fitted as ``a u + b`` against the
trial speeds by least squares, with the residuals, their rms and the standard errors of a and b.

Zig-zag (ITTC 10/10, 20/20): the Nomoto K, T minimising the heading error of the model driven by the
measured rudder (zero-order hold, exact discretisation), separable least squares (K linear for a
fixed T) refined by ``scipy.optimize.least_squares``; standard errors from the Jacobian (optimistic
when residuals are correlated).
"""

from __future__ import annotations

import math
from dataclasses import asdict, dataclass, field

import numpy as np

from ..errors import InputError

KIND_CODES = {0: "straight", 1: "turn", 2: "zigzag"}


@dataclass
class Columns:
    """Log column names of the signals (CLI options --time --steer --thrust --speed --heading --yaw-rate --trial)."""

    time: str = "t"
    steer: str = "trial.steer"
    thrust: str = "trial.thrust"
    speed: str = "trial.speed"
    heading: str = "trial.heading"
    yaw_rate: str = "trial.yaw_rate"
    trial: str | None = "trial.id"
    kind: str | None = "trial.kind"


@dataclass
class StepFit:
    """Result of the integral method on one step trial (units: those of the log's columns)."""

    trial: int
    kind: str
    speed: float  # mean speed over the last part of the steady interval, m/s
    K: float
    T: float
    K_std: float
    T_std: float
    t1: float
    t2: float
    t3: float
    noise_std: float  # estimated output noise (y units)


@dataclass
class LinearFit:
    """``value = slope * u + intercept`` fitted over trials (000 table 2)."""

    name: str
    slope: float
    intercept: float
    slope_std: float
    intercept_std: float
    residual_rms: float
    residuals: list
    speeds: list
    n: int


@dataclass
class ZigzagFit:
    """Least-squares Nomoto fit of a zig-zag trial."""

    trial: int
    speed: float
    amplitude_deg: float  # heading change at the rudder reversals, deg (10 for a 10/10 zig-zag)
    rudder: float  # rudder amplitude, steer units (rad for an angle)
    K: float
    T: float
    K_std: float
    T_std: float
    heading_rms_deg: float


@dataclass
class Report:
    """Everything an identification run found."""

    steps: list = field(default_factory=list)
    fits: dict = field(default_factory=dict)
    zigzags: list = field(default_factory=list)
    units: dict = field(default_factory=dict)

    def to_dict(self) -> dict:
        return {
            "units": self.units,
            "trials": [asdict(s) for s in self.steps],
            "speed_fits": {k: asdict(v) for k, v in self.fits.items()},
            "zigzag": [asdict(z) for z in self.zigzags],
        }

    def table(self) -> str:
        """Human-readable tables (trials, linear fits, zig-zags)."""
        lines = []
        if self.steps:
            lines.append(
                f"{'trial':>5} {'kind':<8} {'speed':>7} {'K':>11} {'+-K':>9} {'T [s]':>8} {'+-T':>7} "
                f"{'t1':>7} {'t2':>7} {'t3':>7}"
            )
            for s in self.steps:
                lines.append(
                    f"{s.trial:>5d} {s.kind:<8} {s.speed:7.3f} {s.K:11.5g} {s.K_std:9.2g} {s.T:8.4f} "
                    f"{s.T_std:7.2g} {s.t1:7.2f} {s.t2:7.2f} {s.t3:7.2f}"
                )
        if self.fits:
            lines.append("")
            lines.append(
                f"{'coef':<5} {'slope a':>11} {'+-a':>9} {'intercept b':>12} {'+-b':>9} {'res rms':>9} {'n':>3}"
                "   (coef = a u + b, u in m/s)"
            )
            for k, f in self.fits.items():
                lines.append(
                    f"{k:<5} {f.slope:11.5g} {f.slope_std:9.2g} {f.intercept:12.5g} {f.intercept_std:9.2g} "
                    f"{f.residual_rms:9.2g} {f.n:3d}"
                )
        if self.zigzags:
            lines.append("")
            lines.append(
                f"{'trial':>5} {'psi amp':>8} {'rudder':>8} {'speed':>7} {'K_r':>9} {'+-K':>8} {'T_r':>8} "
                f"{'+-T':>8} {'rms psi':>8}"
            )
            for z in self.zigzags:
                lines.append(
                    f"{z.trial:>5d} {z.amplitude_deg:7.1f}d {z.rudder:8.4g} {z.speed:7.3f} {z.K:9.5g} "
                    f"{z.K_std:8.2g} {z.T:8.4f} {z.T_std:8.2g} {z.heading_rms_deg:7.3f}d"
                )
        if self.units:
            lines.append("")
            lines.append("units: " + "; ".join(f"{k} in {v}" for k, v in self.units.items()))
        return "\n".join(lines)


# -- helpers --------------------------------------------------------------------------------------------


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


def integral_estimate(t, w, y, Y, i1, i2, i3, m: int = 1, method: str = "joint"):
    """(K, T) from the integral relations over the intervals (1, 2) and (2, 3) (000 eq. 11-14, 18-21).

    ``method="paper"`` uses eq. 12/19 and 14/21 as printed, i.e. sets y_3 - y_2 = 0 in eq. 11/18;
    ``method="joint"`` (default) solves eq. 11 and 13 (18 and 20) together as a 2x2 linear system,
    which is exact for a first-order system even when the output is still creeping at point 2,
    and reduces to the paper's formulas when y_3 = y_2.
    """
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
    if method == "paper":
        K = (Y3 - Y2) / iw23
        T = (K * iw12 - (Y2 - Y1)) / (y2 - y1)
        return float(K), float(T)
    A = np.array([[iw23, -(y3 - y2)], [iw12, -(y2 - y1)]])
    b = np.array([Y3 - Y2, Y2 - Y1])
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


def _nomoto_basis(t, delta, T, r0):
    """Heading increments of the Nomoto model with K = 1 (g) and of the initial rate r0 (q), ZOH on delta."""
    from scipy.signal import lfilter

    h = np.diff(t)
    hm = float(np.mean(h))
    a = math.exp(-hm / T)
    d = delta[:-1]
    r = lfilter([0.0, 1.0 - a], [1.0, -a], d)  # r_k for K = 1, r_0 = 0, length n-1
    inc = d * hm + (r - d) * T * (1.0 - a)
    g = np.concatenate([[0.0], np.cumsum(inc)])
    k = np.arange(t.size - 1)
    q = np.concatenate([[0.0], np.cumsum(r0 * a**k * T * (1.0 - a))])
    return g, q


def fit_nomoto_zigzag(t, delta, psi, r0: float = 0.0, trial: int = 0, speed: float = float("nan")) -> ZigzagFit:
    """Least-squares (K, T) of ``T r' + r = K delta`` to a zig-zag trial's heading (rad) driven by delta (rad)."""
    from scipy.optimize import least_squares

    t = np.asarray(t, float)
    delta = np.asarray(delta, float)
    psi = np.unwrap(np.asarray(psi, float))
    h = np.diff(t)
    if np.any(np.abs(h - h.mean()) > 0.01 * h.mean()):
        tu = np.linspace(t[0], t[-1], t.size)
        idx = np.searchsorted(t, tu, side="right") - 1
        delta = delta[np.clip(idx, 0, t.size - 1)]
        psi = np.interp(tu, t, psi)
        t = tu
    y = psi - psi[0]

    def k_of(T):
        g, q = _nomoto_basis(t, delta, T, r0)
        gg = float(g @ g)
        K = float(g @ (y - q)) / gg if gg > 0 else 0.0
        return K, g, q

    def cost(T):
        K, g, q = k_of(T)
        e = K * g + q - y
        return float(e @ e)

    grid = np.geomspace(0.05, 100.0, 80)
    c = [cost(T) for T in grid]
    T0 = float(grid[int(np.argmin(c))])
    K0, _, _ = k_of(T0)

    def resid(p):
        g, q = _nomoto_basis(t, delta, p[1], r0)
        return p[0] * g + q - y

    sol = least_squares(resid, [K0, T0], bounds=([-np.inf, 1e-3], [np.inf, 1e3]), x_scale="jac")
    J = sol.jac
    res = sol.fun
    dof = max(1, res.size - 2)
    s2 = float(res @ res) / dof
    try:
        cov = s2 * np.linalg.inv(J.T @ J)
        ks, ts = math.sqrt(max(cov[0, 0], 0.0)), math.sqrt(max(cov[1, 1], 0.0))
    except np.linalg.LinAlgError:
        ks = ts = float("nan")
    # the zig-zag's heading amplitude: heading change at the rudder reversals (ITTC: equals the rudder angle)
    rev = np.nonzero(np.diff(np.sign(delta)) != 0)[0] + 1
    rev = rev[np.abs(delta[rev - 1]) > 0]
    amp = math.degrees(float(np.mean(np.abs(y[rev])))) if rev.size else float("nan")
    return ZigzagFit(
        trial,
        speed,
        round(amp, 1),
        float(np.max(np.abs(delta))),
        float(sol.x[0]),
        float(sol.x[1]),
        ks,
        ts,
        math.degrees(math.sqrt(float(np.mean(res**2)))),
    )


# -- logs ------------------------------------------------------------------------------------------------


def _classify(steer, thrust) -> str:
    if steer is not None:
        s = np.asarray(steer, float)
        amax = float(np.max(np.abs(s))) if s.size else 0.0
        if amax > 1e-9 and np.ptp(s) > 1e-9:
            if s.min() < -0.3 * amax and s.max() > 0.3 * amax and np.count_nonzero(np.diff(np.sign(s))) >= 3:
                return "zigzag"
            return "turn"
    if thrust is not None and np.ptp(np.asarray(thrust, float)) > 0:
        return "straight"
    return "none"


def check_log(df, cols: Columns, options: dict | None = None):
    """Validate a log for identification: needed columns present, finite, time increasing.

    Raises InputError naming the problem (missing column and the CLI option that names it, NaN values
    and where, non-increasing time and where).
    """
    options = options or {}
    if cols.time not in df.columns:
        raise InputError(
            f"log has no time column '{cols.time}' (--time); columns: {', '.join(map(str, df.columns[:30]))}"
        )
    have = {
        k: getattr(cols, k)
        for k in ("steer", "thrust", "speed", "heading", "yaw_rate")
        if getattr(cols, k) in df.columns
    }
    can_straight = "thrust" in have and "speed" in have
    can_turn = "steer" in have and ("heading" in have or "yaw_rate" in have)
    if not (can_straight or can_turn):
        missing = [
            f"'{getattr(cols, k)}' ({options.get(k, '--' + k.replace('_', '-'))})"
            for k in ("thrust", "speed", "steer", "heading", "yaw_rate")
            if k not in have
        ]
        raise InputError(
            f"log has no column {', '.join(missing)}: need thrust+speed (straight trials) or "
            f"steer+heading/yaw-rate (turning trials); columns: {', '.join(map(str, df.columns[:30]))}"
        )
    t = df[cols.time].to_numpy(float)
    used = [cols.time, *have.values()] + [c for c in (cols.trial, cols.kind) if c and c in df.columns]
    for c in used:
        v = df[c].to_numpy(float)
        bad = ~np.isfinite(v)
        if bad.any():
            i = int(np.argmax(bad))
            where = f"row {i}" + (f", t={t[i]:.3f} s" if c != cols.time and np.isfinite(t[i]) else "")
            raise InputError(f"column '{c}' has {int(bad.sum())} NaN/inf value(s), first at {where}")
    dt = np.diff(t)
    if np.any(dt <= 0):
        i = int(np.argmax(dt <= 0)) + 1
        raise InputError(
            f"time column '{cols.time}' is not increasing at row {i} (t={t[i - 1]:.6g} s then {t[i]:.6g} s)"
        )
    return have


def identify_log(
    df,
    cols: Columns | None = None,
    points=None,
    steer_deg: bool = False,
    heading_deg: bool = False,
    settle_tol: float = 0.01,
    min_steady_s: float = 3.0,
    n_mc: int = 200,
    seed: int = 0,
    options: dict | None = None,
    method: str = "joint",
) -> Report:
    """Identify every trial of a log and fit the coefficients against speed.

    Trials are split by the ``cols.trial`` column if present (else the log is one trial), their kind
    taken from ``cols.kind`` (0 straight, 1 turn, 2 zig-zag) or detected from the inputs. Steer and
    heading/yaw rate may be given in degrees (``steer_deg``, ``heading_deg``); they are converted to
    rad, so K_r is reported in 1/s (rad/s per rad). K_v is reported per unit of the thrust column.
    """
    cols = cols or Columns()
    have = check_log(df, cols, options)
    rng = np.random.default_rng(seed)
    rep = Report()
    if cols.trial and cols.trial in df.columns:
        ids = df[cols.trial].to_numpy(float)
        groups = [(int(k), np.nonzero(ids == k)[0]) for k in dict.fromkeys(ids.tolist())]
    else:
        groups = [(0, np.arange(len(df)))]
    sd = math.pi / 180 if steer_deg else 1.0
    hd = math.pi / 180 if heading_deg else 1.0
    col = {k: df[v].to_numpy(float) for k, v in have.items()}
    tt = df[cols.time].to_numpy(float)
    kinds = df[cols.kind].to_numpy(float) if cols.kind and cols.kind in df.columns else None
    for tid, idx in groups:
        t = tt[idx]
        steer = col["steer"][idx] * sd if "steer" in col else None
        thrust = col["thrust"][idx] if "thrust" in col else None
        kind = KIND_CODES.get(int(kinds[idx[0]]), "none") if kinds is not None else _classify(steer, thrust)
        spd = col["speed"][idx] if "speed" in col else None
        if kind == "straight":
            if thrust is None or spd is None:
                raise InputError(f"trial {tid} (straight) needs the thrust and speed columns")
            rep.steps.append(
                identify_step(
                    t,
                    thrust,
                    spd,
                    kind="straight",
                    trial=tid,
                    points=points,
                    settle_tol=settle_tol,
                    min_steady_s=min_steady_s,
                    n_mc=n_mc,
                    rng=rng,
                    out_name="speed",
                    method=method,
                )
            )
        elif kind in ("turn", "zigzag"):
            psi = np.unwrap(col["heading"][idx] * hd) if "heading" in col else None
            r = col["yaw_rate"][idx] * hd if "yaw_rate" in col else None
            if r is None:
                r = np.gradient(psi, t)
            if kind == "turn":
                rep.steps.append(
                    identify_step(
                        t,
                        steer,
                        r,
                        Y=psi,
                        Y_measured=psi is not None,
                        kind="turn",
                        trial=tid,
                        speed=spd,
                        points=points,
                        settle_tol=settle_tol,
                        min_steady_s=min_steady_s,
                        n_mc=n_mc,
                        rng=rng,
                        out_name="yaw rate",
                        method=method,
                    )
                )
            else:
                if psi is None:
                    psi = np.concatenate([[0.0], np.cumsum(0.5 * np.diff(t) * (r[1:] + r[:-1]))])
                r0 = float(np.mean(r[:3]))
                rep.zigzags.append(
                    fit_nomoto_zigzag(
                        t, steer, psi, r0=r0, trial=tid, speed=float(np.mean(spd)) if spd is not None else float("nan")
                    )
                )
        else:
            raise InputError(f"trial {tid}: neither the steer nor the thrust changes; nothing to identify")
    for kind, names in (("straight", ("K_v", "T_v")), ("turn", ("K_r", "T_r"))):
        st = [s for s in rep.steps if s.kind == kind]
        if len({round(s.speed, 6) for s in st}) >= 2:
            u = [s.speed for s in st]
            rep.fits[names[0]] = fit_vs_speed(names[0], u, [s.K for s in st])
            rep.fits[names[1]] = fit_vs_speed(names[1], u, [s.T for s in st])
    rep.units = {
        "K_v": "speed unit per thrust-column unit (m/s per rpm for the first-order USV)",
        "K_r": "rad/s of yaw rate per steer-column unit (1/s with the steer in rad or --steer-deg)",
        "T_v, T_r": "s",
        "speed": "m/s",
    }
    return rep
