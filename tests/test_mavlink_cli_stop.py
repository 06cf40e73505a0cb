"""``oceangnc mavlink`` ends like ``run`` (issue 41): SIGTERM writes summary.json and compacts the log; the
start-up message names the mode the vehicle is in; ``--params`` reads only a bounded regular file."""

from __future__ import annotations

import json
import os
import signal
import subprocess
import sys
import time
from pathlib import Path

import pytest

from oceangnc.cli import main
from oceangnc.io.logs import list_parts
from oceangnc.mavlink.params import MAX_PARAM_FILE_BYTES

ROOT = Path(__file__).resolve().parents[1]


def _env() -> dict:
    env = dict(os.environ)
    env["PYTHONPATH"] = str(ROOT / "src") + os.pathsep + env.get("PYTHONPATH", "")
    return env


def _start(tmp_path, scenario: str) -> subprocess.Popen:
    return subprocess.Popen(
        [sys.executable, "-m", "oceangnc", "mavlink", scenario, "--listen", "udp:127.0.0.1:0", "--out",
         str(tmp_path), "--speed", "5"],
        stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True, env=_env(), cwd=tmp_path,
    )  # fmt: skip


def _wait_serving(proc: subprocess.Popen, seconds: float = 240.0) -> list[str]:
    """The vehicle's printed lines up to "Ctrl-C to stop" (it is serving from then on)."""
    lines: list[str] = []
    t_end = time.monotonic() + seconds
    while time.monotonic() < t_end:
        line = proc.stdout.readline()
        if not line:
            break
        lines.append(line)
        if "Ctrl-C to stop" in line:
            return lines
    proc.kill()
    raise AssertionError(f"the vehicle did not start: {lines} {proc.stderr.read()}")


def test_sigterm_writes_the_summary_and_compacts_the_log(tmp_path):
    proc = _start(tmp_path, "usv-remote")
    try:
        _wait_serving(proc)
        time.sleep(2.5)  # a few log parts written at --speed 5
        proc.send_signal(signal.SIGTERM)
        out, err = proc.communicate(timeout=60)
    finally:
        if proc.poll() is None:
            proc.kill()
    assert proc.returncode == 143, err
    assert "Traceback" not in err
    (run,) = tmp_path.glob("mavlink-usv-remote-*")
    summary = json.loads((run / "summary.json").read_text())
    assert summary["status"] == "interrupted" and summary["signal"] == "SIGTERM"
    assert summary["duration_s"] > 1.0
    assert len(list_parts(run / "log.parquet")) == 1, "the log was not compacted"
    assert "summary.json status: interrupted" in out


def test_rov_start_up_message_names_ardusubs_boot_mode(tmp_path):
    """rov-station-keeping boots in ArduSub's MANUAL (docs, summary): the start-up line says so, not HOLD."""
    proc = _start(tmp_path, "rov-station-keeping")
    try:
        lines = _wait_serving(proc)
        proc.send_signal(signal.SIGTERM)
        proc.communicate(timeout=60)
    finally:
        if proc.poll() is None:
            proc.kill()
    up = next(line for line in lines if "vehicle up" in line)
    assert "disarmed, MANUAL" in up and "HOLD" not in up
    (run,) = tmp_path.glob("mavlink-rov-station-keeping-*")
    assert json.loads((run / "summary.json").read_text())["mode_at_end"] == "MANUAL"


def _fifo(tmp_path):
    p = tmp_path / "fifo.param"
    os.mkfifo(p)
    return p


def _big(tmp_path):
    p = tmp_path / "big.param"
    p.write_text("CRUISE_SPEED 1\n" * (MAX_PARAM_FILE_BYTES // 15 + 1))
    return p


def _binary(tmp_path):
    p = tmp_path / "bin.param"
    p.write_bytes(b"CRUISE_SPEED \xff\xfe\n")
    return p


@pytest.mark.parametrize(
    "make, says",
    [
        (lambda tmp: Path("/dev/zero"), "not a regular file"),
        (_fifo, "not a regular file"),
        (lambda tmp: tmp, "not a regular file"),
        (_big, "bytes"),
        (_binary, "not UTF-8"),
    ],
)
def test_params_file_is_a_bounded_regular_file(tmp_path, capsys, make, says):
    path = make(tmp_path)
    rc = main(["mavlink", "--params", str(path), "--listen", "udp:127.0.0.1:0", "--out", str(tmp_path / "o")])
    err = capsys.readouterr().err
    assert rc == 2
    lines = err.strip().splitlines()
    assert len(lines) == 1 and lines[0].startswith("error: --params") and says in lines[0], err
    assert not (tmp_path / "o").exists()
