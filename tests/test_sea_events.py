"""Slack and snap events counted on every integration step (issue 40, :mod:`oceangnc.models._combined_events`).

Kinds of evidence: a case built to go slack (a top point heaving 1 m at 2 s over a 10 m cable: the UUV
cannot follow the downward accelerations, the cable goes slack once per heave cycle) gives one event
per cycle, whatever the publish rate; the same tow logged at 10, 50 and 100 Hz gives the same counts and
tension maxima (the verdict's figures do not depend on the log); the maximum over the steps bounds the
maximum over the logged rows.
"""

from __future__ import annotations

import math

import numpy as np
import pytest

from oceangnc.models._combined_events import (
    E_ARMED,
    E_END0,
    E_HI,
    E_LO,
    E_NN,
    E_SNAP,
    R_NSLACK,
    R_NSNAP,
    R_SIZE,
    R_SNAPMAX,
    R_TMAX,
    R_TMIN,
    _update_end,
    event_block,
)
from oceangnc.models.cable import CableConfig
from oceangnc.models.combined import CombinedPlant
from oceangnc.models.usv import USVConfig
from oceangnc.models.uuv import UUVConfig
from oceangnc.tension import events

EV = {"t0": 10.0, "tm0": 5.0, "ref": 0.0, "f_lo": 0.01, "f_hi": 0.05, "f_snap": 2.0, "window": 2.0}
PERIOD = 2.0


def _heaving(**kw):
    cc = CableConfig(length=10.0, segments=10, E=7.5e6, integrator="imex")
    return CombinedPlant(USVConfig(), UUVConfig(x0=0.0, z0=10.125), cc, top="fixed", events=EV, **kw)


def _run(pl, duration, tick, dt=0.01):
    bus: dict = {}
    k = int(round(tick / dt))
    t = 0.0
    rows = []
    for _ in range(int(round(duration / tick))):
        t = pl.advance(t, dt, k)
        pl.publish(bus)
        rows.append((t, bus["cable.top_tension"]))
    keys = [k for k in bus if k.startswith(("cable.top_", "cable.bottom_")) and not k.endswith("_tension")]
    return np.array(rows), {k: bus[k] for k in keys}


def test_one_event_per_slack_phase_whatever_the_publish_rate():
    """Publishing at 100, 50 and 10 Hz leaves the counts, extremes and event records unchanged; each
    heave cycle after the settle time gives one slack phase (the log-row counter at 100 Hz, without
    hysteresis, counts more), each followed by a snap; the still cable has none."""
    out = {}
    for tick in (0.01, 0.02, 0.1):
        pl = _heaving(heave="sine", heave_amplitude=1.0, heave_period=PERIOD)
        rows, ev = _run(pl, 30.0, tick)
        out[tick] = (ev, pl.events("top"), rows)
    ev, table, rows = out[0.01]
    for tick in (0.02, 0.1):
        assert out[tick][0] == ev
        np.testing.assert_array_equal(out[tick][1], table)
    cycles = (30.0 - EV["t0"]) / PERIOD
    assert abs(ev["cable.top_slack_events"] - cycles) <= 1
    assert ev["cable.top_snap_events"] >= cycles - 1
    # records: one per phase, a short slack (well under the period), the peak above twice the mean
    assert table.shape[0] >= cycles - 1
    assert np.all(np.diff(table[:, 0]) > 0.8 * PERIOD) and np.all(table[:, 1] < 0.5 * PERIOD)
    assert np.all(table[:, 2] <= ev["cable.top_tension_max"])
    after = rows[rows[:, 0] >= EV["t0"]]
    assert after[:, 1].max() <= ev["cable.top_tension_max"] + 1e-9
    assert after[:, 1].min() >= ev["cable.top_tension_min"] - 1e-9
    _, still = _run(_heaving(heave="sine", heave_amplitude=0.0, heave_period=PERIOD), 20.0, 0.1)
    assert still["cable.top_slack_events"] == 0 and still["cable.top_snap_events"] == 0
    assert still["cable.top_tension_max"] >= still["cable.top_tension_min"] > 0.0


def test_hysteresis_counts_a_rattling_slack_phase_once():
    """A tension that rattles about the slack threshold (1 N) without passing the end threshold (5 N) is
    one slack phase (the row counter without hysteresis sees three); its event is recorded with its
    start, its duration to the first step above 5 N and the peak in the 2 s after; a peak 5 s later is
    outside the window."""
    b = event_block(2, t0=0.0, tm0=0.0, ref=100.0, f_lo=0.01, f_hi=0.05, f_snap=2.0, window=2.0, capacity=4)
    b[E_LO], b[E_HI], b[E_SNAP], b[E_ARMED] = 1.0, 5.0, 200.0, 1.0
    tb = E_END0 + 2 * R_SIZE + int(b[E_NN])
    t = np.arange(0.0, 20.0, 0.1)
    T = np.full(t.size, 100.0)
    T[10:20] = [0.5, 2.0, 0.5, 3.0, 0.2, 4.0, 0.9, 6.0, 150.0, 300.0]  # slack from 1.0 s, ends at 1.7 s
    T[100:103] = 0.0  # a second phase, its peak 5 s later: no snap
    T[153] = 400.0
    for k in range(t.size):
        _update_end(b, 0, E_END0, tb, t[k], 0.1, T[k])
    r = E_END0
    assert b[r + R_NSLACK] == 2 and b[r + R_NSNAP] == 1 and b[r + R_SNAPMAX] == 300.0
    np.testing.assert_allclose(b[tb : tb + 6].reshape(2, 3), [[1.0, 0.7, 300.0], [10.0, 0.3, 100.0]])
    assert b[r + R_TMAX] == 400.0 and b[r + R_TMIN] == 0.0
    assert events(t, T, 1.0, 200.0, 2.0)["slack_events"] == 5


def test_tow_sea_state_log_rate_changes_no_count_or_maximum(tmp_path):
    """tow-sea-state in a steep sea logged at 10, 50 and 100 Hz: the same tension maxima and event counts
    in the summary (taken on every step), each at least the maximum over its own logged rows."""
    import oceangnc

    over = {"analysis.settle_s": 10.0, "environment.waves.hs": 1.6, "environment.waves.tp": 4.0}
    res = {}
    for rate in (10.0, 50.0, 100.0):
        over["sim.log_rate"] = rate
        res[rate] = oceangnc.run("tow-sea-state", duration=30.0, plots=False, overrides=over, out=tmp_path / f"{rate}")
    keys = [
        f"cable.{end}_{k}"
        for end in ("top", "bottom")
        for k in ("max_N", "min_N", "slack_events", "snap_events", "snap_max_N", "slack_time_s")
    ]
    ref = {k: res[10.0].summary[k] for k in keys}
    assert res[10.0].summary["analysis.events_in_step"] == 1
    for rate, r in res.items():
        assert {k: r.summary[k] for k in keys} == ref, rate
        w = r.df[r.df["t"] >= 10.0]
        assert w["cable.top_tension"].max() <= ref["cable.top_max_N"] + 1e-9
    assert res[100.0].df["cable.top_tension"].size > 5 * res[10.0].df["cable.top_tension"].size


def test_named_criteria_and_per_cable_load_limits(tmp_path):
    """One tow summarised under each criterion: static-fraction fails when the least tension is below the
    fraction of the static tension and passes below it; the load limit is the SWL, or the MBL over its
    factor, when chosen; a load limit without its value is refused naming the key."""
    import oceangnc
    from oceangnc.errors import ConfigError
    from oceangnc.io.config import validate
    from oceangnc.scenarios.sea_state import SeaLimits, sea_summary, static_tension

    r = oceangnc.run("tow-sea-state", duration=20.0, plots=False, overrides={"analysis.settle_s": 10.0}, out=tmp_path)
    cfg, df, s = r.config, r.df, r.summary
    static = static_tension(cfg)
    assert static == s["cable.static_tension_N"] > 0.0
    least = min(s["cable.top_min_N"], s["cable.bottom_min_N"])

    def summary(**lim):
        c = cfg.model_copy(update={"limits": cfg.limits.model_copy(update=lim)})
        return sea_summary(df, c)

    assert summary(criterion="static-fraction", min_tension_fraction=0.9 * least / static)["limits.no_snap"] == 1
    assert summary(criterion="static-fraction", min_tension_fraction=min(1.0, 1.1 * least / static))[
        "limits.no_snap"
    ] == int(least >= static)
    top = s["cable.top_max_N"]
    assert summary(load_limit="swl", swl_N=1.01 * top)["limits.tension_ok"] == 1
    assert summary(load_limit="swl", swl_N=0.99 * top)["limits.tension_ok"] == 0
    low = summary(load_limit="mbl", mbl_N=3.0 * top, mbl_factor=3.3)
    assert low["limits.tension_ok"] == 0 and low["sea.pass"] == 0
    assert math.isclose(low["limits.tension_limit_N"], 3.0 * top / 3.3)
    with pytest.raises(ConfigError, match="limits.swl_N"):
        validate(SeaLimits, {"load_limit": "swl"})


def test_the_plain_rk4_stepper_publishes_no_event_counters():
    """The core RK4 stepper does not call the tracker: such a plant carries no event block and publishes
    no counters, so its summary falls back to the logged rows instead of reading zeros."""
    cc = CableConfig(length=10.0, segments=10, E=7.5e6, integrator="rk4")
    pl = CombinedPlant(
        USVConfig(), UUVConfig(x0=0.0, z0=10.125), cc, top="fixed", events=EV, heave="sine", heave_period=PERIOD
    )
    assert pl.events("top").shape == (0, 3)
    assert not any(k.endswith("_tension_max") for k in pl.output_units)
    assert _heaving(heave="sine", heave_period=PERIOD).output_units["cable.top_tension_max"] == "N"
