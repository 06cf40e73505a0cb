"""Verdicts with confidence (issue 40, :mod:`oceangnc.sweep.extremes`): the Gumbel estimate of the most
probable maximum from the seeds' maxima, its interval, and pass / fail / marginal.

Kinds of evidence: Monte Carlo (the interval's coverage of the true mode of a known Gumbel
distribution; max-stability of the exposure scaling); constructed sweeps (a cell below, above and
straddling the limit; a second draw of the seeds flips no verdict outside the marginal cells).
"""

from __future__ import annotations

import math

import numpy as np
import pandas as pd

from oceangnc.sweep.extremes import cell_verdict, gumbel_mpm, tension_verdict
from oceangnc.sweep.operability import operability, operability_table

U, B = 600.0, 20.0  # N: the true mode and scale of the seeds' maxima


def test_interval_covers_the_true_mode_at_its_level():
    """Over 4000 sweeps of 8 seeds the 90 % interval holds the true mode u in 85-95 % of them, the estimate
    is unbiased to 5 % of b, and an exposure three windows long moves the MPM by b ln 3."""
    rng = np.random.default_rng(40)
    x = rng.gumbel(U, B, size=(4000, 8))
    est = np.array([gumbel_mpm(r, 1200.0) for r in x])
    cover = np.mean((est[:, 1] <= U) & (U <= est[:, 2]))
    assert 0.85 <= cover <= 0.95, cover
    assert abs(np.mean(est[:, 0]) - U) < 0.05 * B
    mpm3 = gumbel_mpm(x[0], 1200.0, exposure_s=3600.0)
    assert math.isclose(mpm3[0] - est[0, 0], est[0, 3] * math.log(3.0), rel_tol=1e-9)
    one = gumbel_mpm([612.0], 1200.0)
    assert one[0] == 612.0 and math.isnan(one[1])


def test_verdicts_pass_fail_marginal():
    assert tension_verdict(500.0, 480.0, 520.0, 600.0) == "pass"
    assert tension_verdict(700.0, 680.0, 720.0, 600.0) == "fail"
    assert tension_verdict(600.0, 580.0, 620.0, 600.0) == "marginal"
    assert tension_verdict(610.0, math.nan, math.nan, 600.0) == "fail"
    assert cell_verdict("pass", 1.0) == "pass" and cell_verdict("pass", 0.5) == "marginal"
    assert cell_verdict("marginal", 1.0) == "marginal" and cell_verdict("pass", 0.0) == "fail"


def _sweep(rng, modes, seeds=8):
    rows = []
    for hs, u in modes.items():
        for _ in range(seeds):
            rows.append(
                {
                    "param.environment.waves.hs": hs,
                    "param.environment.waves.tp": 6.0,
                    "param.environment.waves.direction_deg": 0.0,
                    "status": "ok",
                    "cable.top_max_N": float(rng.gumbel(u, B)),
                    "analysis.window_s": 1200.0,
                    "limits.tension_limit_N": 600.0,
                    "limits.tension_ok": 1,  # the per-run flags are not what decides the tension verdict
                    "limits.no_snap": 1,
                    "limits.depth_std_ok": 1,
                    "limits.pitch_std_ok": 1,
                    "sea.pass": 1,
                }
            )
    return pd.DataFrame(rows)


def test_operability_table_holds_the_estimate_and_other_seeds_flip_only_marginal_cells(tmp_path):
    """Modes from 480 to 720 N about a 600 N limit: the cells far below pass, far above fail, near the limit
    are marginal; the table and the Markdown hold the estimate and its interval; a second draw of the seeds
    turns no pass into a fail or back (only cells marked marginal in a draw may change)."""
    modes = {hs: u for hs, u in zip(np.arange(0.25, 3.3, 0.25), np.linspace(480.0, 720.0, 13))}
    rng = np.random.default_rng(7)
    t1, *_ = operability_table(_sweep(rng, modes))
    t2, *_ = operability_table(_sweep(rng, modes))
    v1, v2 = list(t1["verdict"]), list(t2["verdict"])
    assert v1[0] == v2[0] == "pass" and v1[-1] == v2[-1] == "fail"
    assert "marginal" in v1 and "marginal" in v2
    for a, b in zip(v1, v2):
        assert {a, b} != {"pass", "fail"}
    inside = (t1["tension_lo_N"] <= t1["tension_mpm_N"]) & (t1["tension_mpm_N"] <= t1["tension_hi_N"])
    assert inside.all()
    files = operability(_sweep(rng, modes), tmp_path, plots=True)
    md = files[1].read_text()
    assert "marginal T" in md and " [" in md
    csv = pd.read_csv(files[0])
    assert {"tension_mpm_N", "tension_lo_N", "tension_hi_N", "verdict"} <= set(csv.columns)


def test_a_cell_outside_the_linear_model_is_never_pass(tmp_path):
    """A sea state whose runs pass every limit but left the model (sea.in_model = 0) is drawn and tabled
    "outside model"; its neighbour inside the model passes."""
    df = _sweep(np.random.default_rng(3), {0.5: 480.0, 2.0: 480.0})
    df["sea.in_model"] = np.where(df["param.environment.waves.hs"] > 1.0, 0, 1)
    files = operability(df, tmp_path, plots=True)
    t = pd.read_csv(files[0])
    assert list(t["verdict"]) == ["pass", "outside model"]
    assert "| 2 m | outside model |" in files[1].read_text()


def test_usv_pitch_beyond_the_linear_range_is_flagged(tmp_path):
    """tow-sea-state in steep head seas (Hs 1.6 m, Tp 4 s, just inside DNV-RP-C205's steepness limit that
    refuses the issue's Hs 2 m: the USV pitches about 11 deg std) is outside the model (pitch amplitude above
    10 deg); a long low swell is inside."""
    import oceangnc

    base = {"analysis.settle_s": 10.0, "environment.waves.direction_deg": 180.0}
    steep = {**base, "environment.waves.hs": 1.6, "environment.waves.tp": 4.0}
    s = oceangnc.run("tow-sea-state", duration=30.0, plots=False, overrides=steep, out=tmp_path / "a").summary
    assert s["validity.usv_angle_amplitude_deg"] > 10.0 and s["validity.usv_angles_ok"] == 0
    assert s["sea.in_model"] == 0
    swell = {**base, "environment.waves.hs": 0.5, "environment.waves.tp": 8.0}
    s = oceangnc.run("tow-sea-state", duration=30.0, plots=False, overrides=swell, out=tmp_path / "b").summary
    assert s["validity.usv_angles_ok"] == 1 and s["validity.relative_motion_ok"] == 1
    assert s["validity.cable_wet_ok"] == 1 and s["sea.in_model"] == 1
