"""Identity and housekeeping of the MAVLink vehicle (issue 28): AUTOPILOT_VERSION with the package version and
true capability bits, SET_MESSAGE_INTERVAL / GET_MESSAGE_INTERVAL / REQUEST_DATA_STREAM rates, TIMESYNC, a MAVFTP
NAK, SYS_STATUS bits, MISSION_CURRENT.total, the battery model; MAVProxy with its default modules connects without
"fence breach" and without waiting for FTP. 127.0.0.1 only, every wait bounded; message counts are bounded from
above only (a busy machine sends fewer, never more)."""

from __future__ import annotations

import json
import os
import shutil
import struct
import sys

import numpy as np
import pandas as pd
import pytest

from mavlink_gcs import GCS, MAVProxy, served
from oceangnc import __version__
from oceangnc.mavlink.protocol import mavlink as M
from oceangnc.mavlink.vehicle import MavlinkVehicle


@pytest.fixture
def vehicle(tmp_path):
    with served(out_root=tmp_path, speed=4.0) as vg:
        yield vg


def _count(g, kind, seconds):
    g.received.clear()
    g.pump(seconds)
    return sum(1 for m in g.received if m.get_type() == kind and m.get_srcSystem() == 1)


def test_autopilot_version_and_capabilities(vehicle):
    v, g = vehicle
    g.wait("HEARTBEAT", 3.0)
    g.mav.command_long_send(1, 1, M.MAV_CMD_REQUEST_MESSAGE, 0, M.MAVLINK_MSG_ID_AUTOPILOT_VERSION, 0, 0, 0, 0, 0, 0)
    assert g.ack(M.MAV_CMD_REQUEST_MESSAGE).result == M.MAV_RESULT_ACCEPTED
    av = g.wait("AUTOPILOT_VERSION", 3.0)
    major, minor, patch = (int(x) for x in __version__.split("+")[0].split(".")[:3])
    sw = av.flight_sw_version
    assert (sw >> 24, (sw >> 16) & 255, (sw >> 8) & 255) == (major, minor, patch) and sw != 0
    assert sw & 255 == M.FIRMWARE_VERSION_TYPE_OFFICIAL  # "0.1.0": a release
    caps = av.capabilities
    for bit in ("MISSION_INT", "PARAM_FLOAT", "COMMAND_INT", "SET_POSITION_TARGET_GLOBAL_INT", "MAVLINK2",
                "MISSION_FLOAT", "FLIGHT_TERMINATION", "PARAM_ENCODE_C_CAST"):  # fmt: skip
        assert caps & getattr(M, "MAV_PROTOCOL_CAPABILITY_" + bit), bit
    for bit in ("FTP", "MISSION_FENCE", "MISSION_RALLY", "TERRAIN", "SET_ATTITUDE_TARGET", "PARAM_ENCODE_BYTEWISE"):
        assert not caps & getattr(M, "MAV_PROTOCOL_CAPABILITY_" + bit), bit  # what it does not do
    assert av.uid == 1
    g.mav.command_long_send(1, 1, M.MAV_CMD_REQUEST_PROTOCOL_VERSION, 0, 1, 0, 0, 0, 0, 0, 0)
    assert g.ack(M.MAV_CMD_REQUEST_PROTOCOL_VERSION).result == M.MAV_RESULT_UNSUPPORTED  # as ArduPilot answers


def test_message_intervals_streams_timesync_ftp(vehicle):
    v, g = vehicle
    g.wait("HEARTBEAT", 3.0)
    gp = M.MAVLINK_MSG_ID_GLOBAL_POSITION_INT
    # SET_MESSAGE_INTERVAL: 2 Hz (default 10 Hz), read back with GET_MESSAGE_INTERVAL
    g.mav.command_long_send(1, 1, M.MAV_CMD_SET_MESSAGE_INTERVAL, 0, gp, 500000, 0, 0, 0, 0, 0)
    assert g.ack(M.MAV_CMD_SET_MESSAGE_INTERVAL).result == M.MAV_RESULT_ACCEPTED
    g.mav.command_long_send(1, 1, M.MAV_CMD_GET_MESSAGE_INTERVAL, 0, gp, 0, 0, 0, 0, 0, 0)
    assert g.wait("MESSAGE_INTERVAL", 3.0, lambda m: m.message_id == gp).interval_us == 500000
    n = _count(g, "GLOBAL_POSITION_INT", 3.0)
    assert 1 <= n <= 30, n  # 2 Hz a simulated second, 3 s of wall time at 4x: 24 (10 Hz would be 120)
    # -1 stops it, 0 restores the default
    g.mav.command_long_send(1, 1, M.MAV_CMD_SET_MESSAGE_INTERVAL, 0, gp, -1, 0, 0, 0, 0, 0)
    g.ack(M.MAV_CMD_SET_MESSAGE_INTERVAL)
    g.pump(0.3)
    assert _count(g, "GLOBAL_POSITION_INT", 1.5) == 0
    assert _count(g, "ATTITUDE", 0.5) >= 1  # the others go on
    g.mav.command_long_send(1, 1, M.MAV_CMD_SET_MESSAGE_INTERVAL, 0, gp, 0, 0, 0, 0, 0, 0)
    g.ack(M.MAV_CMD_SET_MESSAGE_INTERVAL)
    assert v.rates["GLOBAL_POSITION_INT"] == 10.0
    # a message it does not stream, a non-finite interval
    g.mav.command_long_send(1, 1, M.MAV_CMD_SET_MESSAGE_INTERVAL, 0, M.MAVLINK_MSG_ID_RAW_IMU, 1000, 0, 0, 0, 0, 0)
    assert g.ack(M.MAV_CMD_SET_MESSAGE_INTERVAL).result == M.MAV_RESULT_UNSUPPORTED
    g.mav.command_long_send(1, 1, M.MAV_CMD_SET_MESSAGE_INTERVAL, 0, gp, float("nan"), 0, 0, 0, 0, 0)
    assert g.ack(M.MAV_CMD_SET_MESSAGE_INTERVAL).result == M.MAV_RESULT_DENIED
    # REQUEST_DATA_STREAM (MAVProxy's and QGroundControl's way with ArduPilot): EXTRA1 (ATTITUDE) at 1 Hz
    g.mav.request_data_stream_send(1, 1, M.MAV_DATA_STREAM_EXTRA1, 1, 1)
    g.pump(0.3)
    assert _count(g, "ATTITUDE", 3.0) <= 15 and v.rates["ATTITUDE"] == 1.0  # 1 Hz at 4x: 12 (4 Hz: 48)
    g.mav.request_data_stream_send(1, 1, M.MAV_DATA_STREAM_EXTRA1, 4, 0)  # start_stop 0: stop
    g.pump(0.3)
    assert _count(g, "ATTITUDE", 1.5) == 0
    g.mav.request_data_stream_send(1, 1, M.MAV_DATA_STREAM_ALL, 4, 1)
    g.pump(0.5)
    assert all(v.rates[k] == 4.0 for k in ("ATTITUDE", "GLOBAL_POSITION_INT", "SYS_STATUS", "VFR_HUD"))
    assert v.rates["HEARTBEAT"] == 1.0  # not a stream: always 1 Hz
    # TIMESYNC: a request (tc1 = 0) is answered with ts1 echoed and the vehicle's clock in tc1
    g.mav.timesync_send(0, 123456789)
    ts = g.wait("TIMESYNC", 3.0, lambda m: m.ts1 == 123456789)
    assert ts.tc1 > 0
    # MAVFTP: OpenFileRO @PARAM/param.pck is answered at once with a NAK (file not found), seq + 1
    path = b"@PARAM/param.pck"
    hdr = struct.pack("<HBBBBBBI", 41, 0, 4, len(path), 0, 0, 0, 0)
    g.mav.file_transfer_protocol_send(0, 1, 1, list(hdr + path) + [0] * (251 - 12 - len(path)))
    ftp = g.wait("FILE_TRANSFER_PROTOCOL", 3.0)
    seq, _, opcode, size, req, _, _, _ = struct.unpack("<HBBBBBBI", bytes(ftp.payload[:12]))
    assert (seq, opcode, size, req, ftp.payload[12]) == (42, 129, 1, 4, 10)
    assert ftp.target_system == 255 and ftp.target_component == 190


def test_sys_status_mission_current_battery(vehicle):
    v, g = vehicle
    st = g.wait("SYS_STATUS", 3.0)
    fence = M.MAV_SYS_STATUS_GEOFENCE
    assert st.onboard_control_sensors_health & fence and not st.onboard_control_sensors_present & fence
    for bit in (M.MAV_SYS_STATUS_PREARM_CHECK, M.MAV_SYS_STATUS_SENSOR_BATTERY, M.MAV_SYS_STATUS_SENSOR_GPS):
        assert st.onboard_control_sensors_present & bit and st.onboard_control_sensors_health & bit
    assert 26.0 < st.voltage_battery / 1000 < 27.3 and st.battery_remaining == 100  # 8 LiFePO4 cells, full
    mc = g.wait("MISSION_CURRENT", 3.0)
    assert mc.total == len(v.mission) - 1 == 4 and mc.seq == 1  # the route's 4 waypoints (home not counted)
    assert mc.mission_state == M.MISSION_STATE_NOT_STARTED
    bs = g.wait("BATTERY_STATUS", 3.0)
    assert bs.voltages[7] == bs.voltages[0] and bs.voltages[8] == 65535 and bs.battery_remaining == 100
    # the e-stop makes the vehicle unarmable: the pre-arm bit's health follows
    g.mav.command_long_send(1, 1, M.MAV_CMD_DO_FLIGHTTERMINATION, 0, 1, 0, 0, 0, 0, 0, 0)
    g.ack(M.MAV_CMD_DO_FLIGHTTERMINATION)
    st = g.wait("SYS_STATUS", 3.0, lambda m: not m.onboard_control_sensors_health & M.MAV_SYS_STATUS_PREARM_CHECK)
    assert v.estop


def test_battery_model_follows_the_thrusters(tmp_path):
    """Energy drawn = the integral of the thrusters' electrical power P_max (|T| / T_max)^1.5 each plus the
    hotel load, computed here from the run's log; the state of charge falls by the charge drawn."""
    now = [0.0]
    v = MavlinkVehicle("usv-remote", listen="udp:127.0.0.1:0", out_root=tmp_path, clock=lambda: now[0])
    v._arm(True)
    assert v._set_mode(10, "test") == M.MAV_RESULT_ACCEPTED
    while v.sim.t < 120.0:
        now[0] += 0.02
        v.step_once()
    v.close()
    df = pd.read_parquet(v.run_dir / "log.parquet")
    c = v.cfg_mav
    t_max = v.cfg.usv.max_thrust_kgf * 9.80665
    p = c.hotel_power_w + sum(c.thruster_power_w * np.minimum(1, df[k].abs() / t_max) ** 1.5
                              for k in ("usv.thrust_port", "usv.thrust_stbd"))  # fmt: skip
    e = float(np.sum(0.5 * (p.values[1:] + p.values[:-1]) * np.diff(df["t"].values)))
    assert e > 120.0 * 500  # the boat cruised: well above the hotel load
    assert v.battery.energy_j == pytest.approx(e, rel=0.03)
    soc_drop = v.battery.charge_ah / c.battery_capacity_ah
    assert 1.0 - v.battery.soc == pytest.approx(soc_drop, rel=1e-9) and soc_drop > 0.005
    assert df["mavlink.batt_soc"].iloc[-1] == pytest.approx(v.battery.soc, abs=1e-3)
    assert df["mavlink.batt_v"].iloc[-1] < df["mavlink.batt_v"].iloc[0]
    summary = json.loads((v.run_dir / "summary.json").read_text())
    endurance = summary["battery"]["endurance_h_at_mean_power"]
    assert 0.5 < endurance < 5.0 and summary["params"]["BATT_CAPACITY"] == 100000


MAVPROXY = shutil.which("mavproxy.py") or os.path.join(os.path.dirname(sys.executable), "mavproxy.py")


@pytest.mark.skipif(not os.path.exists(MAVPROXY), reason="mavproxy.py not installed")
def test_mavproxy_default_modules_no_fence_breach_no_ftp_wait(tmp_path):
    pytest.importorskip("MAVProxy")
    v = MavlinkVehicle("usv-remote", listen="udp:127.0.0.1:0", speed=1.0, out_root=tmp_path)
    v.start()
    mp = MAVProxy(MAVPROXY, v.address[1], cwd=tmp_path)
    expect = mp.expect

    try:
        t_detect = expect("Detected vehicle 1:1", 60.0)
        t_params = expect(f"Received {len(v.params)} parameters", 30.0)
        # the FTP attempt got its NAK: no retries until a timeout (MAVProxy retries 10 times before giving up)
        assert t_params - t_detect < 15.0
        mp.send("status SYS_STATUS")
        mp.collect(3.0)  # what it prints over three SYS_STATUS periods
    finally:
        mp.close()
        v.stop()
    out = mp.output()
    assert "fence breach" not in out.lower(), out
    assert "timed out" not in out and "FTP: retry" not in out, out
    assert v.counts["rx_bad"] == 0 and v.counts["ftp_naks"] >= 1  # MAVProxy did try MAVFTP first


def test_uuv_system_2_answers_version_params_mission_arm(tmp_path):
    """combined-survey: QGroundControl creates vehicle 2 (the towed UUV) and asks it for its version, its
    parameters and its mission; every request gets its answer from system 2."""
    v = MavlinkVehicle("combined-survey", listen="udp:127.0.0.1:0", speed=1.0, out_root=None)
    v.start()
    g = GCS(v.address)
    try:
        hb = g.wait("HEARTBEAT", 5.0, sysid=2)
        assert hb.type == M.MAV_TYPE_SUBMARINE and hb.custom_mode == 19  # ArduSub boots in MANUAL

        def cmd(command, *p, seconds=3.0):
            p = list(p) + [0.0] * (7 - len(p))
            g.mav.command_long_send(2, 1, command, 0, *p)
            return g.wait("COMMAND_ACK", seconds, lambda m: m.command == command, sysid=2).result

        assert cmd(M.MAV_CMD_REQUEST_MESSAGE, M.MAVLINK_MSG_ID_AUTOPILOT_VERSION) == M.MAV_RESULT_ACCEPTED
        av = g.wait("AUTOPILOT_VERSION", 3.0, sysid=2)
        assert av.flight_sw_version >> 8 != 0 and av.uid == 2
        g.mav.param_request_list_send(2, 1)
        first = g.wait("PARAM_VALUE", 3.0, sysid=2)
        got = {first.param_index: first}
        while len(got) < first.param_count:
            m = g.wait("PARAM_VALUE", 3.0, sysid=2)
            got[m.param_index] = m
        names = {m.param_id for m in got.values()}
        assert {"SYSID_THISMAV", "FOLL_OFS_X", "FOLL_OFS_Y"} <= names and "CRUISE_SPEED" not in names
        g.mav.param_set_send(2, 1, b"FOLL_OFS_X", -9.0, M.MAV_PARAM_TYPE_REAL32)
        assert g.wait("PARAM_VALUE", 3.0, lambda m: m.param_id == "FOLL_OFS_X", sysid=2).param_value == -9.0
        lf = next(b for b in v.sim.blocks if type(b).__name__ == "LeaderFollower")
        assert lf.lx_d == -9.0  # the station behind the USV in the running leader-follower law
        g.mav.mission_request_list_send(2, 1, 0)
        assert g.wait("MISSION_COUNT", 3.0, sysid=2).count == 1  # home only (ArduPilot's item 0)
        g.mav.mission_count_send(2, 1, 3, 0)
        assert g.wait("MISSION_REQUEST_INT", 3.0, sysid=2).seq == 0  # an upload (tests/test_mavlink_ardusub.py)
        assert cmd(M.MAV_CMD_DO_SET_MODE, 1, 2) == M.MAV_RESULT_ACCEPTED  # ALT_HOLD: the winch holds the depth
        assert cmd(M.MAV_CMD_DO_SET_MODE, 1, 7) == M.MAV_RESULT_DENIED  # CIRCLE: not flown
        assert cmd(M.MAV_CMD_COMPONENT_ARM_DISARM, 1) == M.MAV_RESULT_ACCEPTED
        assert v.armed
        g.wait("HEARTBEAT", 3.0, lambda m: m.base_mode & M.MAV_MODE_FLAG_SAFETY_ARMED, sysid=2)
        assert cmd(M.MAV_CMD_NAV_TAKEOFF) == M.MAV_RESULT_UNSUPPORTED
        assert len(v.mission) == 4  # the USV's mission is untouched by system 2's traffic
    finally:
        g.close()
        v.stop()
