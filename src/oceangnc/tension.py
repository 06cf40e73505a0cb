"""Tension statistics, slack and snap events, motion statistics and spectra of a tow's log (issue 29).

All vectorised numpy over the logged rows (no Python loop per row).

**Slack event**: a run of consecutive rows with the tension T below the slack threshold T_s
(``slack``, N; default ``slack_fraction`` x the mean tension, 1 %): the cable has gone (nearly) slack.
**Snap event**: a slack event after whose end (the first row back above T_s) the tension exceeds
``snap_factor`` x the mean (default 2) within ``snap_window`` s (default 2 s): the jerk of a cable
that goes taut again (this project's rule, on logged rows and without hysteresis; the scenarios count
events on every integration step instead, :mod:`oceangnc.models._combined_events`, and name the
standard criteria as options: docs/sea-state.md). The snap force of an event is the largest tension in
its window.

**Spectra**: one-sided power spectral densities by Welch's method (Hann windows of ``nperseg`` rows,
50 % overlap, mean removed; scipy.signal.welch), in N^2/Hz for the tension, m^2/Hz for the wave
elevation.
"""

from __future__ import annotations

import math

import numpy as np


def events(t, T, threshold: float, snap_level: float, snap_window: float) -> dict:
    """Slack and snap events of the tension series ``T`` (N) at times ``t`` (s): counts, the time spent
    slack (s) and the largest snap tension (N, 0 without a snap). Definitions in the module docstring."""
    t = np.asarray(t, dtype=float)
    T = np.asarray(T, dtype=float)
    n = T.size
    if n == 0:
        return {"slack_events": 0, "slack_time_s": 0.0, "snap_events": 0, "snap_max_N": 0.0}
    slack = T < threshold
    edge = np.diff(slack.astype(np.int8), prepend=np.int8(0), append=np.int8(0))
    starts = np.flatnonzero(edge == 1)  # first slack row of each run
    ends = np.flatnonzero(edge == -1)  # first row back above the threshold (n: still slack at the end)
    dt_row = np.diff(t, append=t[-1] if n < 2 else 2 * t[-1] - t[-2])
    slack_time = float(np.sum(dt_row[slack]))
    above = T > snap_level
    idx = np.where(above, np.arange(n), n)
    nxt = np.minimum.accumulate(idx[::-1])[::-1]  # the next row at or after i above the snap level
    nxt = np.append(nxt, n)
    j = nxt[ends]
    ok = j < n
    snap = np.zeros(ends.size, dtype=bool)
    snap[ok] = t[j[ok]] - t[np.minimum(ends[ok], n - 1)] <= snap_window
    snap_max = 0.0
    if np.any(snap):
        # the largest tension within the window after each snapping event
        e = ends[snap]
        hi = np.searchsorted(t, t[e] + snap_window, side="right")
        cover = np.zeros(n + 1, dtype=np.int64)
        np.add.at(cover, e, 1)
        np.add.at(cover, hi, -1)
        snap_max = float(np.max(T[np.cumsum(cover)[:n] > 0]))
    return {
        "slack_events": int(starts.size),
        "slack_time_s": slack_time,
        "snap_events": int(np.sum(snap)),
        "snap_max_N": snap_max,
    }


def tension_statistics(
    t,
    T,
    slack: float | None = None,
    slack_fraction: float = 0.01,
    snap_factor: float = 2.0,
    snap_window: float = 2.0,
) -> dict:
    """Mean, standard deviation, maximum and minimum of the tension ``T`` (N) and its slack and snap
    events (:func:`events`), as ``{"mean_N", "std_N", "max_N", "min_N", "slack_threshold_N",
    "slack_events", "slack_time_s", "snap_events", "snap_max_N"}``."""
    T = np.asarray(T, dtype=float)
    if T.size == 0:
        nan = float("nan")
        empty = {"mean_N": nan, "std_N": nan, "max_N": nan, "min_N": nan, "slack_threshold_N": nan}
        return {**empty, **events([], [], 0, 0, 0)}
    mean = float(np.mean(T))
    thr = float(slack) if slack is not None else slack_fraction * mean
    out = {
        "mean_N": mean,
        "std_N": float(np.std(T)),
        "max_N": float(np.max(T)),
        "min_N": float(np.min(T)),
        "slack_threshold_N": thr,
    }
    out.update(events(t, T, thr, snap_factor * mean, snap_window))
    return out


#: motion columns whose standard deviation is reported, (column, key, scale): the USV's heave, roll and
#: pitch are read where logged (issue 29 part B adds them)
MOTIONS = (
    ("uuv.z", "uuv.depth_std_m", 1.0),
    ("uuv.theta", "uuv.pitch_std_deg", 180.0 / math.pi),
    ("uuv.phi", "uuv.roll_std_deg", 180.0 / math.pi),
    ("usv.z", "usv.heave_std_m", 1.0),
    ("usv.phi", "usv.roll_std_deg", 180.0 / math.pi),
    ("usv.theta", "usv.pitch_std_deg", 180.0 / math.pi),
)


def motion_statistics(df) -> dict:
    """Standard deviations of the logged motions of :data:`MOTIONS` (columns absent are skipped)."""
    return {key: float(np.std(df[col].to_numpy()) * s) for col, key, s in MOTIONS if col in df}


def spectrum(x, fs: float, nperseg: int | None = None):
    """(f (Hz), one-sided PSD (units^2/Hz)) of the series ``x`` sampled at ``fs`` (Hz), Welch's method
    (Hann, 50 % overlap, mean removed); ``nperseg`` default: the largest power of two <= len / 4, at least 16."""
    from scipy.signal import welch

    x = np.asarray(x, dtype=float)
    if nperseg is None:
        nperseg = max(16, 2 ** int(math.log2(max(16, x.size // 4))))
    nperseg = min(nperseg, x.size)
    return welch(x, fs=fs, nperseg=nperseg, detrend="constant")
