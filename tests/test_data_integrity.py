"""Data integrity (issue 41): a checkpoint is data, checked whole (every array against the live
simulation, the JSON inside the checksum, the log's parts by the folder itself) before any compiled
code sees it; a resumed run keeps checkpointing.

See docs/reliability.md, "Checkpoints are data, checked whole".
"""

from __future__ import annotations

import json
import os
import shutil
import subprocess
import sys
from pathlib import Path

import numpy as np
import pandas as pd
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

import oceangnc
from oceangnc import api
from oceangnc.core import checkpoint as ckpt
from oceangnc.errors import InputError
from oceangnc.io.logs import LogWriter, list_parts, read_log

ENV = {**os.environ, "PYTHONPATH": str(Path(__file__).resolve().parents[1] / "src")}


def cli(*args, timeout=300):
    return subprocess.run(
        [sys.executable, "-m", "oceangnc.cli", *args],
        capture_output=True,
        text=True,
        timeout=timeout,
        env=ENV,
        check=False,
    )


def unpack(blob: bytes) -> tuple[dict, dict[str, np.ndarray]]:
    with np.load(__import__("io").BytesIO(blob), allow_pickle=False) as z:
        members = {k: z[k] for k in z.files}
    doc = json.loads(members.pop(ckpt.DOC).tobytes())
    members.pop(ckpt.SUM)
    return doc, members


def plant_array_key(doc: dict, attr: str = "x") -> str:
    """The member name of plant 0's attribute ``attr`` (its state vector by default)."""
    return doc["sim"]["plants"][0][attr]["$a"]


def folder_bytes(d: Path) -> dict[str, bytes]:
    """Every file under ``d`` (name -> bytes): a log left exactly as it was compares equal."""
    return {str(p.relative_to(d)): p.read_bytes() for p in sorted(d.rglob("*")) if p.is_file()}


@pytest.fixture(scope="module")
def usv():
    """The usv-turn scenario built, run 3 s and captured: (scenario, config, checkpoint bytes)."""
    sc, cfg = api.resolve_config("usv-turn")
    sim = sc.build(cfg, np.random.default_rng(0))
    sim.run(3.0)
    return sc, cfg, ckpt.capture(sim)


def fresh(usv):
    sc, cfg, _ = usv
    return sc.build(cfg, np.random.default_rng(0))


# -- every array against the live simulation -----------------------------------------------------------------


@pytest.mark.parametrize(
    "make",
    [
        lambda a: np.zeros(a.size + 1),  # 7 instead of 6
        lambda a: a.astype(np.float32),
        lambda a: a.astype(np.uint8),
        lambda a: np.zeros(1000),  # the size that made compiled code write out of bounds (SIGSEGV)
        lambda a: a.reshape(1, -1),
    ],
    ids=["one-more", "float32", "uint8", "1000", "2-d"],
)
def test_a_plant_state_of_another_shape_or_dtype_is_refused_before_it_is_written(usv, make):
    doc, arrays = unpack(usv[2])
    key = plant_array_key(doc)
    arrays[key] = make(arrays[key])
    sim = fresh(usv)
    x0 = sim.plants[0].x
    before = x0.copy()
    with pytest.raises(InputError) as ei:
        ckpt.restore(sim, ckpt.pack(doc, arrays))
    msg = str(ei.value)
    assert "\n" not in msg and f"plant '{sim.plants[0].name}' attribute .x" in msg and "shape" in msg, msg
    assert sim.plants[0].x is x0 and x0.shape == before.shape and x0.dtype == before.dtype


def test_an_array_where_a_number_was_and_a_number_where_an_array_was_are_refused(usv):
    doc, arrays = unpack(usv[2])
    doc["sim"]["plants"][0]["x"] = 1.0
    with pytest.raises(InputError, match="a float where the simulation holds an array"):
        ckpt.restore(fresh(usv), ckpt.pack(doc, arrays))


def test_a_json_tree_nested_200000_deep_is_one_line(usv, tmp_path):
    """The real archive, its document replaced by one nested 200,000 deep and its checksum recomputed
    (a traceback before)."""
    from oceangnc.core.checkpoint_format import checksum

    _, arrays = unpack(usv[2])
    raw = ('{"format":"oceangnc-checkpoint","version":3,"deep":' + "[" * 200_000 + "]" * 200_000 + "}").encode()
    digest = np.frombuffer(checksum(raw, arrays).encode(), np.uint8)
    np.savez(tmp_path / ckpt.FILE, **{ckpt.DOC: np.frombuffer(raw, np.uint8), ckpt.SUM: digest}, **arrays)
    with pytest.raises(InputError) as ei:
        ckpt.load(tmp_path)
    assert "nested" in str(ei.value) and "\n" not in str(ei.value)


# -- the log is cut by the folder, never by a count in the file ------------------------------------------------


@pytest.fixture(scope="module")
def cut_run(tmp_path_factory):
    """A 40 s usv-turn run with checkpoints every 15 s, "killed" at its end (parts not compacted, no
    summary), and the log of the same run uninterrupted: (folder, reference log)."""
    d = tmp_path_factory.mktemp("cut")
    full = oceangnc.run("usv-turn", duration=40, out=d / "full", plots=False).df
    orig = LogWriter.close
    LogWriter.close = lambda self: (setattr(self, "compact", False), orig(self))[1]
    try:
        oceangnc.run(
            "usv-turn",
            duration=40,
            out=d / "cut",
            plots=False,
            checkpoint_every=15,
            overrides={"log.min_flush_wall_s": 0.0},
        )
    finally:
        LogWriter.close = orig
    (d / "cut" / "summary.json").unlink()
    return d / "cut", full


def _copy(src: Path, dst: Path) -> Path:
    shutil.copytree(src, dst)
    return dst


@pytest.mark.parametrize("parts", [0, 10**12])
def test_a_log_part_count_in_the_checkpoint_never_deletes_or_duplicates_rows(cut_run, tmp_path, parts):
    """``log.parts`` = 0 deleted rows 0-30 s of the resumed run, 10^12 duplicated them (issue 41); the
    count is now ignored (rewritten here with a valid checksum, as a tool or an attacker could)."""
    src, full = cut_run
    out = _copy(src, tmp_path / "run")
    doc, arrays = unpack((out / ckpt.FILE).read_bytes())
    doc["log"]["parts"] = parts
    (out / ckpt.FILE).write_bytes(ckpt.pack(doc, arrays))
    res = oceangnc.run(resume=out, plots=False)
    assert res.summary["resumed_from_t"] == 30.0
    pd.testing.assert_frame_equal(read_log(out), full, check_exact=True)


def test_a_resumed_run_keeps_checkpointing_at_the_runs_period(tmp_path, monkeypatch):
    """``--resume`` without ``--checkpoint-every`` kept no checkpoint: 20 kills of one run each restarted
    from the first checkpoint (summary "checkpoints": 0). A run "killed" after its checkpoint at 15 s
    (later saves suppressed, parts not compacted) resumes, and saves again at 30 s."""
    orig_close, orig_save = LogWriter.close, ckpt.Checkpointer._save
    monkeypatch.setattr(LogWriter, "close", lambda self: (setattr(self, "compact", False), orig_close(self))[1])
    monkeypatch.setattr(ckpt.Checkpointer, "_save", lambda self, sim: sim.t <= 15.0 and orig_save(self, sim))
    out = tmp_path / "run"
    oceangnc.run("usv-turn", duration=40, out=out, plots=False, checkpoint_every=15)
    (out / "summary.json").unlink()
    monkeypatch.undo()
    assert ckpt.load(out)["t"] == 15.0
    res = oceangnc.run(resume=out, plots=False)
    assert res.summary["resumed_from_t"] == 15.0 and res.summary["checkpoints"] == 1
    state = ckpt.load(out)
    assert state["t"] == 30.0 and state["every"] == 15


def test_a_log_that_cannot_give_the_checkpoints_rows_is_refused_unchanged(cut_run, tmp_path):
    src, _ = cut_run
    out = _copy(src, tmp_path / "run")
    parts = list_parts(out / "log.parquet")
    parts[5].unlink()  # a lost part before the checkpoint: rows 5-6 s are missing
    before = folder_bytes(out)
    with pytest.raises(InputError) as ei:
        oceangnc.run(resume=out, plots=False)
    assert "misses rows" in str(ei.value) and "\n" not in str(ei.value)
    assert folder_bytes(out) == before


def test_a_refused_checkpoint_leaves_the_log_and_summary_as_they_were_cli(cut_run, tmp_path):
    """A plant state of 10^6 elements (a 19-minute spin or SIGSEGV before): exit 2, one line, nothing
    changed in the run folder."""
    src, _ = cut_run
    out = _copy(src, tmp_path / "run")
    (out / "summary.json").write_text('{"status": "interrupted"}')
    doc, arrays = unpack((out / ckpt.FILE).read_bytes())
    arrays[plant_array_key(doc)] = np.zeros(10**6)
    (out / ckpt.FILE).write_bytes(ckpt.pack(doc, arrays))
    before = folder_bytes(out)
    r = cli("run", "--resume", str(out), "--quiet", "--no-plots")
    assert r.returncode == 2 and r.stderr.count("\n") == 1, r.stderr
    assert "checkpoint does not match this simulation" in r.stderr and "(1000000,)" in r.stderr
    assert folder_bytes(out) == before


# -- fuzz: random shapes, dtypes, sizes and JSON values ----------------------------------------------------------

_DTYPES = st.sampled_from(["f8", "f4", "i8", "i4", "u1", "b1", "c16", "f2", "<U3", "S2"])
_SHAPES = st.lists(st.integers(0, 9), min_size=0, max_size=3).map(tuple) | st.sampled_from([(7,), (1000,), (0,)])
_JSON = st.recursive(
    st.none() | st.booleans() | st.integers(-(2**70), 2**70) | st.floats() | st.text(max_size=8),
    lambda inner: st.lists(inner, max_size=3) | st.dictionaries(st.text(max_size=4), inner, max_size=3),
    max_leaves=6,
)


def _paths(node, path=()):
    """Every path into a JSON tree (keys and list indices)."""
    yield path
    if isinstance(node, dict):
        for k, v in node.items():
            yield from _paths(v, (*path, k))
    elif isinstance(node, list):
        for i, v in enumerate(node):
            yield from _paths(v, (*path, i))


def _set(node, path, value):
    if not path:
        return value
    *head, last = path
    cur = node
    for k in head:
        cur = cur[k]
    cur[last] = value
    return node


@settings(max_examples=60, deadline=None, suppress_health_check=[HealthCheck.too_slow], derandomize=True)
@given(data=st.data())
def test_fuzz_random_arrays_and_json_values_are_restored_exactly_or_refused_in_one_line(usv, tmp_path_factory, data):
    doc, arrays = unpack(usv[2])
    for _ in range(data.draw(st.integers(1, 3))):
        if data.draw(st.booleans()):  # an array of another shape, dtype or size
            key = data.draw(st.sampled_from(sorted(arrays)))
            shape, dtype = data.draw(_SHAPES), np.dtype(data.draw(_DTYPES))
            arrays[key] = np.zeros(shape, dtype=dtype)
        else:  # a JSON value anywhere in the document
            paths = list(_paths(doc))
            path = data.draw(st.sampled_from(paths[1:]))
            doc = _set(doc, path, data.draw(_JSON))
    d = tmp_path_factory.mktemp("fz")
    try:
        (d / ckpt.FILE).write_bytes(ckpt.pack(doc, arrays))
    except (ValueError, TypeError):
        return  # not JSON data at all (e.g. a NaN key): nothing a checkpoint writer could produce
    sim = fresh(usv)
    live = [
        (pl, {k: (a.shape, a.dtype) for k, a in vars(pl).items() if isinstance(a, np.ndarray)}) for pl in sim.plants
    ]
    try:
        state = ckpt.load(d)
        ckpt.restore(sim, state["sim"])
    except InputError as e:
        assert str(e) and "\n" not in str(e), str(e)
        return
    # accepted: every array compiled code holds kept its shape and dtype
    for pl, shapes in live:
        for k, (shape, dtype) in shapes.items():
            v = getattr(pl, k)
            assert isinstance(v, np.ndarray) and v.shape == shape and v.dtype == dtype, (pl.name, k)
