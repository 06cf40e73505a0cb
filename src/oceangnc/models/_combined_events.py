"""Slack and snap events of the cable's end tensions, detected on every integration step (issue 40).

The *event block* is appended to the combined plant's parameter array at sea (its offset in the sea
block's word ``S_EV``; 0: no tracking). After every step of the plant's integrator (``imex_advance``,
``split_advance``), :func:`track_events` evaluates the top and the bottom tension at the new state
(:func:`~oceangnc.models._combined_kernels.cable_state`, the forces the published
``cable.top_tension`` / ``cable.bottom_tension`` are made of) and updates, per end:

* the largest and the smallest tension over the integration steps since ``E_T0`` (the end of the
  start-up transient): the tension maximum a verdict uses, whatever the log rate;
* a **slack phase** with hysteresis: it starts at the first step with T < T_lo and ends at the first
  step with T > T_hi > T_lo, so a tension that rattles about T_lo counts once;
* the **peak after it**: the largest tension within ``E_WIN`` s after the slack phase ends (or until
  the next slack phase starts, if sooner); the event is *recorded* (start s, duration s, peak N) when
  that window closes, and it is a **snap** when the peak exceeds T_snap;
* counts of slack phases (at their start) and of snaps, the time spent slack (s), the largest snap peak,
  and the last recorded event (start, duration, peak; 0 before the first).

The thresholds are fractions of a reference tension: the given static tension ``E_REF`` (N), or, with
``E_REF`` = 0, the mean tension over the steps in [``E_TM0``, ``E_T0``) (the project's rule: fractions
of the mean), fixed at the first step at or after ``E_T0``; ``E_LOABS`` >= 0 replaces T_lo by an
absolute value (T_hi scaled with it). Before ``E_T0`` nothing is counted.
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit

from ._combined_kernels import cable_state
from ._combined_layout import H_N, H_SEA, H_T
from ._sea_layout import S_EV

# scalar words of the event block
E_T0, E_TM0, E_REF, E_FLO, E_FHI, E_FSNAP, E_WIN, E_LOABS = 0, 1, 2, 3, 4, 5, 6, 7
E_ARMED, E_SUM, E_SUMT, E_TPREV, E_LO, E_HI, E_SNAP, E_CAP, E_NN = 8, 9, 10, 11, 12, 13, 14, 15, 16
E_SCR = 17  # 8: the end forces' scratch (cable_state's ``ends``)
E_END0 = 32  # the top end's record, then the bottom's (R_SIZE words each), the node scratch, the tables
R_SLACK, R_TSTART, R_TEND, R_PEAK, R_DUR = 0, 1, 2, 3, 4
R_NSLACK, R_NSNAP, R_TSLACK, R_TMAX, R_TMIN, R_SNAPMAX, R_LSTART, R_LDUR, R_LPEAK, R_NREC, R_NSTEP = range(5, 16)
R_SIZE = 16
R_PUBLISHED = (R_NSLACK, R_NSNAP, R_TSLACK, R_TMAX, R_TMIN, R_SNAPMAX, R_LSTART, R_LDUR, R_LPEAK)
#: published per end (leaf, record word, unit): cable.<end>_<leaf>
EVENT_OUTPUTS = (
    ("slack_events", R_NSLACK, "count"),
    ("snap_events", R_NSNAP, "count"),
    ("slack_time", R_TSLACK, "s"),
    ("tension_max", R_TMAX, "N"),
    ("tension_min", R_TMIN, "N"),
    ("snap_max", R_SNAPMAX, "N"),
    ("event_start", R_LSTART, "s"),
    ("event_duration", R_LDUR, "s"),
    ("event_peak", R_LPEAK, "N"),
)
ENDS = ("top", "bottom")


def event_block(nmax: int, t0: float, tm0: float, ref: float, f_lo: float, f_hi: float, f_snap: float,
                window: float, lo_abs: float = -1.0, capacity: int = 256) -> np.ndarray:  # fmt: skip
    """The event block (layout above) for a plant with ``nmax`` segment slots: thresholds T_lo, T_hi,
    T_snap = ``f_lo``, ``f_hi``, ``f_snap`` x the reference (``ref`` N, or 0: the mean over [tm0, t0)),
    the snap window ``window`` (s), room for ``capacity`` event records (start, duration, peak) per end."""
    size = E_END0 + 2 * R_SIZE + 3 * (nmax + 1) + 2 * 3 * capacity
    b = np.zeros(size)
    b[E_T0], b[E_TM0], b[E_REF] = t0, min(tm0, t0), ref
    b[E_FLO], b[E_FHI], b[E_FSNAP], b[E_WIN], b[E_LOABS] = f_lo, f_hi, f_snap, window, lo_abs
    b[E_CAP] = capacity
    b[E_NN] = 3 * (nmax + 1)
    reset_events(b, 0)
    return b


def reset_events(p, e: int) -> None:
    """Clear the counters and the reference of the event block at ``e`` of ``p`` (a reset of the plant)."""
    p[e + E_ARMED] = p[e + E_SUM] = p[e + E_SUMT] = 0.0
    p[e + E_TPREV] = math.nan
    for j in range(2):
        r = e + E_END0 + R_SIZE * j
        p[r : r + R_SIZE] = 0.0
        p[r + R_TEND] = -math.inf  # no window open (the published words stay finite: 0 before t0)


def event_table(p, e: int, end: int) -> np.ndarray:
    """The recorded events of end ``end`` (0 top, 1 bottom) as rows (start s, duration s, peak N)."""
    r = e + E_END0 + R_SIZE * end
    cap = int(p[e + E_CAP])
    tb = e + E_END0 + 2 * R_SIZE + int(p[e + E_NN]) + 3 * cap * end
    k = min(int(p[r + R_NREC]), cap)
    return p[tb : tb + 3 * k].reshape(k, 3).copy()


@njit(cache=True)
def _update_end(p, e, r, tb, t, dt, T):
    """One step of the slack/snap record at ``r`` (module docstring) with tension ``T`` (N) at ``t`` (s)."""
    if T > p[r + R_TMAX] or p[r + R_NSTEP] == 0.0:
        p[r + R_TMAX] = T
    if T < p[r + R_TMIN] or p[r + R_NSTEP] == 0.0:
        p[r + R_TMIN] = T
    p[r + R_NSTEP] += 1.0
    if p[r + R_SLACK] > 0.0:
        p[r + R_TSLACK] += dt
        if T > p[e + E_HI]:  # the slack phase ends: the window for the peak after it opens
            p[r + R_SLACK] = 0.0
            p[r + R_DUR] = t - p[r + R_TSTART]
            p[r + R_TEND] = t + p[e + E_WIN]
            p[r + R_PEAK] = T
        return
    if p[r + R_TEND] > -math.inf:
        inside = t <= p[r + R_TEND]
        if inside and T > p[r + R_PEAK]:
            p[r + R_PEAK] = T
        if not inside or T < p[e + E_LO]:  # the window closes: record the event
            peak = p[r + R_PEAK]
            if peak > p[e + E_SNAP]:
                p[r + R_NSNAP] += 1.0
                if peak > p[r + R_SNAPMAX]:
                    p[r + R_SNAPMAX] = peak
            p[r + R_LSTART] = p[r + R_TSTART]
            p[r + R_LDUR] = p[r + R_DUR]
            p[r + R_LPEAK] = peak
            k = int(p[r + R_NREC])
            if k < int(p[e + E_CAP]):
                p[tb + 3 * k] = p[r + R_TSTART]
                p[tb + 3 * k + 1] = p[r + R_DUR]
                p[tb + 3 * k + 2] = peak
            p[r + R_NREC] = k + 1.0
            p[r + R_TEND] = -math.inf
    if T < p[e + E_LO]:  # a slack phase starts
        p[r + R_SLACK] = 1.0
        p[r + R_TSTART] = t
        p[r + R_NSLACK] += 1.0


@njit(cache=True)
def track_events(t, x, u, p):
    """Update the event block (module docstring) with the end tensions at state ``x``, time ``t`` (s)
    after an integration step; current (m/s, NED) from ``u[2]``, ``u[3]``. Nothing without a block (the
    steppers call it behind their ``SEA`` switch: the plain plant's copies never compile it)."""
    s = int(p[H_SEA])
    if s <= 0:
        return
    e = int(p[s + S_EV])
    if e <= 0:
        return
    dt = t - p[e + E_TPREV] if p[e + E_TPREV] == p[e + E_TPREV] else 0.0
    p[e + E_TPREV] = t
    if t < p[e + E_TM0]:
        return
    n = int(p[H_N])
    nn = int(p[e + E_NN])
    ends = p[e + E_SCR : e + E_SCR + 8]
    nodes = p[e + E_END0 + 2 * R_SIZE : e + E_END0 + 2 * R_SIZE + 3 * (n + 1)]
    ends[6] = u[2]
    ends[7] = u[3]
    p[H_T] = t
    cable_state(x, p, nodes, ends)
    top = math.sqrt(ends[0] ** 2 + ends[1] ** 2 + ends[2] ** 2)
    if t < p[e + E_T0]:  # the reference window: the mean of the top tension over the steps
        p[e + E_SUM] += top * dt
        p[e + E_SUMT] += dt
        return
    if p[e + E_ARMED] == 0.0:  # the thresholds, fixed once
        ref = p[e + E_REF]
        if ref <= 0.0:
            ref = p[e + E_SUM] / p[e + E_SUMT] if p[e + E_SUMT] > 0.0 else top
        lo = p[e + E_FLO] * ref
        hi = p[e + E_FHI] * ref
        if p[e + E_LOABS] >= 0.0:
            hi = p[e + E_LOABS] * p[e + E_FHI] / max(p[e + E_FLO], 1e-12)
            lo = p[e + E_LOABS]
        p[e + E_LO] = lo
        p[e + E_HI] = hi
        p[e + E_SNAP] = p[e + E_FSNAP] * ref
        p[e + E_REF] = ref
        p[e + E_ARMED] = 1.0
    bottom = math.sqrt(ends[3] ** 2 + ends[4] ** 2 + ends[5] ** 2)
    cap = int(p[e + E_CAP])
    tb = e + E_END0 + 2 * R_SIZE + nn
    _update_end(p, e, e + E_END0, tb, t, dt, top)
    _update_end(p, e, e + E_END0 + R_SIZE, tb + 3 * cap, t, dt, bottom)


#: the published keys, in the order of :func:`attach_events`'s indices
EVENT_KEYS = tuple(f"cable.{end}_{leaf}" for end in ENDS for leaf, _, _ in EVENT_OUTPUTS)


def attach_events(p, nmax: int, events: dict):
    """``p`` with an event block (:func:`event_block` of the keyword arguments ``events``) appended and its
    offset in the sea block, and the indices in ``p`` of the published words (:data:`EVENT_KEYS`)."""
    e = p.size
    p = np.concatenate([p, event_block(nmax, **events)])
    p[int(p[H_SEA]) + S_EV] = e
    idx = [e + E_END0 + R_SIZE * j + w for j in range(2) for _, w, _ in EVENT_OUTPUTS]
    return p, np.array(idx, dtype=np.int64)


def event_units(idx) -> dict:
    """{key: unit} of the published event signals (none without tracking)."""
    if not len(idx):
        return {}
    return {f"cable.{end}_{leaf}": unit for end in ENDS for leaf, _, unit in EVENT_OUTPUTS}
