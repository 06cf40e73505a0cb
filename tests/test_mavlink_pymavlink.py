"""The MAVLink vehicle driven by plain pymavlink (a client nobody here wrote): safety, modes, sticks,
failsafe, malformed floods, mission protocol. Everything on 127.0.0.1, every wait bounded."""

from __future__ import annotations

import math
import time

import numpy as np
import pandas as pd
import pytest

from mavlink_gcs import GCS, served
from oceangnc.io.geo import latlon_to_ned, ned_to_latlon
from oceangnc.mavlink.protocol import mavlink as M
from oceangnc.mavlink.vehicle import MavlinkVehicle


@pytest.fixture
def vehicle(tmp_path):
    with served(out_root=tmp_path, speed=4.0) as vg:
        yield vg


def _mode(g, num, seconds=3.0):
    g.mav.set_mode_send(1, M.MAV_MODE_FLAG_CUSTOM_MODE_ENABLED, num)
    return g.wait("HEARTBEAT", seconds, lambda m: m.custom_mode == num)


def test_geo_round_trip():
    lat, lon = ned_to_latlon(1234.5, -987.6, 59.9, 10.7)
    n, e = latlon_to_ned(lat, lon, 59.9, 10.7)
    assert abs(n - 1234.5) < 1e-6 and abs(e + 987.6) < 1e-6
    # one minute of latitude at 60 deg: the WGS-84 meridian radius 6 383 453 m x pi / 10800 = 1856.9 m
    n, _ = latlon_to_ned(60.0 + 1 / 60, 0.0, 60.0, 0.0)
    assert abs(n - 1856.9) < 0.1


def test_disarmed_at_start_then_arm_manual_stick_and_modes(vehicle):
    v, g = vehicle
    hb = g.wait("HEARTBEAT", 3.0)
    assert hb.type == M.MAV_TYPE_SURFACE_BOAT and hb.autopilot == M.MAV_AUTOPILOT_ARDUPILOTMEGA
    assert not hb.base_mode & M.MAV_MODE_FLAG_SAFETY_ARMED
    assert hb.custom_mode == 4  # Rover HOLD
    # disarmed: a full stick in MANUAL moves nothing (thrust zero)
    _mode(g, 0)
    g.pump(1.0, stick=(1000, 0))
    assert v.sim.bus["usv.thrust_port"] == 0.0 and v.sim.bus["usv.speed"] < 1e-6
    # arm: the same stick drives the boat ahead (open loop, 36 kgf per thruster)
    g.mav.command_long_send(1, 1, M.MAV_CMD_COMPONENT_ARM_DISARM, 0, 1, 0, 0, 0, 0, 0, 0)
    assert g.ack(M.MAV_CMD_COMPONENT_ARM_DISARM).result == M.MAV_RESULT_ACCEPTED
    g.pump(2.0, stick=(1000, 0))
    assert v.sim.bus["usv.thrust_port"] > 300.0 and v.sim.bus["usv.speed"] > 0.5
    hb = g.wait("HEARTBEAT", 2.0)
    assert hb.base_mode & M.MAV_MODE_FLAG_SAFETY_ARMED and hb.custom_mode == 0
    vfr = g.wait("VFR_HUD", 2.0)
    assert vfr.throttle > 80 and vfr.groundspeed > 0.5
    # yaw stick to starboard: yaw rate positive, heading increases
    psi0 = v.sim.bus["usv.psi"]
    g.pump(1.5, stick=(500, 1000))
    assert v.sim.bus["usv.r"] > 0.05 and v.sim.bus["usv.psi"] > psi0
    # RC_CHANNELS_OVERRIDE (Rover: ch3 throttle, ch1 steering, 1500 +- 400 us): full astern, no steering
    for _ in range(10):
        g.mav.rc_channels_override_send(1, 1, 1500, 0, 1100, 0, 0, 0, 0, 0)
        g.pump(0.05)
    g.pump(0.5)
    assert v.stick == (-1.0, 0.0) and v.sim.bus["usv.thrust_port"] < -100.0
    # ACRO (1): the stick is a yaw-rate setpoint (20 deg/s at full stick)
    _mode(g, 1)
    g.pump(3.0, stick=(0, 1000))
    assert abs(math.degrees(v.sim.bus["usv.r_d"]) - 20.0) < 1e-6
    # HOLD (4): setpoints zero whatever the stick says
    _mode(g, 4)
    g.pump(0.5, stick=(1000, 1000))
    assert v.sim.bus["usv.u_d"] == 0.0 and v.sim.bus["usv.r_d"] == 0.0
    # a Rover mode this vehicle does not fly (STEERING 3) is denied and counted, the mode stays HOLD
    g.mav.command_long_send(1, 1, M.MAV_CMD_DO_SET_MODE, 0, 1, 3, 0, 0, 0, 0, 0)
    assert g.ack(M.MAV_CMD_DO_SET_MODE).result == M.MAV_RESULT_DENIED
    assert g.wait("HEARTBEAT", 2.0).custom_mode == 4
    assert v.counts["rx_out_of_range"] >= 1


def test_heartbeat_loss_in_manual_goes_to_hold_within_1s(vehicle):
    v, g = vehicle
    g.wait("HEARTBEAT", 3.0)
    g.mav.command_long_send(1, 1, M.MAV_CMD_COMPONENT_ARM_DISARM, 0, 1, 0, 0, 0, 0, 0, 0)
    g.ack(M.MAV_CMD_COMPONENT_ARM_DISARM)
    _mode(g, 0)
    g.pump(1.5, stick=(800, 0))
    assert v.sim.bus["usv.speed"] > 0.3 and v.mode == 0
    g.send_heartbeats = False  # the ground station goes silent (no heartbeat, no stick)
    hb = g.wait("HEARTBEAT", 10.0, lambda m: m.custom_mode == 4)  # a bound on the test, not a rate
    # the heartbeat reporting HOLD left within 1 s of the last GCS packet (HEARTBEATs are sent at 1 Hz,
    # so also check the vehicle's own switch time through its event log and its state)
    assert v.stick_failsafe and v.mode == 4
    assert hb.system_status == M.MAV_STATE_CRITICAL
    assert any("Failsafe" in s for _, s in v.events)
    # the stick stream stopped with the link: the stick failsafe (RC_OVERRIDE_TIME, 3 s) switched,
    # before the GCS failsafe (gcs_timeout_s, 5 s) could (the wall-time bound is the benchmark's)
    t_fs = next(t for t, s in v.events if "Failsafe" in s)
    assert any("stick stream lost" in s for _, s in v.events)
    # stay silent a little longer, so that the failsafe spans logged rows whenever the 1 Hz heartbeat
    # reporting HOLD came right after the switch (else the link came back within one log period)
    g.pump(0.5)
    assert v.stick_failsafe
    g.send_heartbeats = True
    g.pump(1.0)
    # heartbeats back: the mode stays HOLD, and nothing claims the GCS link was lost or restored (it was
    # the stick that stopped; in HOLD the GCS failsafe does not watch); the operator's mode change clears it
    assert v.stick_failsafe and v.mode == 4 and not v.failsafe
    assert not any("GCS link" in s for _, s in v.events)
    assert v.sim.bus["usv.u_d"] == 0.0
    v.stop()
    df = pd.read_parquet(v.run_dir / "log.parquet")
    fs = df[df["console.failsafe"] > 0]
    assert len(fs) and abs(fs["t"].iloc[0] - t_fs) < 0.2  # the failsafe is in the log at the event's time
    assert (fs["mavlink.mode"] == 4).all()


def test_failsafe_delay_measured_in_wall_time(tmp_path):
    """Stick stream then silence: the vehicle's mode switches to HOLD no sooner than the stick timeout
    of wall time later (the upper bound, a rate, is the benchmark's: benchmarks/bench_mavlink.py)."""
    v = MavlinkVehicle("usv-remote", listen="udp:127.0.0.1:0", speed=2.0, out_root=None)
    v.start()
    g = GCS(v.address)
    try:
        g.wait("HEARTBEAT", 3.0)
        _mode(g, 1)
        g.pump(0.5, stick=(300, 0))
        g.send_heartbeats = False
        t_lost = time.monotonic()
        deadline = t_lost + 30.0  # generous: a loaded machine may be slow, only the lower bound is timed
        while v.mode != 4 and time.monotonic() < deadline:
            time.sleep(0.005)
        delay = time.monotonic() - g._t_last_stick  # from the last stick message sent
        assert v.mode == 4 and v.stick_failsafe
        c = v.cfg_mav
        assert delay >= max(c.stick_timeout_s, c.rc_override_time_s), f"failsafe after {delay:.3f} s"
    finally:
        g.close()
        v.stop()


def test_malformed_flood_is_counted_and_ignored(vehicle):
    v, g = vehicle
    g.wait("HEARTBEAT", 3.0)
    g.mav.command_long_send(1, 1, M.MAV_CMD_COMPONENT_ARM_DISARM, 0, 1, 0, 0, 0, 0, 0, 0)
    g.ack(M.MAV_CMD_COMPONENT_ARM_DISARM)
    _mode(g, 10)  # AUTO: the run goes on during the flood
    t0 = v.sim.t
    good = g.mav.heartbeat_encode(M.MAV_TYPE_GCS, 0, 0, 0, 0).pack(g.mav)
    bad_crc = bytearray(good)
    bad_crc[-1] ^= 0xFF
    unknown = bytearray(good)
    unknown[7] = 0xEE  # message id 238 (not in the dialect) with a MAVLink 2 header
    n = 0
    for i in range(300):
        g.raw(bytes(bad_crc))  # CRC error
        g.raw(b"\xfd\x09\x00")  # truncated header
        g.raw(bytes([i % 256]) * 40)  # garbage without a start byte
        g.raw(bytes(unknown))
        n += 4
        if i % 10 == 9:  # paced by the vehicle's reading: a busy machine must not drop datagrams
            sent_bad, sent_unknown = 3 * (i + 1), i + 1
            wait_until = time.monotonic() + 5.0
            while time.monotonic() < wait_until and (
                v.counts["rx_bad"] < sent_bad or v.counts["rx_unknown"] < sent_unknown
            ):
                time.sleep(0.002)
    g.mav.manual_control_send(1, 5000, 0, 0, 0, 0)  # out of range: counted, ignored
    g.mav.rc_channels_override_send(1, 1, 3000, 0, 1500, 0, 0, 0, 0, 0)  # PWM 3000: out of range
    g.pump(2.0)
    c = v.counts
    assert c["rx_bad"] >= 0.9 * 900, c  # bad CRC, truncated, garbage
    assert c["rx_unknown"] >= 0.9 * 300, c  # well-formed frames of an unknown message id
    assert c["rx_out_of_range"] >= 2
    assert not v.ended and v.mode == 10 and v.armed
    assert v.sim.t > t0 + 2.0  # the simulation kept running at about 4x
    hb = g.wait("HEARTBEAT", 2.0)
    assert hb.custom_mode == 10
    st = g.wait("SYS_STATUS", 2.0)
    assert st.errors_count1 >= 600 and st.drop_rate_comm > 0
    v.stop()  # the counters are in the run's log
    df = pd.read_parquet(v.run_dir / "log.parquet")
    assert df["mavlink.rx_bad"].iloc[-1] == c["rx_bad"] and df["mavlink.rx_unknown"].iloc[-1] == c["rx_unknown"]
    assert df["mavlink.rx_out_of_range"].iloc[-1] >= 2 and df["mavlink.rx_bad"].iloc[0] == 0


def test_estop_latched_and_arm_refused(vehicle):
    v, g = vehicle
    g.wait("HEARTBEAT", 3.0)
    g.mav.command_long_send(1, 1, M.MAV_CMD_COMPONENT_ARM_DISARM, 0, 1, 0, 0, 0, 0, 0, 0)
    g.ack(M.MAV_CMD_COMPONENT_ARM_DISARM)
    _mode(g, 0)
    g.pump(1.0, stick=(1000, 0))
    assert v.sim.bus["usv.thrust_port"] > 300
    g.mav.command_long_send(1, 1, M.MAV_CMD_DO_FLIGHTTERMINATION, 0, 1, 0, 0, 0, 0, 0, 0)
    assert g.ack(M.MAV_CMD_DO_FLIGHTTERMINATION).result == M.MAV_RESULT_ACCEPTED
    g.pump(0.3, stick=(1000, 0))
    assert v.sim.bus["usv.thrust_port"] == 0.0 and v.sim.bus["usv.thrust_stbd"] == 0.0
    hb = g.wait("HEARTBEAT", 2.0)
    assert hb.system_status == M.MAV_STATE_EMERGENCY and not hb.base_mode & M.MAV_MODE_FLAG_SAFETY_ARMED
    g.mav.command_long_send(1, 1, M.MAV_CMD_COMPONENT_ARM_DISARM, 0, 1, 0, 0, 0, 0, 0, 0)
    assert g.ack(M.MAV_CMD_COMPONENT_ARM_DISARM).result == M.MAV_RESULT_DENIED
    g.mav.command_long_send(1, 1, M.MAV_CMD_DO_FLIGHTTERMINATION, 0, 0, 0, 0, 0, 0, 0, 0)
    g.ack(M.MAV_CMD_DO_FLIGHTTERMINATION)
    g.mav.command_long_send(1, 1, M.MAV_CMD_COMPONENT_ARM_DISARM, 0, 1, 0, 0, 0, 0, 0, 0)
    assert g.ack(M.MAV_CMD_COMPONENT_ARM_DISARM).result == M.MAV_RESULT_ACCEPTED


def test_mission_upload_download_and_reached(tmp_path):
    v = MavlinkVehicle(
        "usv-remote",
        listen="udp:127.0.0.1:0",
        speed=20.0,
        out_root=tmp_path,
        mav={"origin_lat_deg": 59.9, "origin_lon_deg": 10.7},
    )
    v.start()
    g = GCS(v.address)
    try:
        g.wait("HEARTBEAT", 3.0)
        # an empty mission (home only): AUTO is refused, the scenario's own route is not flown behind our back
        g.mav.mission_clear_all_send(1, 1, 0)
        assert g.wait("MISSION_ACK", 3.0).type == M.MAV_MISSION_ACCEPTED
        g.mav.command_long_send(1, 1, M.MAV_CMD_DO_SET_MODE, 0, 1, 10, 0, 0, 0, 0, 0)
        assert g.ack(M.MAV_CMD_DO_SET_MODE).result == M.MAV_RESULT_DENIED
        pts = [(0.0, 0.0), (15.0, 0.0), (15.0, 15.0), (0.0, 15.0)]  # home + 3 waypoints (N, E m)
        g.mav.mission_count_send(1, 1, len(pts), 0)
        for seq, (n, e) in enumerate(pts):
            req = g.wait("MISSION_REQUEST_INT", 3.0, lambda m, s=seq: m.seq == s)
            lat, lon = ned_to_latlon(n, e, 59.9, 10.7)
            g.mav.mission_item_int_send(
                1,
                1,
                req.seq,
                M.MAV_FRAME_GLOBAL_RELATIVE_ALT_INT,
                M.MAV_CMD_NAV_WAYPOINT,
                0,
                1,
                0,
                0,
                0,
                0,
                round(lat * 1e7),
                round(lon * 1e7),
                0.0,
                0,
            )
        assert g.wait("MISSION_ACK", 3.0).type == M.MAV_MISSION_ACCEPTED
        # download gives the same items back
        g.mav.mission_request_list_send(1, 1, 0)
        assert g.wait("MISSION_COUNT", 3.0).count == 4
        g.mav.mission_request_int_send(1, 1, 2, 0)
        it = g.wait("MISSION_ITEM_INT", 3.0, lambda m: m.seq == 2)
        n, e = latlon_to_ned(it.x * 1e-7, it.y * 1e-7, 59.9, 10.7)
        assert abs(n - 15.0) < 0.02 and abs(e - 15.0) < 0.02
        g.mav.command_long_send(1, 1, M.MAV_CMD_COMPONENT_ARM_DISARM, 0, 1, 0, 0, 0, 0, 0, 0)
        g.ack(M.MAV_CMD_COMPONENT_ARM_DISARM)
        _mode(g, 10)
        last = g.wait("MISSION_ITEM_REACHED", 30.0, lambda m: m.seq == 3)
        assert last.seq == 3 and v.reached == [1, 2, 3]
        hb = g.wait("HEARTBEAT", 3.0, lambda m: m.custom_mode == 4)  # HOLD at the end, like ArduPilot
        assert hb.custom_mode == 4
        # the boat went round: the log has passed near each waypoint (acceptance radius 3 m)
        v.stop()
        df = pd.read_parquet(v.run_dir / "log.parquet")
        for n, e in pts[1:]:
            d = ((df["usv.x"] - n) ** 2 + (df["usv.y"] - e) ** 2) ** 0.5
            assert d.min() < 3.5
        assert df["mavlink.armed"].iloc[0] == 0.0 and df["mavlink.armed"].max() == 1.0
    finally:
        g.close()
        v.stop()


def test_combined_vehicle_reports_uuv_depth_and_cable_tension(tmp_path):
    v = MavlinkVehicle(
        "combined-survey", listen="udp:127.0.0.1:0", speed=1.0, out_root=tmp_path, tlog=tmp_path / "c.tlog"
    )
    v.start()
    g = GCS(v.address)
    try:
        hb = g.wait("HEARTBEAT", 5.0, sysid=2)
        assert hb.type == M.MAV_TYPE_SUBMARINE
        gp = g.wait("GLOBAL_POSITION_INT", 5.0, sysid=2)
        depth = v.sim.bus["uuv.z"]
        assert depth > 0.1 and abs(-gp.relative_alt / 1000 - depth) < 0.2
        nv = g.wait("NAMED_VALUE_FLOAT", 5.0, lambda m: m.name.rstrip("\x00") == "cable_T")
        assert nv.value > 0.0
        g.mav.mission_request_list_send(1, 1, 0)
        assert g.wait("MISSION_COUNT", 3.0).count == 1 + 3  # home + the scenario's 3 waypoints
        g.pump(1.0)
    finally:
        g.close()
        v.stop()
    # the UUV's telemetry read back from the .tlog (system 2, signals named uuv.*) against the run's log
    from oceangnc.io.importers import import_log

    truth = pd.read_parquet(v.run_dir / "log.parquet")
    res = import_log(
        tmp_path / "c.tlog", rate=5.0, system=2, body="uuv", origin=(v.cfg_mav.origin_lat_deg, v.cfg_mav.origin_lon_deg)
    )
    t = res.df["t"] + res.report["t0_source_s"]
    for col, tol in (("uuv.z", 0.01), ("uuv.x", 0.03), ("uuv.y", 0.03)):
        assert np.max(np.abs(res.df[col] - np.interp(t, truth["t"], truth[col]))) < tol, col


def test_combined_mission_feeds_the_pure_pursuit_guidance(tmp_path):
    """combined-survey's guidance is a PurePursuit block: a mission reaches it through the route hook, the USV
    (towing the UUV) reaches every item and the vehicle switches to HOLD without ending the run.
    A fake wall clock steps the vehicle (no sockets, no waiting)."""
    from oceangnc.mavlink.protocol import AUTO, HOLD

    now = [0.0]
    v = MavlinkVehicle("combined-survey", listen="udp:127.0.0.1:0", out_root=None, clock=lambda: now[0])
    assert v.route.kind == "pure_pursuit" and v.has_uuv
    v.mission = [v._item(0, 0.0, 0.0)] + [v._item(i + 1, n, e) for i, (n, e) in enumerate([(6.0, 6.0), (12.0, 2.0)])]
    v._arm(True)
    assert v._set_mode(AUTO, "test") == M.MAV_RESULT_ACCEPTED
    while v.sim.t < 120.0 and v.reached != [1, 2]:
        now[0] += 0.05
        v.step_once()
    assert v.reached == [1, 2], (v.reached, v.sim.t)
    assert v.mode == HOLD and not v.ended
    d = math.hypot(v.sim.bus["usv.x"] - 12.0, v.sim.bus["usv.y"] - 2.0)
    assert d < 2.5  # within the acceptance radius (2 m) plus the distance run since
    v.close()


def test_cli_serves_for_a_duration_and_keeps_the_log(tmp_path, capsys):
    from oceangnc.cli import main

    model = tmp_path / "identified.toml"
    model.write_text('[parameters]\n"usv.m11" = 31.5\n')
    assert (
        main(
            [
                "mavlink",
                "usv-remote",
                "--listen",
                "udp:127.0.0.1:0",
                "--speed",
                "20",
                "--duration",
                "10",
                "--quiet",
                "--out",
                str(tmp_path),
                "--set",
                "mavlink.origin_lat_deg=10.5",
                "--model",
                str(model),
            ]
        )
        == 0
    )
    (run,) = list(tmp_path.glob("mavlink-usv-remote-*"))
    assert "m11 = 31.5" in (run / "config.toml").read_text()  # the model file's parameters are the vehicle's
    df = pd.read_parquet(run / "log.parquet")
    assert df["t"].iloc[-1] == pytest.approx(10.0, abs=0.05)
    assert (df["mavlink.armed"] == 0).all() and (df["usv.thrust_port"] == 0).all()  # never armed: no thrust
    # the run folder also holds the telemetry stream as a .tlog, which `oceangnc import` reads back
    assert main(["import", str(run / "telemetry.tlog"), "--out", str(tmp_path / "imp")]) == 0
    imp = pd.read_parquet(tmp_path / "imp" / "log.parquet")
    # 10 s at 10 Hz per simulated second (the streams keep their rates in simulated time at 20x), no gap
    assert len(imp) > 80 and not imp["usv.x"].isna().any(), f"{int(imp['usv.x'].isna().sum())} NaN rows of usv.x"
    assert imp["usv.x"].abs().max() < 1e-2  # a boat at rest at the origin
    assert main(["mavlink", "usv-remote", "--listen", "udp:nowhere", "--quiet", "--out", str(tmp_path)]) == 2
    assert "expected udp:HOST:PORT" in capsys.readouterr().err
    assert main(["mavlink", "usv-remote", "--set", "mavlink.gcs_timeout_s=0", "--quiet", "--out", str(tmp_path)]) == 2
    assert "gcs_timeout_s" in capsys.readouterr().err


def _tlog_messages(path):
    """(simulated time, message type) of every frame of a .tlog the vehicle wrote (stamp - tlog_epoch)."""
    from pymavlink import mavutil

    log = mavutil.mavlink_connection(str(path))
    out = []
    while (m := log.recv_match()) is not None:
        out.append((m._timestamp - 1.7e9, m.get_type()))
    log.close()
    return out


def test_telemetry_keeps_its_rates_in_simulated_time_when_faster_than_real_time(tmp_path):
    """At 20x (loop passes 10 ms of wall time apart on a fake clock) the 10 Hz streams are 10 Hz per simulated
    second, each message sent at its own instant (the simulation is stopped there), so a .tlog of the run
    imports without gaps; wall-paced streams gave 0.5 Hz of simulated time. Below real time (0.5x) and after the
    end of the run, when simulated time crawls or stands still, the streams keep their rates per wall second."""
    from oceangnc.io.importers import resample
    from oceangnc.io.importers.formats.ardupilot import read_tlog

    now = [0.0]
    tlog = tmp_path / "t.tlog"
    v = MavlinkVehicle(
        "usv-remote", listen="udp:127.0.0.1:0", out_root=None, speed=20.0, duration=4.0, clock=lambda: now[0], tlog=tlog
    )
    while v.sim.t < 2.0 - 1e-9:
        now[0] += 0.01
        v.step_once()
    v._set_speedup(0.5)
    for _ in range(100):  # 1 s of wall time: 0.5 s simulated
        now[0] += 0.01
        v.step_once()
    v._set_speedup(20.0)
    while not v.ended:
        now[0] += 0.01
        v.step_once()
    for _ in range(350):  # 3.5 s of wall time after the end (simulated time stands at 4 s)
        now[0] += 0.01
        v.step_once()
    v.close()
    msgs = _tlog_messages(tlog)
    pos = np.array([t for t, k in msgs if k == "GLOBAL_POSITION_INT"])
    fast = pos[pos <= 2.0 + 1e-6]
    assert fast.size == 21 and np.allclose(fast, 0.1 * np.arange(21), atol=2e-6), fast  # 0, 0.1, ..., 2.0 s
    slow = pos[(pos > 2.0 + 1e-6) & (pos < 2.5 - 1e-6)]
    assert 8 <= slow.size <= 11, slow  # 10 Hz per wall second over 1 s of wall time (0.5 s simulated)
    after = pos[pos > 2.5 + 1e-6]
    assert np.diff(after).max() <= 0.1 + 2e-6 and after[-1] == pytest.approx(4.0, abs=2e-6)
    beats = [t for t, k in msgs if k == "HEARTBEAT"]
    assert sum(t >= 4.0 - 1e-6 for t in beats) >= 3, beats[-5:]  # 1 Hz per wall second after the end
    series, _ = read_tlog(tlog)
    cols, report = resample(series, 10.0)
    assert not report["gaps"] and not np.isnan(cols["usv.x"]).any()
    # the repeats at 4 s after the end share one stamp: counted as duplicates, never as a time jump (issue 39)
    assert report["jumps"] == [] and sum(report.get("duplicate_stamps", {}).values()) > 0


def test_scenario_without_stick_or_route_hook_holds_by_zero_thrust():
    """usv-waypoints-7 flies its own route and takes no stick: MANUAL / ACRO are refused, a mission upload
    is refused, AUTO runs the scenario's own guidance, and HOLD (like disarmed) zeroes the thrust."""
    from oceangnc.mavlink.protocol import ACRO, AUTO, HOLD, MANUAL

    now = [0.0]
    v = MavlinkVehicle("usv-waypoints-7", listen="udp:127.0.0.1:0", out_root=None, clock=lambda: now[0])
    assert not v.reads_stick and not v.route.available

    def run(seconds):
        t_end = v.sim.t + seconds
        while v.sim.t < t_end:
            now[0] += 0.05
            v.step_once()

    v._arm(True)
    assert v._set_mode(MANUAL, "test") == M.MAV_RESULT_DENIED and v._set_mode(ACRO, "test") == M.MAV_RESULT_DENIED
    run(3.0)
    assert v.mode == HOLD and v.sim.bus["usv.rpm"] == 0.0 and v.sim.bus["usv.u"] < 1e-9  # armed, HOLD: no thrust
    v._on_mission_count(M.MAVLink_mission_count_message(1, 1, 3, 0))
    assert len(v.mission) == 1 and any("Mission refused" in s for _, s in v.events)
    assert v._set_mode(AUTO, "test") == M.MAV_RESULT_ACCEPTED
    run(10.0)
    assert v.sim.bus["usv.rpm"] > 100.0 and v.sim.bus["usv.u"] > 1.0  # the scenario's own guidance drives
    v._set_mode(HOLD, "test")
    run(0.5)
    assert v.sim.bus["usv.rpm"] == 0.0
    v.close()
