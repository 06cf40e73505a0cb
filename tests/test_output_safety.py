"""Temporary files are created, never followed; outputs never replace what they should not; inputs are
bounded before they are read (issue 41). See docs/reliability.md.
"""

from __future__ import annotations

import os
import socket
import stat
from pathlib import Path

import pytest

import oceangnc
from oceangnc.cli import main
from oceangnc.core import checkpoint as ckpt
from oceangnc.core.files import LIMIT_TOML, create_exclusive, read_bounded
from oceangnc.errors import ConfigError, InputError
from oceangnc.io.log_read import list_parts
from oceangnc.models.vehicle import load_vehicle


@pytest.fixture(scope="module")
def run_dir(tmp_path_factory):
    out = tmp_path_factory.mktemp("run") / "r"
    oceangnc.run("usv-turn", duration=6, out=out, plots=False)
    return out


def cli(capsys, *args) -> tuple[int, str, str]:
    rc = main(list(args))
    c = capsys.readouterr()
    return rc, c.out, c.err


# -- temporary files are created, never followed ------------------------------------------------------------


def test_a_planted_temporary_link_is_never_written_through(tmp_path):
    victim = tmp_path / "victim.txt"
    victim.write_text("precious")
    tmp = tmp_path / ".x.tmp"
    tmp.symlink_to(victim)
    with create_exclusive(tmp) as f:
        f.write(b"new")
    assert victim.read_text() == "precious" and not tmp.is_symlink() and tmp.read_bytes() == b"new"


def test_resume_never_writes_through_links_planted_in_a_shared_run_folder(tmp_path, capsys):
    """A ``.summary.json.tmp`` symlink made ``run --resume`` overwrite any file the user could write, and
    left summary.json a link to it (issue 41); the checkpoint's and the log's temporary names too."""
    out = tmp_path / "run"
    oceangnc.run("usv-turn", duration=6, out=out, plots=False, checkpoint_every=2)
    (out / "summary.json").unlink()  # as if killed
    victims = {}
    for name in (".summary.json.tmp", f".{ckpt.FILE}.tmp", "log.parquet/.part-000009.parquet.tmp"):
        v = tmp_path / f"victim{len(victims)}"
        v.write_text("precious")
        (out / name).symlink_to(v)
        victims[name] = v
    rc, _, err = cli(capsys, "run", "--resume", str(out), "--quiet", "--no-plots")
    assert rc == 0, err
    assert all(v.read_text() == "precious" for v in victims.values())
    s = out / "summary.json"
    assert stat.S_ISREG(os.lstat(s).st_mode) and '"status": "ok"' in s.read_text()


# -- outputs never replace what they should not ---------------------------------------------------------------


@pytest.mark.parametrize("cmd", [["view"], ["export", "--mcap"]])
@pytest.mark.parametrize("name", ["config.toml", "summary.json"])
def test_view_and_export_never_replace_a_runs_own_files(run_dir, capsys, cmd, name):
    before = (run_dir / name).read_bytes()
    rc, _, err = cli(capsys, *cmd, str(run_dir), "--out", str(run_dir / name))
    assert rc == 2 and err.count("\n") == 1 and name in err, err
    assert (run_dir / name).read_bytes() == before


@pytest.mark.parametrize("cmd", [["view"], ["export", "--mcap"]])
def test_out_refuses_devices_links_and_files_of_another_kind(run_dir, tmp_path, capsys, cmd):
    other = tmp_path / "notes.txt"
    other.write_text("mine")
    link = tmp_path / "link.out"
    link.symlink_to(other)
    for target in ("/dev/null", str(other), str(link), str(tmp_path)):
        rc, _, err = cli(capsys, *cmd, str(run_dir), "--out", target)
        assert rc == 2 and err.count("\n") == 1 and "refused" in err, (target, err)
    assert other.read_text() == "mine" and stat.S_ISCHR(os.stat("/dev/null").st_mode)
    # a previous output of the same kind is replaced; an uncreatable folder is one line
    out = tmp_path / "again.out"
    for _ in range(2):
        rc, _, err = cli(capsys, *cmd, str(run_dir), "--out", str(out))
        assert rc == 0, err
    rc, _, err = cli(capsys, *cmd, str(run_dir), "--out", str(other / "sub" / "x.out"))
    assert rc == 2 and err.count("\n") == 1 and "cannot" in err, err


def test_serve_port_out_of_range_or_busy_is_one_line(run_dir, capsys):
    rc, _, err = cli(capsys, "view", str(run_dir), "--serve", "--port", "70000")
    assert rc == 2 and err.count("\n") == 1 and "out of range" in err, err
    s = socket.socket()
    s.bind(("127.0.0.1", 0))
    s.listen(1)
    try:
        rc, _, err = cli(capsys, "view", str(run_dir), "--serve", "--port", str(s.getsockname()[1]))
    finally:
        s.close()
    assert rc == 2 and err.count("\n") == 1 and "cannot listen" in err, err


def test_an_export_of_a_log_with_a_damaged_part_names_the_missing_span(tmp_path, capsys):
    out = tmp_path / "run"
    from oceangnc.io.logs import LogWriter

    orig = LogWriter.close
    LogWriter.close = lambda self: (setattr(self, "compact", False), orig(self))[1]
    try:
        oceangnc.run("usv-turn", duration=6, out=out, plots=False, overrides={"log.min_flush_wall_s": 0.0})
    finally:
        LogWriter.close = orig
    parts = list_parts(out / "log.parquet")
    parts[2].write_bytes(b"PAR1 torn")  # rows of 2-3 s
    rc, _, err = cli(capsys, "export", str(out), "--mcap", "--out", str(tmp_path / "x.mcap"))
    assert rc == 0
    assert err.startswith("warning: ") and "part-000002.parquet unreadable" in err, err
    assert "no data between t = 2.000 s to 3.050 s" in err or "no data between t = 2.000 s" in err, err


# -- inputs are bounded before they are read -------------------------------------------------------------------


def test_loaders_refuse_devices_fifos_and_oversized_files_in_one_line(tmp_path, capsys):
    fifo = tmp_path / "fifo.toml"
    os.mkfifo(fifo)
    big = tmp_path / "big.toml"
    with open(big, "wb") as f:
        f.truncate(LIMIT_TOML + 1)  # sparse: nothing is written, nothing may be read
    for p in ("/dev/zero", str(fifo), str(big), str(tmp_path)):
        with pytest.raises(InputError) as ei:
            read_bounded(p, LIMIT_TOML, "config file")
        assert "\n" not in str(ei.value)
        rc, _, err = cli(capsys, "run", "usv-turn", "--config", p, "--quiet")
        assert rc == 2 and err.count("\n") == 1, (p, err)
        with pytest.raises((InputError, ConfigError)) as ei:
            load_vehicle(p)
        assert "\n" not in str(ei.value)


def test_a_toml_array_nested_100000_deep_and_non_utf8_files_are_one_line(tmp_path, run_dir, capsys):
    deep = tmp_path / "deep.toml"
    deep.write_text("a = " + "[" * 100_000 + "]" * 100_000 + "\n")
    rc, _, err = cli(capsys, "run", "usv-turn", "--config", str(deep), "--quiet")
    assert rc == 2 and err.count("\n") == 1 and "nested too deeply" in err, err[:300]
    bad = tmp_path / "latin1.toml"
    bad.write_bytes(b"# caf\xe9\n")
    rc, _, err = cli(capsys, "run", "usv-turn", "--config", str(bad), "--quiet")
    assert rc == 2 and err.count("\n") == 1 and "not UTF-8" in err, err
    # a run folder whose config or summary is not UTF-8: view and resume say it in one line
    for name in ("config.toml", "summary.json"):
        d = tmp_path / f"run-{name}"
        import shutil

        shutil.copytree(run_dir, d)
        (d / name).write_bytes(b"\xff\xfe garbage")
        rc, _, err = cli(capsys, "view", str(d), "--out", str(tmp_path / f"{name}.html"))
        if name == "config.toml":
            assert rc == 2 and err.count("\n") == 1 and "not UTF-8" in err, err
        else:
            assert rc == 0, err  # an unreadable summary only loses the page's summary panel
        rc, _, err = cli(capsys, "run", "--resume", str(d), "--quiet")
        assert rc == 2 and err.count("\n") == 1, err


# -- exports stream ---------------------------------------------------------------------------------------------


def _messages(path):
    from mcap.reader import make_reader

    with open(path, "rb") as f:
        r = make_reader(f)
        out = [(ch.topic, m.log_time, m.sequence, m.data) for _, ch, m in r.iter_messages(log_time_order=False)]
        meta = [(m.name, m.metadata) for m in r.iter_metadata()]
    return out, meta


def test_the_mcap_export_streams_the_log_in_bounded_parts_with_the_same_messages(tmp_path, monkeypatch):
    """An MCAP export of a 5-million-row log failed past 8 GB (issue 41): the log is now read row group
    by row group in parts of at most ``batch_rows`` rows, and the file holds the same messages as an
    export of the whole log held in memory."""
    from oceangnc.view import mcap_export, run_data

    out = tmp_path / "run"
    oceangnc.run("tow-straight", duration=20, out=out, plots=False)
    rd = run_data.load_run(out)
    rows = rd.rows
    whole = mcap_export.export_mcap(rd, tmp_path / "whole.mcap")
    sizes: list[int] = []
    orig = run_data.describe

    def spy(path, cols, *a, **kw):
        sizes.append(len(cols["t"]))
        return orig(path, cols, *a, **kw)

    monkeypatch.setattr(run_data, "describe", spy)
    streamed = mcap_export.export_mcap(out, tmp_path / "streamed.mcap", batch_rows=50)
    assert sizes[0] == 1  # the one-row probe of the folder, before anything is written
    parts = sizes[1:]
    assert max(parts) <= 50 and sum(parts) == 2 * rows  # two passes, each over every row in parts of <= 50
    a, b = _messages(whole), _messages(streamed)
    assert len(a[0]) >= 8 * rows and a == b


def test_a_fifo_named_like_a_log_part_is_not_read(run_dir, tmp_path):
    """A FIFO among a log's parts blocked every reader of the log forever; parts are regular files."""
    import shutil
    import subprocess
    import sys

    d = tmp_path / "r"
    shutil.copytree(run_dir, d)
    os.mkfifo(d / "log.parquet" / "part-000007.parquet")
    env = {**os.environ, "PYTHONPATH": str(Path(__file__).resolve().parents[1] / "src")}
    r = subprocess.run(
        [sys.executable, "-m", "oceangnc.cli", "view", str(d), "--out", str(tmp_path / "p.html")],
        capture_output=True,
        text=True,
        timeout=120,
        env=env,
        check=False,
    )
    assert r.returncode == 0, r.stderr
