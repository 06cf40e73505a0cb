"""run_batch (issue 19): K runs in one compiled prange call give the results of the same runs made alone."""

from __future__ import annotations

import json

import numpy as np
import pytest

import oceangnc
from oceangnc.io.logs import read_log


@pytest.mark.slow
def test_batch_results_equal_one_by_one_runs(tmp_path):
    rng = np.random.default_rng(7)
    over = [
        {
            "environment.current.speed": float(rng.uniform(0.0, 0.3)),
            "environment.current.direction_deg": float(rng.uniform(0.0, 360.0)),
            "usv.x0": float(rng.uniform(-1.0, 1.0)),
            "usv.y0": float(rng.uniform(-1.0, 1.0)),
        }
        for _ in range(3)
    ]
    seeds = [11, 12, 13]
    summaries = oceangnc.run_batch("combined-survey", over, seeds=seeds, duration=3.0, out=tmp_path / "b", chunk=2)
    assert [s["status"] for s in summaries] == ["ok"] * 3
    starts = set()
    for i in range(3):
        d = tmp_path / "b" / f"run-{i:05d}"
        assert json.loads((d / "summary.json").read_text()) == summaries[i]
        r = oceangnc.run(
            "combined-survey",
            overrides={**over[i], "sim.seed": seeds[i]},
            duration=3.0,
            out=tmp_path / f"one{i}",
            plots=False,
        )
        a, b = read_log(d), read_log(r.out_dir)
        assert list(a.columns) == list(b.columns) and len(a) == len(b) == 31
        np.testing.assert_array_equal(a.to_numpy(), b.to_numpy())
        assert {k: v for k, v in summaries[i].items() if not k.startswith("wall_time")} == {
            k: v for k, v in r.summary.items() if not k.startswith("wall_time")
        }
        starts.add(round(float(a["usv.x"].iloc[0]), 6))
    assert len(starts) == 3  # the runs really differ


def test_batch_of_a_scenario_without_fused_path_runs_one_by_one(tmp_path):
    s = oceangnc.run_batch("autopilot-speed", [{}, {"speed_control.wn": 1.5}], duration=2.0, out=tmp_path / "b")
    assert [x["status"] for x in s] == ["ok", "ok"]
    r = oceangnc.run(
        "autopilot-speed", overrides={"speed_control.wn": 1.5}, duration=2.0, out=tmp_path / "one", plots=False
    )
    np.testing.assert_array_equal(read_log(tmp_path / "b" / "run-00001").to_numpy(), read_log(r.out_dir).to_numpy())


def test_sweep_with_batch_records_the_same_rows_as_without(tmp_path):
    from oceangnc.sweep import build_design
    from oceangnc.sweep.execute import run_sweep

    design = build_design("usv-turn", grid={"command.thrust_stbd_kgf": [10.0, 20.0]}, seeds=2, duration=5.0)
    one = run_sweep(design, tmp_path / "one", workers=0, progress=False)
    bat = run_sweep(design, tmp_path / "bat", workers=0, progress=False, batch=3)
    a = one.table.sort_values("run_id").reset_index(drop=True)
    b = bat.table.sort_values("run_id").reset_index(drop=True)
    assert list(a["status"]) == list(b["status"]) == ["ok"] * 4
    metrics = [c for c in a.columns if c.startswith("usv.")]
    assert metrics
    for c in metrics:
        np.testing.assert_array_equal(a[c].to_numpy(), b[c].to_numpy())


@pytest.mark.slow
def test_batch_shared_among_processes_equals_the_batch_in_one_process(tmp_path):
    """workers=2 (spawned processes, issue 19's scaling with the cores) writes the same logs and summaries."""
    over = [{"usv.x0": 0.3 * i, "environment.current.speed": 0.05 * i} for i in range(4)]
    one = oceangnc.run_batch("combined-survey", over, seeds=[1, 2, 3, 4], duration=2.0, out=tmp_path / "w1", workers=1)
    two = oceangnc.run_batch("combined-survey", over, seeds=[1, 2, 3, 4], duration=2.0, out=tmp_path / "w2", workers=2)
    strip = [{k: v for k, v in s.items() if not k.startswith("wall_time")} for s in (*one, *two)]
    assert strip[:4] == strip[4:] and all(s["status"] == "ok" for s in two)
    for i in range(4):
        a, b = read_log(tmp_path / "w1" / f"run-{i:05d}"), read_log(tmp_path / "w2" / f"run-{i:05d}")
        np.testing.assert_array_equal(a.to_numpy(), b.to_numpy())
    assert read_log(tmp_path / "w2" / "run-00003")["usv.x"].iloc[0] == pytest.approx(0.9)


def test_batch_rejects_zero_workers(tmp_path):
    with pytest.raises(ValueError, match="workers must be >= 1, got 0"):
        oceangnc.run_batch("combined-survey", [{}], duration=1.0, out=tmp_path / "b", workers=0)
