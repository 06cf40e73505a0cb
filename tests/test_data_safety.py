"""Data safety (issue 26): the atomic final merge of a run's log, checkpoints that cannot run code,
SIGTERM ended like Ctrl-C, and ``oceangnc log repair`` printing counts.

See docs/reliability.md for the guarantees these tests check.
"""

from __future__ import annotations

import json
import os
import pickle
import signal
import subprocess
import sys
import threading
import time
from pathlib import Path

import numpy as np
import pandas as pd
import pyarrow.parquet as pq
import pytest

import oceangnc
from oceangnc import api
from oceangnc.core import checkpoint as ckpt
from oceangnc.errors import ConfigError, InputError
from oceangnc.io import logs
from oceangnc.io.logs import LogWriter, list_parts, merge_folders, read_log, repair_log

ENV = {**os.environ, "PYTHONPATH": str(Path(__file__).resolve().parents[1] / "src")}


def cli(*args):
    return subprocess.run(
        [sys.executable, "-m", "oceangnc.cli", *args], capture_output=True, text=True, timeout=300, env=ENV, check=False
    )


def wait_for(pred, timeout=120.0):
    t0 = time.monotonic()
    while time.monotonic() - t0 < timeout:
        if pred():
            return True
        time.sleep(0.01)
    return False


# -- the atomic final merge --------------------------------------------------------------------------------

ROWS = 201  # 10 s at 20 Hz: 10 parts before the merge

# a LogWriter that flushes 10 parts, then closes (merges) with a hook that ends the process at once
# (os._exit: no clean-up, like SIGKILL) at the named step of the merge
WRITER = f"""
import os, sys
from oceangnc.io import logs
mode, step, path = sys.argv[1:]
if mode == "renames":
    logs._exchange = lambda a, b: False
logs._merge_hook = lambda name: os._exit(9) if name == step else None
w = logs.LogWriter(path, flush_period=1.0)
for k in range({ROWS}):
    w.append(k * 0.05, {{"x": float(k), "y": -float(k)}})
w.close()
"""


def _merge_steps(tmp_path: Path, mode: str, monkeypatch) -> list[str]:
    """The steps of the merge, recorded in-process (the same code as the subprocess runs)."""
    seen: list[str] = []
    if mode == "renames":
        monkeypatch.setattr(logs, "_exchange", lambda a, b: False)
    monkeypatch.setattr(logs, "_merge_hook", seen.append)
    w = LogWriter(tmp_path / "steps" / "log.parquet", flush_period=1.0)
    for k in range(ROWS):
        w.append(k * 0.05, {"x": float(k), "y": -float(k)})
    w.close()
    monkeypatch.undo()
    return seen


@pytest.mark.parametrize("mode", ["exchange", "renames"])
def test_a_kill_at_every_step_of_the_final_merge_never_shows_duplicated_rows(tmp_path, mode, monkeypatch):
    """pandas and pyarrow see the old parts, the merged file, or (two renames, between them) no folder,
    never both; read_log reads the full log at every step, and repair leaves one whole part."""
    steps = _merge_steps(tmp_path, mode, monkeypatch)
    assert steps[0] == "started" and steps[-1] == "removed"
    if mode == "renames":
        assert "moved aside" in steps and "exchanged" not in steps
    else:
        (tmp_path / "p").mkdir(), (tmp_path / "q").mkdir()
        if logs._exchange(tmp_path / "p", tmp_path / "q"):  # this file system swaps folders in one call
            assert "exchanged" in steps and "moved aside" not in steps
    ref = pd.read_parquet(tmp_path / "steps" / "log.parquet")
    assert len(ref) == ROWS and len(list_parts(tmp_path / "steps" / "log.parquet")) == 1
    for i, step in enumerate(steps):
        run = tmp_path / f"{i}-{step.replace(' ', '-')}"
        log = run / "log.parquet"
        r = subprocess.run(
            [sys.executable, "-c", WRITER, mode, step, str(log)], env=ENV, capture_output=True, text=True, timeout=300
        )
        assert r.returncode == 9, r.stderr  # ended by the hook at that step
        merging, old = merge_folders(log)
        if not log.exists():  # only between the two renames of the fallback
            assert mode == "renames" and step == "moved aside", step
            with pytest.raises((FileNotFoundError, OSError)):
                pd.read_parquet(log)
        else:
            for df in (pd.read_parquet(log), pq.read_table(log).to_pandas()):
                t = df["t"].to_numpy()
                assert np.all(np.diff(t) > 0), f"{mode}, killed after '{step}': time goes backwards"
                pd.testing.assert_frame_equal(df, ref, check_exact=True)
        pd.testing.assert_frame_equal(read_log(log), ref, check_exact=True)  # reads around the leftovers
        pd.testing.assert_frame_equal(read_log(run), ref, check_exact=True)
        rep = repair_log(run)
        assert rep["rows"] == ROWS and rep["parts"] == 1
        assert not merging.exists() and not old.exists()
        assert [p.name for p in log.iterdir()] == ["part-000000.parquet"]
        pd.testing.assert_frame_equal(pd.read_parquet(log), ref, check_exact=True)


def test_repair_cli_finishes_a_merge_cut_between_the_two_renames(tmp_path):
    log = tmp_path / "log.parquet"
    r = subprocess.run(
        [sys.executable, "-c", WRITER, "renames", "moved aside", str(log)], env=ENV, capture_output=True, timeout=300
    )
    assert r.returncode == 9
    assert not log.exists()
    assert len(read_log(tmp_path)) == ROWS  # a run folder whose log.parquet is missing: still read
    r = cli("log", "repair", str(tmp_path))
    assert r.returncode == 0, r.stderr
    assert "finished an interrupted merge" in r.stdout and f"log has {ROWS} rows in 1 part file" in r.stdout
    assert sorted(p.name for p in tmp_path.iterdir()) == ["log.parquet"]
    np.testing.assert_array_equal(pd.read_parquet(log)["x"].to_numpy(), np.arange(float(ROWS)))


def test_a_resume_after_a_kill_in_the_merge_keeps_the_rows(tmp_path):
    """The cut of a resume finishes an interrupted merge before it drops the later rows."""
    from oceangnc.io.log_resume import cut_to_checkpoint

    log = tmp_path / "log.parquet"
    r = subprocess.run(
        [sys.executable, "-c", WRITER, "renames", "moved aside", str(log)], env=ENV, capture_output=True, timeout=300
    )
    assert r.returncode == 9
    assert cut_to_checkpoint(log, ROWS, (ROWS - 1) * 0.05) == 1
    assert len(read_log(log)) == ROWS and not any(p.exists() for p in merge_folders(log))
    # the merged part runs past a checkpoint at row 100: it is rewritten with its first 100 rows
    assert cut_to_checkpoint(log, 100, 99 * 0.05) == 1
    df = read_log(log)
    assert len(df) == 100 and df["t"].iloc[-1] == 99 * 0.05


def test_a_new_run_into_a_folder_removes_leftovers_of_an_old_merge(tmp_path):
    out = tmp_path / "run"
    log = out / "log.parquet"
    r = subprocess.run(
        [sys.executable, "-c", WRITER, "renames", "moved aside", str(log)], env=ENV, capture_output=True, timeout=300
    )
    assert r.returncode == 9
    oceangnc.run("usv-turn", duration=2, out=out, plots=False, overwrite=True)
    assert not any(p.exists() for p in merge_folders(log))
    assert len(pd.read_parquet(log)) == len(read_log(out)) == 41


def test_a_full_disk_during_the_merge_keeps_the_parts_and_is_one_line(tmp_path, monkeypatch):
    log = tmp_path / "log.parquet"
    w = LogWriter(log, flush_period=1.0)
    for k in range(ROWS):
        w.append(k * 0.05, {"x": float(k)})
    w.flush()

    def full(*a, **k):
        raise OSError(28, "No space left on device")

    monkeypatch.setattr(logs.pq, "write_table", full)
    with pytest.raises(InputError) as ei:
        w.close()
    assert "cannot merge the log" in str(ei.value) and "No space left on device" in str(ei.value)
    assert "\n" not in str(ei.value)
    monkeypatch.undo()
    assert not any(p.exists() for p in merge_folders(log)) and len(list_parts(log)) == 10
    np.testing.assert_array_equal(pd.read_parquet(log)["x"].to_numpy(), np.arange(float(ROWS)))


# -- log repair prints counts ---------------------------------------------------------------------------------


def test_log_repair_prints_counts_not_every_part(tmp_path):
    log = tmp_path / "log.parquet"
    with LogWriter(log, flush_period=1e6) as w:  # one merged part 0 of 3000 rows
        w.append_rows(np.arange(3000) * 1.0, ["x"], np.arange(3000.0)[:, None])
    merged = pq.read_table(list_parts(log)[0]).replace_schema_metadata(None)
    # an older version's crash mid-compaction: the merged part 0 beside the 2999 parts it covers
    w = LogWriter(log)
    for k in range(1, 3000):
        w._write_part(merged.slice(k, 1), k, k, final_part=False)
    (log / ".part-003000.parquet.tmp").write_bytes(b"half")
    (log / "part-003001.parquet").write_bytes(b"PAR1 torn")
    r = cli("log", "repair", str(tmp_path))
    assert r.returncode == 0, r.stderr
    assert r.stdout.strip() == (
        "log repaired: removed 2,999 covered parts, 1 unreadable part, 1 temporary file; "
        "log has 3,000 rows in 1 part file"
    )
    assert len(r.stdout) < 200
    r = cli("log", "repair", str(tmp_path))
    assert r.stdout.strip() == "log repaired: removed nothing; log has 3,000 rows in 1 part file"


# -- checkpoints cannot run code ---------------------------------------------------------------------------------


class _CreatesFile:
    """A pickle payload: unpickling it creates (opens for writing) the file ``path``."""

    def __init__(self, path):
        self.path = str(path)

    def __reduce__(self):
        return (open, (self.path, "w"))


def _run_folder(tmp_path) -> Path:
    out = tmp_path / "run"
    oceangnc.run("usv-turn", duration=4, out=out, plots=False, checkpoint_every=2)
    (out / "summary.json").unlink()  # as if killed
    return out


def _resume(capsys, out):
    from oceangnc.cli import main

    rc = main(["run", "--resume", str(out), "--quiet", "--no-plots"])
    return rc, capsys.readouterr().err


def test_an_old_pickle_checkpoint_is_refused_unread(tmp_path, capsys):
    out = _run_folder(tmp_path)
    (out / ckpt.FILE).unlink()
    marker = tmp_path / "pwned"
    (out / "checkpoint.pkl").write_bytes(
        pickle.dumps({"version": 1, "t": 2.0, "sim": _CreatesFile(marker), "log": {"parts": 0, "rows": 0}})
    )
    rc, err = _resume(capsys, out)
    assert rc == 2 and err.count("\n") == 1, err
    assert "checkpoint.pkl is an old, unsafe format" in err and "rerun" in err
    assert not marker.exists()


@pytest.mark.parametrize("where", ["document", "array"])
def test_a_crafted_npz_checkpoint_cannot_run_code(tmp_path, capsys, where):
    """An object array (pickled inside the .npz) in place of the JSON document or of a state array."""
    out = _run_folder(tmp_path)
    marker = tmp_path / "pwned"
    payload = np.empty(1, dtype=object)
    payload[0] = _CreatesFile(marker)
    with np.load(out / ckpt.FILE, allow_pickle=False) as z:
        members = {k: z[k] for k in z.files}
    members["checkpoint.json" if where == "document" else "a0"] = payload
    np.savez(out / ckpt.FILE, **members)
    rc, err = _resume(capsys, out)
    assert rc == 2 and err.count("\n") == 1, err
    assert "unreadable" in err and "Object arrays cannot be loaded" in err
    assert not marker.exists()
    (out / ckpt.FILE).write_bytes(pickle.dumps(_CreatesFile(marker)))  # a bare pickle named .npz
    rc, err = _resume(capsys, out)
    assert rc == 2 and "not an oceangnc checkpoint" in err and not marker.exists()


def test_checkpoint_is_an_npz_of_arrays_and_json_with_a_checksum(tmp_path, capsys):
    out = _run_folder(tmp_path)
    with np.load(out / ckpt.FILE, allow_pickle=False) as z:  # no object array anywhere
        members = {k: z[k] for k in z.files}
    raw = members.pop("checkpoint.json")
    doc = json.loads(raw.tobytes())
    assert doc["format"] == "oceangnc-checkpoint" and doc["version"] == 3 and doc["scenario"] == "usv-turn"
    assert doc["t"] == 2.0 and doc["log"]["rows"] == 41  # flushed right before it was saved
    assert doc["sim"]["block_names"] and all(a.dtype != object for a in members.values())
    assert "checkpoint.sha256" in members
    # a changed array, and a changed number of the JSON document (issue 41: the log position was outside
    # the checksum), are both caught by the one SHA-256
    changed = dict(doc, log={"parts": 0, "rows": 41})
    for text, arrays in (
        (raw, {**members, "a0": members["a0"] + 1.0}),
        (np.frombuffer(json.dumps(changed, separators=(",", ":")).encode(), np.uint8), members),
    ):
        np.savez(out / ckpt.FILE, **{"checkpoint.json": text}, **arrays)
        rc, err = _resume(capsys, out)
        assert rc == 2 and "damaged" in err and "SHA-256" in err and err.count("\n") == 1, err
    (out / ckpt.FILE).write_bytes(b"PK\x03\x04 torn")
    rc, err = _resume(capsys, out)
    assert rc == 2 and "unreadable" in err and err.count("\n") == 1


def _plain_block(sim):
    """A block of ``sim`` written in plain Python (its state: its attributes), not a one-law block."""
    from oceangnc.core.law import LawBlock

    return next(b for b in sim.blocks if not isinstance(b, LawBlock))


def test_a_block_state_that_cannot_be_stored_is_refused_at_capture_naming_block_and_attribute():
    sc, cfg = api.resolve_config("usv-turn")
    sim = sc.build(cfg, np.random.default_rng(0))
    b = _plain_block(sim)  # a block whose state is its attributes
    b.guard = {"lock": threading.Lock()}
    with pytest.raises(ConfigError) as ei:
        ckpt.capture(sim)
    msg = str(ei.value)
    assert f"block '{b.name}' attribute .guard['lock'] holds a _thread.lock" in msg and "\n" not in msg
    b.guard = np.array([object()], dtype=object)
    with pytest.raises(ConfigError, match="an array of Python objects"):
        ckpt.capture(sim)


class _Holder:
    """An object of the simulation's own classes inside a block's state (restored in place)."""

    def __init__(self):
        self.count = 0
        self.hist: list = []


def test_state_tree_round_trips_every_allowed_kind():
    import collections
    import enum

    class Mode(enum.Enum):
        A = 1
        B = 2

    sc, cfg = api.resolve_config("usv-turn")

    def build():
        sim = sc.build(cfg, np.random.default_rng(0))
        b = _plain_block(sim)
        b.extra = _Holder()
        b.mode = Mode.A
        return sim, b

    sim, b = build()
    shared = np.arange(3.0)
    b.extra.count = 7
    b.extra.hist = [1, 2.5, "s", None, True, (1, 2), {"k": [np.float64(0.1), np.int32(3)]}]
    b.q = collections.deque([1.0, 2.0], maxlen=3)
    b.keys = {1: "one", (2, 3): "pair"}
    b.tags = {"a", "b"}
    b.same = [shared, shared]
    b.plant = sim.plants[0]
    b.other = b.extra  # the same object twice
    b.mode = Mode.B
    b.gen = np.random.Generator(np.random.MT19937(5))
    b.gen.random(3)
    blob = ckpt.capture(sim)
    sim2, b2 = build()
    ckpt.restore(sim2, blob)
    assert b2.extra.count == 7 and b2.extra.hist == b.extra.hist
    assert type(b2.extra.hist[6]["k"][0]) is np.float64 and type(b2.extra.hist[6]["k"][1]) is np.int32
    assert b2.q == b.q and b2.q.maxlen == 3 and b2.keys == b.keys and b2.tags == b.tags
    assert b2.same[0] is b2.same[1] and np.array_equal(b2.same[0], shared)
    assert b2.plant is sim2.plants[0] and b2.other is b2.extra and b2.mode is Mode.B
    assert b2.gen.random() == b.gen.random()


def test_a_checkpoint_naming_a_class_the_simulation_does_not_hold_is_refused(tmp_path):
    sc, cfg = api.resolve_config("usv-turn")
    sim = sc.build(cfg, np.random.default_rng(0))
    _plain_block(sim).extra = _Holder()
    blob = ckpt.capture(sim)
    sim2 = sc.build(cfg, np.random.default_rng(0))  # no _Holder here: nothing is created from a name
    with pytest.raises(InputError) as ei:
        ckpt.restore(sim2, blob)
    assert "checkpoint does not match this simulation (block 'command' attribute .extra: no " in str(ei.value)
    assert "_Holder here" in str(ei.value)


def test_a_get_state_returning_an_object_is_refused_at_capture():
    """A get_state() result is restored with no live object to write into: plain data only."""
    sc, cfg = api.resolve_config("usv-turn")
    sim = sc.build(cfg, np.random.default_rng(0))
    b = sim.blocks[-1]  # the thrusters: a LawBlock, whose get_state() gives arrays and a dict of ints
    assert ckpt.capture(sim)
    state = b.get_state()
    b.get_state = lambda: {**state, "extra": _Holder()}
    with pytest.raises(ConfigError) as ei:
        ckpt.capture(sim)
    assert f"block '{b.name}' attribute get_state()['extra'] holds a test_data_safety._Holder" in str(ei.value)
    assert "return plain data from get_state" in str(ei.value)


# -- SIGTERM ends a run like Ctrl-C ----------------------------------------------------------------------------


def test_sigterm_ends_a_run_like_ctrl_c(tmp_path):
    out = tmp_path / "run"
    proc = subprocess.Popen(
        [sys.executable, "-m", "oceangnc.cli", "run", "usv-turn", "--duration", "5000", "--out", str(out)],
        stdout=subprocess.PIPE,
        stderr=subprocess.PIPE,
        text=True,
        env=ENV,
    )
    try:
        assert wait_for(lambda: (out / "log.parquet").is_dir() and len(list_parts(out / "log.parquet")) >= 1)
        assert proc.poll() is None, "the run ended before it could be terminated"
        proc.send_signal(signal.SIGTERM)
        _, err = proc.communicate(timeout=120)
    finally:
        proc.kill()
        proc.wait(timeout=30)
    assert proc.returncode == 143 and "Traceback" not in err and "terminated (SIGTERM)" in err, err
    s = json.loads((out / "summary.json").read_text())
    assert s["status"] == "interrupted" and s["signal"] == "SIGTERM"
    assert len(list_parts(out / "log.parquet")) == 1  # closed: merged into one file
    assert s["rows"] == len(read_log(out)) == len(pd.read_parquet(out / "log.parquet")) > 20


def test_the_cli_installs_its_sigterm_handler_only_while_a_run_runs(monkeypatch):
    """``run`` turns SIGTERM into a Ctrl-C-like end while it runs, then gives the caller's handler back;
    other commands (servers, bridges) keep the default SIGTERM."""
    from oceangnc import cli as cli_mod

    before = signal.getsignal(signal.SIGTERM)
    during = []
    monkeypatch.setattr(cli_mod, "_cmd_run", lambda args: during.append(signal.getsignal(signal.SIGTERM)) or 0)
    monkeypatch.setattr(cli_mod, "_cmd_list", lambda args: during.append(signal.getsignal(signal.SIGTERM)) or 0)
    assert cli_mod.main(["run", "usv-turn"]) == 0
    assert callable(during[0]) and during[0] is not before  # SIGTERM raises Terminated while it runs
    assert signal.getsignal(signal.SIGTERM) is before  # and the caller's handler is back after
    assert cli_mod.main(["list"]) == 0
    assert during[1] is before  # list: untouched
