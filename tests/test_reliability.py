"""Crash safety of run logs, checkpoints and resume, and the first-hour CLI errors (issue 20).

See docs/reliability.md for the guarantees these tests check.
"""

import json
import os
import random
import signal
import subprocess
import sys
import time
from pathlib import Path

import numpy as np
import pandas as pd
import pyarrow.parquet as pq
import pytest

import oceangnc
from oceangnc import api
from oceangnc.errors import ConfigError, InputError
from oceangnc.io import logs
from oceangnc.io.logs import LogWriter, list_parts, read_log, repair_log

ENV = {**os.environ, "PYTHONPATH": str(Path(__file__).resolve().parents[1] / "src")}


def cli(*args, **kw):
    return subprocess.run(
        [sys.executable, "-m", "oceangnc.cli", *args],
        capture_output=True,
        text=True,
        timeout=300,
        env=ENV,
        check=False,
        **kw,
    )


def main_cli(capsys, *args):
    """The CLI entry point in-process (no interpreter start-up): (exit code, stdout, stderr)."""
    from oceangnc.cli import main

    rc = main(list(args))
    out = capsys.readouterr()
    return rc, out.out, out.err


def _foreground_signals():
    """In the child: SIGINT as in a foreground terminal. A shell's background job ignores SIGINT and
    passes that on to everything it starts (pytest included), where Ctrl-C could not be tested."""
    signal.signal(signal.SIGINT, signal.SIG_DFL)


def start(*args):
    return subprocess.Popen(
        [sys.executable, "-m", "oceangnc.cli", *args],
        stdout=subprocess.PIPE,
        stderr=subprocess.PIPE,
        text=True,
        env=ENV,
        preexec_fn=_foreground_signals,
    )


def wait_for(pred, timeout=120.0):
    t0 = time.monotonic()
    while time.monotonic() - t0 < timeout:
        if pred():
            return True
        time.sleep(0.01)
    return False


# -- the log layout ---------------------------------------------------------------------------------------


def test_log_parts_open_as_one_table_in_pandas_pyarrow_and_read_log(tmp_path):
    p = tmp_path / "log.parquet"
    w = LogWriter(p, flush_period=1.0, compact=False)
    for k in range(101):  # 5 s at 20 Hz
        w.append(k * 0.05, {"a.x": float(k), "a.y": -float(k)})
        if k == 30:
            assert len(list_parts(p)) == 1  # rows 0..1 s are on disk after 1 s of simulated time
    w.close()
    assert len(list_parts(p)) == 5
    for df in (read_log(p), pd.read_parquet(p), pq.read_table(p).to_pandas(), read_log(tmp_path)):
        assert list(df.columns) == ["t", "a.x", "a.y"]
        np.testing.assert_array_equal(df["a.x"].to_numpy(), np.arange(101.0))


def test_ctrl_c_while_a_part_is_written_waits_for_the_part_and_its_counters(tmp_path):
    """A SIGINT that lands inside a flush (here: while the part file is written) comes out after it, with
    the part on disk counted: close() then merges every row (before: KeyboardInterrupt between the write
    and the counters, and close() failed with 'need at least one array to concatenate')."""

    class Interrupted(LogWriter):
        def _write_part(self, table, index, row0, final_part=True):
            if not final_part and index == 1:
                signal.raise_signal(signal.SIGINT)  # Ctrl-C in the middle of the flush
            return super()._write_part(table, index, row0, final_part)

    p = tmp_path / "log.parquet"
    w = Interrupted(p, flush_period=1.0, compact=True, min_flush_wall_s=0.0)
    previous = signal.signal(signal.SIGINT, signal.default_int_handler)
    try:
        with pytest.raises(KeyboardInterrupt):
            for k in range(101):
                w.append(k * 0.05, {"a.x": float(k)})
        assert w.parts == len(list_parts(p)) == 2 and w.rows_written == sum(len(read_log(q)) for q in list_parts(p))
        w.close()
    finally:
        signal.signal(signal.SIGINT, previous)
    assert len(read_log(p)) == w.rows_written > 20


def test_a_wall_clock_floor_keeps_a_fast_run_to_few_parts_and_the_same_rows(tmp_path):
    """log.min_flush_wall_s: a run far faster than real time does not write a part per simulated second;
    once the floor has passed, the next row past the flush time flushes (same rows either way)."""
    rows = [(k * 0.05, {"x": float(k)}) for k in range(201)]  # 10 s at 20 Hz
    fast = LogWriter(tmp_path / "fast.parquet", flush_period=1.0, min_flush_wall_s=3600.0, compact=False)
    for t, r in rows:
        fast.append(t, r)
    assert not (tmp_path / "fast.parquet").exists()  # nothing due yet: less than an hour of wall time
    fast.close()
    slow = LogWriter(tmp_path / "slow.parquet", flush_period=1.0, min_flush_wall_s=0.02, compact=False)
    for t, r in rows[:30]:
        slow.append(t, r)
    assert not (tmp_path / "slow.parquet").exists()  # t = 1 s passed, 20 ms of wall time not yet
    time.sleep(0.05)
    slow.append(*rows[30])
    assert len(list_parts(tmp_path / "slow.parquet")) == 1  # the floor has passed: the next row flushes
    slow.append_rows(np.array([t for t, _ in rows[31:]]), ["x"], np.array([[r["x"]] for _, r in rows[31:]]))
    assert len(list_parts(tmp_path / "slow.parquet")) == 1  # a block right after: within the floor
    slow.close()
    for name in ("fast", "slow"):
        np.testing.assert_array_equal(read_log(tmp_path / f"{name}.parquet")["x"].to_numpy(), np.arange(201.0))


def test_the_wall_clock_floor_counts_from_the_first_row(tmp_path):
    """The wall time a run spends before its first row (building, loading cached code) does not make
    its first rows due: a fast run's rows past the flush time wait for the floor from the first row."""
    w = LogWriter(tmp_path / "l.parquet", flush_period=1.0, min_flush_wall_s=0.2, compact=False)
    time.sleep(0.3)  # the build
    w.append_rows(np.arange(0.0, 3.0, 0.5), ["x"], np.arange(6.0).reshape(6, 1))
    assert not (tmp_path / "l.parquet").exists()  # t = 1, 2 s passed, not 0.2 s of wall time since the first row
    w.close()
    np.testing.assert_array_equal(read_log(tmp_path / "l.parquet")["x"].to_numpy(), np.arange(6.0))


def test_close_compacts_into_one_file_and_a_crash_mid_compaction_is_repaired(tmp_path):
    p = tmp_path / "log.parquet"
    w = LogWriter(p, flush_period=1.0, compact=False)
    for k in range(81):
        w.append(k * 0.05, {"x": float(k)})
    w.close()
    parts = list_parts(p)
    assert len(parts) == 4
    # a crash after part 0 was replaced by the compacted file but before the old parts were removed
    import pyarrow as pa

    merged = pa.concat_tables([pq.read_table(q) for q in parts]).replace_schema_metadata(None)
    LogWriter(p)._write_part(merged, 0, 0)
    (p / ".part-000009.parquet.tmp").write_bytes(b"PAR1 half written")
    assert len(read_log(p)) == 81  # covered parts are skipped by read_log
    r = repair_log(tmp_path)
    assert r["rows"] == 81 and r["parts"] == 1
    assert set(r["removed"]) == {
        "part-000001.parquet",
        "part-000002.parquet",
        "part-000003.parquet",
        ".part-000009.parquet.tmp",
    }
    np.testing.assert_array_equal(pd.read_parquet(p)["x"].to_numpy(), np.arange(81.0))


def test_log_repair_cli_drops_a_truncated_part(tmp_path):
    p = tmp_path / "log.parquet"
    w = LogWriter(p, flush_period=1.0, compact=False)
    for k in range(61):
        w.append(k * 0.05, {"x": float(k)})
    w.close()
    last = list_parts(p)[-1]
    last.write_bytes(last.read_bytes()[:40])  # e.g. a disk that lied about a write
    r = cli("log", "repair", str(tmp_path))
    assert r.returncode == 0, r.stderr
    assert "removed 1 unreadable part; log has 41 rows in 1 part file" in r.stdout
    assert len(read_log(tmp_path)) == 41
    r = cli("log", "repair", str(tmp_path / "nowhere"))
    assert r.returncode == 2 and "log folder not found" in r.stderr and "Traceback" not in r.stderr


def test_full_disk_keeps_flushed_parts_and_is_one_line(tmp_path, monkeypatch):
    p = tmp_path / "log.parquet"
    w = LogWriter(p, flush_period=1.0)
    for k in range(21):
        w.append(k * 0.05, {"x": float(k)})
    real = logs.pq.write_table

    def full(*a, **k):
        raise OSError(28, "No space left on device")

    monkeypatch.setattr(logs.pq, "write_table", full)
    with pytest.raises(InputError) as ei:
        for k in range(21, 41):
            w.append(k * 0.05, {"x": float(k)})
    assert "No space left on device" in str(ei.value) and "21 rows flushed before are kept" in str(ei.value)
    monkeypatch.setattr(logs.pq, "write_table", real)
    assert not any(q.name.endswith(".tmp") for q in p.iterdir())
    assert len(read_log(p)) == 21


@pytest.mark.parametrize("seed", [1, 2, 3])
def test_sigkill_at_a_random_instant_keeps_every_flushed_row(tmp_path, seed):
    rnd = random.Random(seed)
    out = tmp_path / "run"
    proc = start(
        "run", "usv-turn", "--duration", "5000", "--out", str(out), "--quiet", "--no-plots", "--set", f"sim.seed={seed}"
    )
    try:
        assert wait_for(lambda: (out / "log.parquet").is_dir() and len(list_parts(out / "log.parquet")) >= 1)
        time.sleep(rnd.uniform(0.0, 1.0))
        assert proc.poll() is None, "the run ended before it could be killed"
        proc.send_signal(signal.SIGKILL)
    finally:
        proc.kill()
        proc.wait(timeout=30)
    assert proc.returncode == -signal.SIGKILL
    assert not (out / "summary.json").exists()
    parts = list_parts(out / "log.parquet")
    df = read_log(out)
    # every visible part is whole (a part is due each simulated second once log.min_flush_wall_s of
    # wall time has passed, so a run at thousands x real time writes a part per ~0.25 s of wall time)
    assert len(parts) >= 1 and len(df) > 20
    t = df["t"].to_numpy()
    np.testing.assert_allclose(np.diff(t), 0.05, atol=1e-9)
    # and the rows are exactly those of an uninterrupted run up to the last flush
    ref = oceangnc.run(
        "usv-turn", duration=float(t[-1]), out=tmp_path / "ref", plots=False, overrides={"sim.seed": seed}
    ).df
    pd.testing.assert_frame_equal(df, ref, check_exact=True)
    r = repair_log(out)
    assert r["rows"] == len(df) and r["parts"] == 1


# -- checkpoints and resume ---------------------------------------------------------------------------------


def test_resume_from_checkpoint_equals_uninterrupted_log(tmp_path, monkeypatch):
    full = oceangnc.run("usv-turn", duration=40, out=tmp_path / "full", plots=False).df
    # a run that "crashes" at its very end: the parts are not compacted and no summary is written
    orig = LogWriter.close
    monkeypatch.setattr(LogWriter, "close", lambda self: (setattr(self, "compact", False), orig(self))[1])
    res = oceangnc.run(
        "usv-turn",
        duration=40,
        out=tmp_path / "cut",
        plots=False,
        checkpoint_every=15,
        overrides={"log.min_flush_wall_s": 0.0},  # a part per simulated second, however fast the run
    )
    monkeypatch.setattr(LogWriter, "close", orig)
    assert res.summary["checkpoints"] == 2
    (tmp_path / "cut" / "summary.json").unlink()
    assert len(list_parts(tmp_path / "cut" / "log.parquet")) == 40  # the parts after t = 30 get dropped
    res2 = oceangnc.run(resume=tmp_path / "cut", plots=False)
    assert res2.summary["resumed_from_t"] == 30.0 and res2.summary["status"] == "ok"
    pd.testing.assert_frame_equal(res2.df, full, check_exact=True)
    assert (
        json.loads((tmp_path / "cut" / "summary.json").read_text())["usv.turn_radius_m"]
        == json.loads((tmp_path / "full" / "summary.json").read_text())["usv.turn_radius_m"]
    )


def test_sigkill_then_resume_gives_the_uninterrupted_log(tmp_path):
    out = tmp_path / "run"
    proc = start(
        "run",
        "usv-turn",
        "--duration",
        "300",
        "--out",
        str(out),
        "--quiet",
        "--no-plots",
        "--checkpoint-every",
        "10",
        "--set",
        "environment.current.speed=0.2",
    )
    try:
        assert wait_for(lambda: (out / "checkpoint.npz").exists() or proc.poll() is not None)
        time.sleep(random.Random(7).uniform(0.0, 0.3))
        assert proc.poll() is None, "the run ended before it could be killed"
        proc.send_signal(signal.SIGKILL)
    finally:
        proc.kill()
        proc.wait(timeout=30)
    r = cli("run", "--resume", str(out), "--quiet", "--no-plots", "--json")
    assert r.returncode == 0, r.stderr
    s = json.loads(r.stdout.strip().splitlines()[-1])
    assert s["status"] == "ok" and s["resumed_from_t"] > 0 and s["resumed_from_t"] % 10 == 0
    ref = oceangnc.run(
        "usv-turn", duration=300, out=tmp_path / "ref", plots=False, overrides={"environment.current.speed": 0.2}
    ).df
    pd.testing.assert_frame_equal(read_log(out), ref, check_exact=True)
    r = cli("run", "--resume", str(out), "--quiet")
    assert r.returncode == 2 and "nothing to resume" in r.stderr


def test_resume_errors_are_one_line(tmp_path, capsys):
    rc, _, err = main_cli(capsys, "run", "--resume", str(tmp_path / "nowhere"))
    assert rc == 2 and "run folder not found" in err
    (tmp_path / "d").mkdir()
    rc, _, err = main_cli(capsys, "run", "--resume", str(tmp_path / "d"))
    assert rc == 2 and "no checkpoint in" in err
    rc, _, err = main_cli(capsys, "run", "usv-turn", "--checkpoint-every", "-1")
    assert rc == 2 and "--checkpoint-every" in err and err.count("\n") == 1
    rc, _, err = main_cli(capsys, "run", "usv-turn", "--resume", str(tmp_path / "d"))
    assert rc == 2 and "give no scenario" in err


def test_checkpoint_holds_plants_blocks_rngs_and_clock():
    from oceangnc.core import checkpoint as ckpt

    sc, cfg = api.resolve_config("usv-turn-current", overrides={"environment.current.model": "gauss-markov"})
    sim = sc.build(cfg, np.random.default_rng(3))
    sim.run(7.0)
    blob = ckpt.capture(sim)
    x7 = sim.plants[0].x.copy()
    sim.run(5.0)
    after = dict(sim.bus)
    sim2 = sc.build(cfg, np.random.default_rng(3))
    ckpt.restore(sim2, blob)
    assert sim2.k == 7000 and sim2.t == 7.0
    np.testing.assert_array_equal(sim2.plants[0].x, x7)
    sim2.run(5.0)
    assert {k: v for k, v in sim2.bus.items() if isinstance(v, float)} == {
        k: v for k, v in after.items() if isinstance(v, float)
    }


# -- first-hour errors -----------------------------------------------------------------------------------------


def test_nan_inf_and_huge_waypoints_are_bad_input_exit_2(capsys):
    rc, _, err = main_cli(capsys, "run", "usv-remote", "--set", "guidance.waypoints=[[0,0],[nan,5]]", "--quiet")
    assert rc == 2, err
    assert "guidance.waypoints.1.0 = nan: must be finite" in err
    rc, _, err = main_cli(capsys, "run", "usv-remote", "--set", "guidance.waypoints=[[0,0],[1e308,5]]", "--quiet")
    assert rc == 2 and "must be within +-1e+07 m of the origin" in err
    assert "overflow" not in err.lower()
    rc, _, err = main_cli(capsys, "run", "usv-turn", "--set", "environment.current.speed=inf", "--quiet")
    assert rc == 2 and "environment.current.speed = inf: must be finite" in err
    assert "should be" not in err


def test_waypoint_count_message_reads_naturally():
    with pytest.raises(ConfigError) as ei:
        api.resolve_config("usv-remote", overrides={"guidance.waypoints": []})
    assert "guidance.waypoints = []: 0 item(s); allowed length 1 to 200 items" in str(ei.value)


def test_toml_given_as_scenario_points_to_config_and_plot_names_missing_folder(tmp_path, capsys):
    rc, _, err = main_cli(capsys, "run", "mine.toml")
    assert rc == 2 and "oceangnc run --config mine.toml" in err
    rc, _, err = main_cli(capsys, "plot", str(tmp_path / "nowhere"))
    assert rc == 2 and f"run folder not found: {tmp_path / 'nowhere'}" in err
    assert "config.toml" not in err


def test_sigint_writes_interrupted_summary(tmp_path):
    out = tmp_path / "run"
    proc = start("run", "usv-turn", "--duration", "5000", "--out", str(out), "--no-plots")
    try:
        assert wait_for(lambda: (out / "log.parquet").is_dir() and len(list_parts(out / "log.parquet")) >= 2)
        proc.send_signal(signal.SIGINT)
        _, err = proc.communicate(timeout=60)
    finally:
        proc.kill()
    assert proc.returncode == 130 and "Traceback" not in err and "interrupted" in err, (proc.returncode, err[-800:])
    s = json.loads((out / "summary.json").read_text())
    assert s["status"] == "interrupted" and s["rows"] == len(read_log(out)) > 40


def test_progress_bar_says_compiling_then_closes_at_100_percent_when_ended_early(capsys):
    from oceangnc.core.blocks import FunctionBlock
    from oceangnc.core.clock import Simulation

    def stop_at_3(t, bus):
        bus["a.v"] = t
        if t >= 3.0:
            bus["_stop"] = True

    sim = Simulation([], [FunctionBlock("a", 0.1, stop_at_3)], dt=0.01, log_period=0.1)
    import tqdm

    seen = []
    orig = tqdm.tqdm.__init__

    def spy(self, *a, **k):
        orig(self, *a, **k)
        seen.append((self, self.desc))

    tqdm.tqdm.__init__ = spy
    try:
        sim.run(10.0, progress=True)
    finally:
        tqdm.tqdm.__init__ = orig
    bar, desc0 = seen[0]
    assert desc0 == "compiling" and bar.desc == ""
    assert bar.n == bar.total == 3.0  # counts to where the run ended, not to the asked 10 s (issue 26)
    assert "scenario ended at t = 3.0 s" in bar.postfix


@pytest.mark.slow
def test_flagship_resume_is_bit_identical(tmp_path, monkeypatch):
    """The combined USV + cable + UUV survey (guidance, random sensors, cable plant) resumes exactly."""
    full = oceangnc.run("combined-survey", duration=30, out=tmp_path / "full", plots=False).df
    orig = LogWriter.close
    monkeypatch.setattr(LogWriter, "close", lambda self: (setattr(self, "compact", False), orig(self))[1])
    oceangnc.run("combined-survey", duration=30, out=tmp_path / "cut", plots=False, checkpoint_every=12)
    monkeypatch.setattr(LogWriter, "close", orig)
    (tmp_path / "cut" / "summary.json").unlink()
    res = oceangnc.run(resume=tmp_path / "cut", plots=False)
    assert res.summary["resumed_from_t"] == 24.0
    pd.testing.assert_frame_equal(res.df, full, check_exact=True)
