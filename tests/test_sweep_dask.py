"""Sweeps on dask.distributed: same results on 1 worker, 2 workers and an external cluster; kill + resume.

Every cluster here is a real ``dask.distributed`` scheduler with worker processes on 127.0.0.1. Each
worker process compiles the simulation's numba code once (a few seconds), hence ``slow``.
"""

from __future__ import annotations

import os
import signal
import subprocess
import sys
import time

import pandas as pd
import pyarrow.parquet as pq
import pytest

from oceangnc.cli import main
from oceangnc.sweep import build_design, read_results

pytest.importorskip("distributed")

# gusty wind so that the seed matters; short runs
ARGS = [
    "usv-turn-wind",
    "--grid",
    "command.thrust_stbd_kgf=10,20",
    "--grid",
    "environment.wind.direction_deg=0,90",
    "--seeds",
    "2",
    "--duration",
    "4",
    "--set",
    "environment.wind.gust_sigma=0.5",
    "--quiet",
]
VOLATILE = ["wall_time_s", "wall_time_start_unix_s", "cpu_time_s", "worker", "finished_at", "out_dir"]


def _sweep(tmp_path, name, *extra):
    out = tmp_path / name
    assert main(["sweep", *ARGS, "--out", str(out), *extra]) == 0
    return read_results(out)


def _comparable(df):
    return df.drop(columns=VOLATILE).sort_values("run_id").reset_index(drop=True)


@pytest.mark.slow
def test_same_results_on_1_and_2_workers_and_an_external_cluster(tmp_path):
    """The table (timing columns aside) is identical, run order aside, however the runs are spread."""
    from distributed import LocalCluster

    one = _sweep(tmp_path, "w1", "--workers", "1")
    two = _sweep(tmp_path, "w2", "--workers", "2")
    with LocalCluster(
        n_workers=2, threads_per_worker=1, processes=True, host="127.0.0.1", dashboard_address="127.0.0.1:0"
    ) as cluster:
        assert cluster.scheduler_address.startswith("tcp://127.0.0.1:")
        ext = _sweep(tmp_path, "ext", "--scheduler", cluster.scheduler_address)
    assert len(one) == 8 and (one["status"] == "ok").all()
    assert one["worker"].nunique() == 1
    assert two["worker"].nunique() == 2 and ext["worker"].nunique() == 2  # really spread over 2 processes
    assert os.getpid() not in {int(w.split(":")[1]) for w in pd.concat([one, two, ext])["worker"]}
    pd.testing.assert_frame_equal(_comparable(one), _comparable(two), check_exact=True)
    pd.testing.assert_frame_equal(_comparable(one), _comparable(ext), check_exact=True)
    # and the seeds did matter (otherwise identity would be trivial)
    assert one.groupby("point_id")["usv.turn_radius_m"].nunique().eq(2).all()


@pytest.mark.slow
def test_killed_sweep_resumes_with_no_run_twice_and_none_missing(tmp_path, capsys):
    """SIGKILL the sweep (driver and workers) after a few runs; --resume runs exactly the rest."""
    out = tmp_path / "killed"
    args = [
        "usv-turn-wind",
        "--grid",
        "command.thrust_stbd_kgf=8,10,12,14,16,18,20,22",
        "--seeds",
        "2",
        "--duration",
        "30",
        "--set",
        "environment.wind.gust_sigma=0.5",
        "--quiet",
        "--out",
        str(out),
    ]
    env = {**os.environ, "NUMBA_NUM_THREADS": "1"}
    proc = subprocess.Popen(
        [sys.executable, "-m", "oceangnc.cli", "sweep", *args, "--workers", "1"],
        stdout=subprocess.DEVNULL,
        stderr=subprocess.DEVNULL,
        env=env,
        start_new_session=True,
    )
    table = out / "results.parquet"
    deadline = time.monotonic() + 120
    n_before = 0
    try:
        while time.monotonic() < deadline and proc.poll() is None:
            if table.exists():
                n_before = pq.read_metadata(table).num_rows
                if n_before >= 3:
                    break
            time.sleep(0.02)
    finally:
        os.killpg(proc.pid, signal.SIGKILL)
        proc.wait(30)
    assert proc.returncode == -signal.SIGKILL, "the sweep finished before it could be killed"
    before = read_results(out)
    total = 16
    assert 3 <= len(before) < total
    assert main(["sweep", *args, "--workers", "1", "--resume"]) == 0
    printed = capsys.readouterr().out
    after = read_results(out)
    design = build_design(
        "usv-turn-wind",
        grid=["command.thrust_stbd_kgf=8,10,12,14,16,18,20,22"],
        seeds=2,
        duration=30.0,
        overrides={"environment.wind.gust_sigma": 0.5},
    )
    expected = [r.run_id for r in design.runs()]
    assert sorted(after["run_id"]) == sorted(expected)  # none missing, none extra
    assert after["run_id"].is_unique  # no run recorded twice
    assert (after["status"] == "ok").all()
    assert f"{total - len(before)} run(s) done now, {len(before)} already in the table" in printed
    # the runs finished before the kill were not run again: their rows are untouched
    kept = after.set_index("run_id").loc[before["run_id"], ["finished_at", "worker"]]
    assert list(kept["finished_at"]) == list(before["finished_at"]) and list(kept["worker"]) == list(before["worker"])
    new = after[~after["run_id"].isin(before["run_id"])]
    assert not set(new["worker"]) & set(before["worker"])
    assert not (out / "results.parquet.tmp").exists()
