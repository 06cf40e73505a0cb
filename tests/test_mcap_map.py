"""MCAP with a map (issue 39): every run with a geographic origin exports a ``foxglove.LocationFix``
channel per body, valid against Foxglove's published schema (tests/data/foxglove/LocationFix.json), and
its log times start at the run's real start: a MAVLink session's wall clock (its origin written to the
run's config), or an imported log's own clock (a real ROV's QGroundControl tlog, tests/data/public)."""

from __future__ import annotations

import json
import subprocess
import sys
import time
from pathlib import Path

import pytest

from oceangnc.io.importers import import_log
from oceangnc.io.importers.core import write_run

DATA = Path(__file__).parent / "data"
SCHEMA = json.loads((DATA / "foxglove" / "LocationFix.json").read_text())


def _gps(path: Path) -> dict[str, list]:
    from mcap.reader import make_reader

    out: dict[str, list] = {}
    with open(path, "rb") as f:
        for schema, channel, msg in make_reader(f).iter_messages():
            if channel.topic.endswith("/gps") and not channel.topic.startswith("/signals/"):
                assert schema.name == "foxglove.LocationFix"
                out.setdefault(channel.topic, []).append((msg.log_time, json.loads(msg.data)))
    return out


def _valid(fixes: list) -> None:
    jsonschema = pytest.importorskip("jsonschema")
    for _, m in fixes[:: max(1, len(fixes) // 50)]:
        jsonschema.validate(m, SCHEMA)


def test_imported_rov_tlog_exports_its_track_at_its_own_time(tmp_path):
    pytest.importorskip("mcap")
    pytest.importorskip("pymavlink")
    from pymavlink import mavutil

    from oceangnc.view.mcap_export import export_mcap

    tlog = DATA / "public" / "ardusub_blueos_small.tlog"
    res = import_log(tlog, rate=10.0)
    write_run(res, tmp_path / "imp")
    gps = _gps(export_mcap(tmp_path / "imp"))
    assert set(gps) == {"/usv/gps"}
    _valid(gps["/usv/gps"])
    # the first record of the tlog, by pymavlink: its UNIX stamp (QGC writes the receive time)
    conn = mavutil.mavlink_connection(str(tlog))
    first = conn.recv_match(type="GLOBAL_POSITION_INT")
    t_rec = first._timestamp
    t0 = gps["/usv/gps"][0][0] * 1e-9 - res.df["t"].iloc[0]
    assert abs(t0 - res.report["start_unix_s"]) < 1e-3
    assert abs(res.report["start_unix_s"] - t_rec) < 600, (res.report["start_unix_s"], t_rec)  # same session
    lat0, lon0 = res.report["origin_deg"]
    m = gps["/usv/gps"][5][1]
    assert abs(m["latitude"] - lat0) < 0.01 and abs(m["longitude"] - lon0) < 0.01


def test_mavlink_session_exports_gps_at_its_wall_clock(tmp_path):
    pytest.importorskip("mcap")
    from oceangnc.view.mcap_export import export_mcap

    before = time.time()
    cmd = [sys.executable, "-m", "oceangnc", "mavlink", "--listen", "udp:127.0.0.1:14677", "--speed", "20"]
    cmd += ["--duration", "2", "--out", str(tmp_path), "--quiet", "--set", "mavlink.origin_lat_deg=59.9"]
    subprocess.run(cmd, check=True, timeout=600, capture_output=True)
    after = time.time()
    (run,) = list(tmp_path.glob("mavlink-*"))
    cfg = (run / "config.toml").read_text()
    assert "[mavlink]" in cfg and "origin_lat_deg = 59.9" in cfg
    gps = _gps(export_mcap(run))
    assert "/usv/gps" in gps
    _valid(gps["/usv/gps"])
    t_first = gps["/usv/gps"][0][0] * 1e-9
    assert before <= t_first <= after
    assert abs(gps["/usv/gps"][0][1]["latitude"] - 59.9) < 1e-3
