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

Every fit is then checked (:mod:`oceangnc.identification.first_order_checks`): a time constant at its
bound, a near-singular information matrix, a poor fit or residuals that are not white are failures,
listed in ``Report.failures``; ``oceangnc identify first-order`` refuses such a log (exit 2).
"""

from __future__ import annotations

import math

import numpy as np

from ..errors import InputError
from .first_order_checks import judge
from .first_order_results import Columns, LinearFit, Report, StepFit, ZigzagFit
from .integral_method import _trapz_cum, detect_points, fit_vs_speed, identify_step, integral_estimate, noise_std
from .nomoto_zigzag import fit_nomoto_zigzag

__all__ = [
    "KIND_CODES",
    "Columns",
    "LinearFit",
    "Report",
    "StepFit",
    "ZigzagFit",
    "check_log",
    "trim_nan_edges",
    "detect_points",
    "fit_nomoto_zigzag",
    "fit_vs_speed",
    "identify_log",
    "identify_step",
    "integral_estimate",
    "noise_std",
]

KIND_CODES = {0: "straight", 1: "turn", 2: "zigzag"}


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
            hint = ""
            if c != cols.time:
                a, b = _longest_finite(df[used].to_numpy(float))
                if b > a and np.isfinite(t[a]) and np.isfinite(t[b]):
                    hint = (
                        f"; the longest stretch without NaN is {t[a]:.2f}-{t[b]:.2f} s "
                        f"(--start {t[a]:.2f} --end {t[b]:.2f})"
                    )
            raise InputError(f"column '{c}' has {int(bad.sum())} NaN/inf value(s), first at {where}{hint}")
    dt = np.diff(t)
    if np.any(dt <= 0):
        i = int(np.argmax(dt <= 0)) + 1
        raise InputError(
            f"time column '{cols.time}' is not increasing at row {i} (t={t[i - 1]:.6g} s then {t[i]:.6g} s)"
        )
    return have


def _longest_finite(a) -> tuple[int, int]:
    """First and last row of the longest run of rows finite in every column of ``a``."""
    ok = np.all(np.isfinite(a), axis=1)
    best, cur = (0, -1), None
    for i, k in enumerate(ok):
        if k:
            cur = i if cur is None else cur
            if i - cur > best[1] - best[0]:
                best = (cur, i)
        else:
            cur = None
    return best


def _used_columns(df, cols: Columns) -> list[str]:
    names = [getattr(cols, k) for k in ("steer", "thrust", "speed", "heading", "yaw_rate")]
    return [c for c in names if c in df.columns]


def trim_nan_edges(df, cols: Columns):
    """Drop the rows at the start and end of a log where a signal identification uses is NaN (not yet
    started, or stopped: typical of a field log whose streams start at different times). Returns the log
    and a note saying what was dropped (None if nothing)."""
    used = _used_columns(df, cols)
    if not used or len(df) == 0:
        return df, None
    ok = np.all(np.isfinite(df[used].to_numpy(float)), axis=1)
    if ok.all() or not ok.any():
        return df, None
    a = int(np.argmax(ok))
    b = int(len(ok) - 1 - np.argmax(ok[::-1]))
    if a == 0 and b == len(ok) - 1:
        return df, None
    t = df[cols.time].to_numpy(float) if cols.time in df.columns else np.arange(len(df), dtype=float)
    parts = []
    if a > 0:
        parts.append(f"{a} row(s) at the start (t {t[0]:.2f}-{t[a - 1]:.2f} s)")
    if b < len(ok) - 1:
        parts.append(f"{len(ok) - 1 - b} row(s) at the end (t {t[b + 1]:.2f}-{t[-1]:.2f} s)")
    nan_cols = [c for c in used if not np.isfinite(df[c].to_numpy(float)[np.r_[0:a, b + 1 : len(ok)]]).all()]
    note = f"dropped {' and '.join(parts)} where {', '.join(nan_cols)} had no value"
    return df.iloc[a : b + 1].reset_index(drop=True), note


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
    skip_checks=(),
) -> Report:
    """Identify every trial of a log and fit the coefficients against speed.

    Trials are split by the ``cols.trial`` column if present (else the log is one trial), their kind
    taken from ``cols.kind`` (0 straight, 1 turn, 2 zig-zag) or detected from the inputs. Steer and
    heading/yaw rate may be given in degrees (``steer_deg``, ``heading_deg``); they are converted to
    rad, so K_r is reported in 1/s (rad/s per rad). K_v is reported per unit of the thrust column.
    Every fit is checked (:mod:`.first_order_checks`: bound, condition, fit, whiteness); the failures are
    listed in ``Report.failures`` (``skip_checks`` marks those of the named checks as skipped).
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
    # the options of every step trial
    opts = dict(points=points, settle_tol=settle_tol, min_steady_s=min_steady_s, n_mc=n_mc, rng=rng, method=method)
    for tid, idx in groups:
        t = tt[idx]
        steer = col["steer"][idx] * sd if "steer" in col else None
        thrust = col["thrust"][idx] if "thrust" in col else None
        kind = KIND_CODES.get(int(kinds[idx[0]]), "none") if kinds is not None else _classify(steer, thrust)
        spd = col["speed"][idx] if "speed" in col else None
        if kind == "straight":
            if thrust is None or spd is None:
                raise InputError(f"trial {tid} (straight) needs the thrust and speed columns")
            rep.steps.append(identify_step(t, thrust, spd, kind="straight", trial=tid, out_name="speed", **opts))
        elif kind in ("turn", "zigzag"):
            psi = np.unwrap(col["heading"][idx] * hd) if "heading" in col else None
            r = col["yaw_rate"][idx] * hd if "yaw_rate" in col else None
            if r is None:
                r = np.gradient(psi, t)
            if kind == "turn":
                turn = dict(Y=psi, Y_measured=psi is not None, kind="turn", trial=tid, speed=spd, out_name="yaw rate")
                rep.steps.append(identify_step(t, steer, r, **turn, **opts))
            else:
                if psi is None:
                    psi = _trapz_cum(t, r)
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
    every = sorted(rep.steps + rep.zigzags, key=lambda s: s.trial)
    fits = [(f"trial {s.trial} ({getattr(s, 'kind', 'zigzag')})", s.checks) for s in every]
    rep.failures = judge(fits, skip=skip_checks)
    rep.units = {
        "K_v": "speed unit per thrust-column unit (m/s per rpm for the first-order USV)",
        "K_r": "rad/s of yaw rate per steer-column unit (1/s with the steer in rad or --steer-deg)",
        "T_v, T_r": "s",
        "speed": "m/s",
    }
    return rep
