"""Summary and plots in forked helpers (oceangnc.postproc): the same files and summary as in-process,
no pandas/matplotlib in the parent, and a failing helper falls back to in-process work."""

from __future__ import annotations

import json
import os
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

from oceangnc.io.logs import LogWriter, read_log

SRC = Path(__file__).resolve().parents[1] / "src"
PLOTS = {"trajectory3d.png", "track.png", "speeds.png", "thrusts.png", "headings.png", "depth_distance.png"}

pytestmark = pytest.mark.skipif(not sys.platform.startswith("linux"), reason="the helpers fork (Linux only)")


def _cli(out: Path, mode: str, prelude: str = "", scenario: str = "combined-survey") -> list:
    """``oceangnc run SCENARIO`` through ``cli.main`` in a new process: (summary, files, heavy
    modules imported by the parent)."""
    code = (
        "import sys, json\n" + prelude + "from oceangnc.cli import main\n"
        f"rc = main(['run', {scenario!r}, '--duration', '2', '--quiet', '--out', {str(out)!r}])\n"
        "print(json.dumps([rc, [m in sys.modules for m in ('pandas', 'matplotlib')]]))\n"
    )
    env = dict(os.environ, PYTHONPATH=str(SRC), OCEANGNC_POSTPROC=mode)
    r = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, env=env, timeout=600)
    assert r.returncode == 0, r.stderr
    rc, heavy = json.loads(r.stdout.strip().splitlines()[-1])
    assert rc == 0
    summary = json.loads((out / "summary.json").read_text())
    summary.pop("wall_time_s")
    summary.pop("wall_time_start_unix_s", None)
    return summary, {p.name: p.stat().st_size for p in out.glob("*.png")}, heavy


def test_forked_summary_and_plots_equal_the_in_process_ones(tmp_path):
    """The flagship: its drawer forked first thing (light plot module, plain config, columns)."""
    s_fork, png_fork, heavy_fork = _cli(tmp_path / "fork", "fork")
    s_inl, png_inl, heavy_inl = _cli(tmp_path / "inline", "inline")
    assert s_fork == s_inl and s_fork["status"] == "ok"
    assert set(png_fork) == set(png_inl) == PLOTS
    assert png_fork == png_inl  # byte sizes equal (tests/test_frame.py compares the bytes)
    assert all(size > 10_000 for size in png_fork.values())  # drawn PNGs, not empty files
    assert heavy_fork == [False, False]  # the parent never imported pandas or matplotlib
    assert heavy_inl == [False, True]  # its summary and plots read columns: no pandas even in-process


def test_the_classic_helper_of_a_pandas_scenario_equals_in_process_work(tmp_path):
    """A scenario without a light plot module: the helper forked after the first imports, with pandas."""
    s_fork, png_fork, heavy_fork = _cli(tmp_path / "fork", "fork", scenario="berthing-dock")
    s_inl, png_inl, heavy_inl = _cli(tmp_path / "inline", "inline", scenario="berthing-dock")
    assert s_fork == s_inl and s_fork["status"] == "ok"
    assert png_fork and png_fork == png_inl
    assert heavy_fork == [False, False] and heavy_inl == [True, True]


def test_a_failing_helper_falls_back_to_in_process_work(tmp_path):
    prelude = (
        "import os\n"
        "import oceangnc.scenarios._combined_plots as light\n"
        "parent = os.getpid(); real = light.plot_jobs\n"
        "def jobs(name, df, cfg, out_dir):  # breaks in the drawers only\n"
        "    if os.getpid() != parent: raise RuntimeError('drawer failure')\n"
        "    return real(name, df, cfg, out_dir)\n"
        "light.plot_jobs = jobs\n"
    )
    summary, pngs, heavy = _cli(tmp_path, "fork", prelude)
    assert summary["status"] == "ok" and set(pngs) == PLOTS
    assert heavy == [False, True]  # the parent drew them itself


def test_log_blocks_and_rows_mix_in_order(tmp_path):
    """append_rows (the fused clock's blocks) and append (the Python clock's rows) in one log."""
    names = ["a", "b"]
    w = LogWriter(tmp_path / "log.parquet", flush_period=0.5)
    w.append(0.0, {"a": 1.0, "b": 2.0})
    t = np.arange(1, 9) * 0.1
    w.append_rows(t, ["b", "a"], np.column_stack([t * 10.0, t]))
    w.append(0.9, {"a": 5.0})  # b missing: NaN
    w.close()
    df = read_log(tmp_path / "log.parquet")
    assert list(df.columns) == ["t", *names]
    np.testing.assert_array_equal(df["t"], np.r_[0.0, t, 0.9])
    np.testing.assert_array_equal(df["a"], np.r_[1.0, t, 5.0])
    np.testing.assert_array_equal(df["b"].to_numpy()[:-1], np.r_[2.0, t * 10.0])
    assert np.isnan(df["b"].iloc[-1])
    assert w.parts == 2  # flushed at t >= 0.5 and at close, as row-by-row appends would
