"""A new user's rough edges (issue 26): each bad input is one line and exit 2, nothing half-written."""

from __future__ import annotations

import json

import pyarrow as pa
import pyarrow.parquet as pq
import pytest

from oceangnc.cli import main


def _run(capsys, *args):
    rc = main(list(args))
    out, err = capsys.readouterr()
    return rc, out, err


def test_out_pointing_at_a_file_or_an_uncreatable_path_is_one_line(tmp_path, capsys):
    f = tmp_path / "afile"
    f.write_text("x")
    for out in (f, f / "below", tmp_path / ("n" * 300)):
        rc, _, err = _run(capsys, "run", "usv-turn", "--duration", "1", "--no-plots", "--quiet", "--out", str(out))
        assert rc == 2 and err.count("\n") == 1 and "--out" in err and "Traceback" not in err


def test_out_into_an_existing_run_needs_overwrite(tmp_path, capsys):
    out = tmp_path / "r"
    rc, _, _ = _run(capsys, "run", "usv-turn", "--duration", "2", "--no-plots", "--quiet", "--out", str(out))
    assert rc == 0
    rc, _, err = _run(capsys, "run", "usv-turn", "--duration", "3", "--no-plots", "--quiet", "--out", str(out))
    assert rc == 2 and "--overwrite" in err and err.count("\n") == 1
    assert json.loads((out / "summary.json").read_text())["duration_s"] == 2.0  # the old run is untouched
    args = ("run", "usv-turn", "--duration", "3", "--no-plots", "--quiet", "--out", str(out), "--overwrite")
    assert _run(capsys, *args)[0] == 0
    assert json.loads((out / "summary.json").read_text())["duration_s"] == 3.0


def test_a_config_refused_at_build_leaves_no_run_folder(tmp_path, capsys):
    """The stability limit of the pole-placed autopilot is checked when the blocks are built."""
    out = tmp_path / "refused"
    rc, _, err = _run(capsys, "run", "autopilot-heading", "--set", "heading.wn=0.001", "--quiet", "--out", str(out))
    assert rc == 2 and err.count("\n") == 1
    assert not out.exists()


def test_plot_refuses_an_empty_log_and_keeps_the_figures(tmp_path, capsys):
    out = tmp_path / "r"
    assert _run(capsys, "run", "usv-turn", "--duration", "2", "--quiet", "--out", str(out))[0] == 0
    pngs = {p: p.read_bytes() for p in out.glob("*.png")}
    assert pngs
    log = out / "log.parquet"
    schema = pq.read_schema(next(log.glob("*.parquet")) if log.is_dir() else log)
    for p in log.glob("*.parquet") if log.is_dir() else [log]:
        p.unlink()
    pq.write_table(pa.Table.from_pylist([], schema=schema), log / "part-000000.parquet" if log.is_dir() else log)
    rc, _, err = _run(capsys, "plot", str(out))
    assert rc == 2 and "no rows" in err
    assert {p: p.read_bytes() for p in out.glob("*.png")} == pngs


def test_json_prints_only_the_json_line(tmp_path, capsys):
    rc, out, _ = _run(
        capsys, "run", "usv-turn", "--duration", "1", "--no-plots", "--json", "--out", str(tmp_path / "j")
    )
    assert rc == 0
    lines = [ln for ln in out.splitlines() if ln.strip()]
    assert len(lines) == 1 and json.loads(lines[0])["status"] == "ok"


@pytest.mark.parametrize("dt", [0.1])
def test_sim_dt_message_names_the_key(dt, capsys):
    rc, _, err = _run(capsys, "run", "combined-survey", "--set", f"sim.dt={dt}", "--duration", "1", "--quiet",
                      "--no-plots", "--out", "/tmp/never-written-dt")  # fmt: skip
    assert rc == 2 and "sim.dt" in err and err.count("\n") == 1


def test_a_gain_belongs_to_the_selected_controller_and_never_switches_it(capsys):
    """combined-survey flies the UUV by backstepping: its gain is taken as such, a PID gain is refused."""
    from oceangnc.api import resolve_config

    _, cfg = resolve_config("combined-survey", overrides={"control.uuv.k1": 0.5})
    assert cfg.control.uuv.full_kind == "uuv.backstepping" and cfg.control.uuv.params == {"k1": 0.5}
    rc, _, err = _run(capsys, "run", "combined-survey", "--set", "control.uuv.range_kp=300", "--quiet")
    assert rc == 2 and err.count("\n") == 1 and "not a parameter of kind 'backstepping'" in err
    _, cfg = resolve_config("combined-survey", overrides={"control.uuv.kind": "pid", "control.uuv.range_kp": 300})
    assert cfg.control.uuv.full_kind == "uuv.pid"


def test_a_run_shorter_than_one_step_is_refused(capsys, tmp_path):
    rc, _, err = _run(capsys, "run", "usv-turn", "--duration", "1e-5", "--quiet", "--out", str(tmp_path / "x"))
    assert rc == 2 and "sim.duration" in err and not (tmp_path / "x").exists()


def test_a_cable_shorter_than_the_start_gap_is_refused(tmp_path, capsys):
    """A cable shorter than the distance from the USV's tow point to the UUV at the start would start
    the run with a snap load (6.9 kN with a 2 m cable): refused in one line naming the keys."""
    out = tmp_path / "r"
    rc, _, err = _run(capsys, "run", "combined-survey", "--set", "cable.length=2", "--no-plots", "--out", str(out))
    assert rc == 2 and err.count("\n") == 1 and "cable.length = 2 m" in err and "uuv.x0/y0/z0" in err
    assert not out.exists()
    # the same cable reaches a UUV started within its reach
    args = ("run", "combined-survey", "--set", "cable.length=2", "--set", "uuv.z0=1.5", "--duration", "2")
    assert _run(capsys, *args, "--no-plots", "--quiet", "--out", str(out))[0] == 0


def test_a_warning_is_one_line_without_a_source_path(tmp_path, capsys):
    """The first-order USV starts from rest, below the trial ranges of 000 table 2: the user sees one
    ``warning:`` line, not Python's ``path:line: RuntimeWarning`` with a code line."""
    args = ("run", "usv-waypoints-7", "--duration", "5", "--no-plots", "--quiet", "--out", str(tmp_path / "r"))
    rc, _, err = _run(capsys, *args)
    assert rc == 0
    lines = [ln for ln in err.splitlines() if ln.strip()]
    assert lines and all(ln.startswith("warning: ") for ln in lines), err
    assert ".py" not in err and "RuntimeWarning" not in err
