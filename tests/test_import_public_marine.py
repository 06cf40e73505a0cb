"""Import of public marine logs nobody on the project wrote (tests/data/public/README.md: source, licence).

- ``ardusub_small.BIN``: an ArduSub 4.1.0 DataFlash log of a real ROV (clydemcqueen/ardusub_log_tools,
  ``testing/small.BIN``, MIT): no GPS; the depth is ``-CTUN.Alt``, compared with pymavlink's own reading.
- ``ardusub_blueos_small.tlog``: a QGroundControl telemetry log of a BlueOS ROV (same repository,
  ``testing/small.tlog``): its first system-1 heartbeat comes from the camera manager (component 100,
  MAV_TYPE_CAMERA); the autopilot's (component 1) types it as a submarine; the depth
  (GLOBAL_POSITION_INT.relative_alt) is kept where GPS_RAW_INT has no fix, compared with pymavlink.
- ``rosbag2_service_events/``: rosbag2's own test bag with service events (ros2/rosbag2,
  ``rosbag2_tests/resources/mcap/bag_with_topics_and_service_events``, Apache-2.0), which rosbags'
  AnyReader cannot open: the topics are read, the service channels skipped with a note (issue 39).
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from oceangnc.cli import main
from oceangnc.io.importers import import_log

PUBLIC = Path(__file__).parent / "data" / "public"
BIN = PUBLIC / "ardusub_small.BIN"
TLOG = PUBLIC / "ardusub_blueos_small.tlog"
BAG = PUBLIC / "rosbag2_service_events"


def _pymavlink(path: Path, kind: str, system: int | None = None) -> list:
    from pymavlink import mavutil

    conn = mavutil.mavlink_connection(str(path))
    out = []
    while (m := conn.recv_match(type=kind)) is not None:
        if system is None or m.get_srcSystem() == system:
            out.append(m)
    return out


def test_ardusub_dataflash_keeps_the_depth_as_pymavlink_reads_it():
    pytest.importorskip("pymavlink")
    res = import_log(BIN, rate=10.0)
    assert res.report["vehicle"]["type"] == "submarine" and "usv.z" in res.df.columns
    ctun = _pymavlink(BIN, "CTUN")
    assert ctun, "the log has CTUN records"
    tc = np.array([m.TimeUS * 1e-6 for m in ctun])
    depth = -np.array([m.Alt for m in ctun])
    t = res.df["t"].to_numpy() + res.report["t0_source_s"]
    ok = (t >= tc[0]) & (t <= tc[-1])
    assert ok.sum() > 0.9 * len(t)
    err = np.abs(res.df["usv.z"].to_numpy()[ok] - np.interp(t[ok], tc, depth))
    assert err.max() < 1e-6, err.max()
    assert any("CTUN.Alt" in n for n in res.report["notes"])


def test_blueos_tlog_is_typed_by_the_autopilot_and_keeps_depth_without_a_fix():
    pytest.importorskip("pymavlink")
    beats = _pymavlink(TLOG, "HEARTBEAT", system=1)
    assert beats[0].get_srcComponent() != 1 and int(beats[0].type) == 30  # the camera's heartbeat comes first
    res = import_log(TLOG, rate=10.0)
    assert res.report["vehicle"]["type"] == "submarine", res.report["vehicle"]
    gp = _pymavlink(TLOG, "GLOBAL_POSITION_INT", system=1)
    tg = np.array([m.time_boot_ms * 1e-3 for m in gp])
    depth = -np.array([m.relative_alt * 1e-3 for m in gp])
    order = np.argsort(tg, kind="stable")
    tg, depth = tg[order], depth[order]
    t = res.df["t"].to_numpy() + res.report["t0_source_s"]
    z = res.df["usv.z"].to_numpy()
    no_fix = np.isnan(res.df["usv.x"].to_numpy()) & np.isfinite(z)
    assert no_fix.sum() > 10  # rows without a position still have their depth
    ok = np.isfinite(z) & (t >= tg[0]) & (t <= tg[-1])
    assert ok.sum() > 0.8 * len(t)
    # the resampled depth lies between the neighbouring samples pymavlink reads (10 Hz grid over ~3 Hz data)
    k = np.clip(np.searchsorted(tg, t[ok]), 1, tg.size - 1)
    lo, hi = np.minimum(depth[k - 1], depth[k]), np.maximum(depth[k - 1], depth[k])
    assert np.all((z[ok] >= lo - 1e-9) & (z[ok] <= hi + 1e-9))


def test_rosbag2_bag_with_service_events_reads_its_topics(tmp_path, capsys):
    pytest.importorskip("rosbags")
    from oceangnc.io.importers.formats.ros2_services import TopicsOnlyReader, service_channels

    assert service_channels(BAG) == ["/test_service1/_service_event", "/test_service2/_service_event"]
    reader = TopicsOnlyReader(BAG)
    try:
        topics = {c.topic for c in reader.connections}
        assert topics == {"/events/write_split", "/test_topic1", "/test_topic2"}
        msgs = [(c.topic, reader.deserialize(raw, c.msgtype)) for c, _, raw in reader.messages()]
    finally:
        reader.close()
    # metadata.yaml of the bag: one message on each test topic, none on /events/write_split
    assert sorted(t for t, _ in msgs) == ["/test_topic1", "/test_topic2"]
    assert all(hasattr(m, "string_value") for _, m in msgs)
    code = main(["import", str(BAG), "--out", str(tmp_path / "o")])
    err = capsys.readouterr().err.strip()
    assert code == 2 and len(err.splitlines()) == 1 and len(err) < 400, err
    assert "/test_topic1" in err and "service" in err and "--topic" in err
