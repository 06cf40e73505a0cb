"""The command line end to end, in subprocesses, as a user runs it."""

import json
import subprocess
import sys

import pyarrow.parquet as pq


def oceangnc(*args, cwd=None):
    return subprocess.run(
        [sys.executable, "-m", "oceangnc.cli", *args], capture_output=True, text=True, cwd=cwd, timeout=600
    )


def test_list_shows_scenarios_one_line_each():
    r = oceangnc("list")
    assert r.returncode == 0
    lines = r.stdout.strip().splitlines()
    names = [ln.split()[0] for ln in lines]
    assert {"usv-straight", "usv-turn", "usv-turn-wind", "usv-turn-current"} <= set(names)
    assert sum("(default)" in ln for ln in lines) == 1


def test_run_writes_outputs_and_plot_redraws(tmp_path):
    out = tmp_path / "turn"
    r = oceangnc(
        "run",
        "usv-turn",
        "--out",
        str(out),
        "--duration",
        "30",
        "--set",
        "environment.current.speed=0.1",
        "--quiet",
        "--json",
    )
    assert r.returncode == 0, r.stderr
    s = json.loads(r.stdout.strip().splitlines()[-1])
    assert s["scenario"] == "usv-turn" and s["duration_s"] == 30.0
    assert (out / "config.toml").read_text().count("speed = 0.1") == 1
    log = pq.read_table(out / "log.parquet")
    assert log.column_names[0] == "t"
    assert {"usv.x", "usv.psi", "usv.u", "usv.thrust_port"} <= set(log.column_names)
    t = log.column("t").to_numpy()
    assert t[-1] == 30.0 and len(t) == 30 * 20 + 1  # 20 Hz log
    pngs = sorted(p.name for p in out.glob("*.png"))
    assert {"trajectory.png", "states.png", "actuators.png"} <= set(pngs)
    for p in out.glob("*.png"):
        p.unlink()
    r = oceangnc("plot", str(out))
    assert r.returncode == 0, r.stderr
    assert (out / "trajectory.png").stat().st_size > 1000


def test_bad_input_exits_2_with_one_line():
    r = oceangnc("run", "usv-turn", "--set", "environment.current.speed=9", "--quiet")
    assert r.returncode == 2
    err = r.stderr.strip()
    assert "\n" not in err and "environment.current.speed" in err and "Traceback" not in err
    r = oceangnc("run", "no-such-scenario")
    assert r.returncode == 2 and "known scenarios" in r.stderr


def test_diverged_run_exits_1_and_keeps_log(tmp_path):
    r = oceangnc("run", "usv-straight", "--set", "usv.m11=0.1", "--out", str(tmp_path / "d"), "--quiet")
    assert r.returncode == 1
    assert "diverged at t=" in r.stderr and "usv" in r.stderr and "Traceback" not in r.stderr
    assert pq.read_table(tmp_path / "d" / "log.parquet").num_rows >= 1


def test_config_file_run(tmp_path):
    cfg = tmp_path / "mine.toml"
    cfg.write_text(
        'scenario = "usv-straight"\n[sim]\nduration = 12.0\n[command]\nthrust_port_kgf = 20.0\nthrust_stbd_kgf = 20.0\n'
    )
    r = oceangnc("run", "--config", str(cfg), "--out", str(tmp_path / "o"), "--quiet", "--json", "--no-plots")
    assert r.returncode == 0, r.stderr
    s = json.loads(r.stdout.strip().splitlines()[-1])
    assert s["scenario"] == "usv-straight"
    assert abs(s["usv.steady_speed_mps"] - 0.8 * 20 / 30) < 0.01


def test_list_into_a_closed_pipe_ends_quietly():
    """``oceangnc list | head -1``: the reader goes away; no traceback, exit 0."""
    import subprocess
    import sys

    code = "import sys; from oceangnc.cli import main; sys.exit(main(['list']))"
    p = subprocess.Popen([sys.executable, "-c", code], stdout=subprocess.PIPE, stderr=subprocess.PIPE)
    p.stdout.close()  # the reader is gone before the command writes (it starts in ~0.1 s)
    err = p.stderr.read().decode()
    assert p.wait(timeout=60) == 0
    assert "Traceback" not in err and "Broken pipe" not in err
