"""ArduPilot Rover's modes as ground stations use them (issue 28): QGroundControl's Start Mission from a disarmed
vehicle (GUIDED, arm, MISSION_START), GUIDED go-to by DO_REPOSITION / MISSION_ITEM_INT current = 2 /
SET_POSITION_TARGET_GLOBAL_INT, DO_CHANGE_SPEED, RTL and SMART_RTL home, LOITER, DO_SET_HOME; and the failsafe
actions (FS_ACTION) that use them. Plain pymavlink clients on 127.0.0.1, every wait bounded; positions are
checked in the run's log."""

from __future__ import annotations

import math

import numpy as np
import pandas as pd
import pytest

from mavlink_gcs import GCS, qgc_connect, qgc_set_mode, qgc_start_mission, upload_mission
from oceangnc.io.geo import latlon_to_ned, ned_to_latlon
from oceangnc.mavlink.protocol import mavlink as M
from oceangnc.mavlink.vehicle import MavlinkVehicle

HOLD, LOITER, AUTO, RTL, SMART_RTL, GUIDED = 4, 5, 10, 11, 12, 15
LAT0, LON0 = 59.9, 10.7


def _vehicle(tmp_path, speed=10.0, **mav):
    v = MavlinkVehicle(
        "usv-remote",
        listen="udp:127.0.0.1:0",
        speed=speed,
        out_root=tmp_path,
        mav={"origin_lat_deg": LAT0, "origin_lon_deg": LON0, **mav},
    )
    return v.start()


def _ll(n, e):
    lat, lon = ned_to_latlon(n, e, LAT0, LON0)
    return round(lat * 1e7), round(lon * 1e7)


def _text(g, text, seconds):
    """Wait for the vehicle's STATUSTEXT containing ``text`` (a bound on the test, not a rate)."""
    return g.wait("STATUSTEXT", seconds, lambda m: text in m.text)


def _track(v):
    df = pd.read_parquet(v.run_dir / "log.parquet")
    return df


def _dist(df, n, e):
    return np.hypot(df["usv.x"] - n, df["usv.y"] - e)


def test_qgc_connect_and_start_mission_from_disarmed(tmp_path):
    v = _vehicle(tmp_path, speed=12.0)
    g = GCS(v.address)  # system 255, component 190: QGroundControl's ids
    try:
        info = qgc_connect(g)
        assert info["acks"][(M.MAV_CMD_REQUEST_MESSAGE, M.MAVLINK_MSG_ID_AUTOPILOT_VERSION)] == M.MAV_RESULT_ACCEPTED
        assert "CRUISE_SPEED" in info["params"] and info["count0"].count == 1 + 4  # home + the scenario's route
        pts = [(0.0, 0.0), (15.0, 0.0), (15.0, 15.0), (0.0, 15.0)]
        upload_mission(g, pts, LAT0, LON0)
        hb = g.wait("HEARTBEAT", 3.0)
        assert not hb.base_mode & M.MAV_MODE_FLAG_SAFETY_ARMED and hb.custom_mode == HOLD
        qgc_start_mission(g)
        assert v.mode == AUTO and v.armed
        last = g.wait("MISSION_ITEM_REACHED", 60.0, lambda m: m.seq == 3)
        assert last.seq == 3 and v.reached == [1, 2, 3]
        g.wait("HEARTBEAT", 5.0, lambda m: m.custom_mode == HOLD)  # mission complete: HOLD, like ArduPilot
    finally:
        g.close()
        v.stop()
    df = _track(v)
    for n, e in pts[1:]:
        assert _dist(df, n, e).min() < 3.5  # within WP_RADIUS (3 m) and the run since
    assert (df["mavlink.mode"] == GUIDED).any() and (df["mavlink.mode"] == AUTO).any()


def test_guided_goto_change_speed_fly_to_here_rtl_and_home(tmp_path):
    v = _vehicle(tmp_path)
    g = GCS(v.address)
    try:
        g.wait("HEARTBEAT", 3.0)
        # outside GUIDED without the CHANGE_MODE flag: denied (ArduPilot)
        g.mav.command_int_send(1, 1, M.MAV_FRAME_GLOBAL, M.MAV_CMD_DO_REPOSITION, 0, 0, -1, 0, 0, math.nan,
                               *_ll(20.0, 0.0), math.nan)  # fmt: skip
        assert g.ack(M.MAV_CMD_DO_REPOSITION).result == M.MAV_RESULT_DENIED
        g.mav.command_long_send(1, 1, M.MAV_CMD_COMPONENT_ARM_DISARM, 0, 1, 0, 0, 0, 0, 0, 0)
        assert g.ack(M.MAV_CMD_COMPONENT_ARM_DISARM).result == M.MAV_RESULT_ACCEPTED
        # QGroundControl's "Go to location": DO_REPOSITION as COMMAND_INT, CHANGE_MODE flag, yaw and alt NaN
        flag = M.MAV_DO_REPOSITION_FLAGS_CHANGE_MODE
        g.mav.command_int_send(1, 1, M.MAV_FRAME_GLOBAL, M.MAV_CMD_DO_REPOSITION, 0, 0, -1, flag, 0, math.nan,
                               *_ll(20.0, 0.0), math.nan)  # fmt: skip
        assert g.ack(M.MAV_CMD_DO_REPOSITION).result == M.MAV_RESULT_ACCEPTED
        g.wait("HEARTBEAT", 3.0, lambda m: m.custom_mode == GUIDED)
        g.mav.command_long_send(1, 1, M.MAV_CMD_DO_CHANGE_SPEED, 0, 1, 1.0, -1, 0, 0, 0, 0)
        assert g.ack(M.MAV_CMD_DO_CHANGE_SPEED).result == M.MAV_RESULT_ACCEPTED
        g.mav.command_long_send(1, 1, M.MAV_CMD_DO_CHANGE_SPEED, 0, 1, 80.0, -1, 0, 0, 0, 0)
        assert g.ack(M.MAV_CMD_DO_CHANGE_SPEED).result == M.MAV_RESULT_DENIED
        _text(g, "Reached destination", 60.0)
        # Mission Planner's "Fly to here": MISSION_ITEM_INT with current = 2, answered with a MISSION_ACK
        g.mav.mission_item_int_send(1, 1, 0, M.MAV_FRAME_GLOBAL_RELATIVE_ALT_INT, M.MAV_CMD_NAV_WAYPOINT, 2, 0,
                                    0, 0, 0, 0, *_ll(20.0, 15.0), 0.0, 0)  # fmt: skip
        assert g.wait("MISSION_ACK", 3.0).type == M.MAV_MISSION_ACCEPTED
        assert g.wait("HEARTBEAT", 3.0).custom_mode == GUIDED
        _text(g, "Reached destination", 60.0)
        # a companion computer's SET_POSITION_TARGET_GLOBAL_INT (position only) in GUIDED
        mask = 0b110111111000  # use x, y, z; ignore velocity, acceleration, yaw, yaw rate
        g.mav.set_position_target_global_int_send(0, 1, 1, M.MAV_FRAME_GLOBAL_RELATIVE_ALT_INT, mask,
                                                  *_ll(5.0, 15.0), 0, 0, 0, 0, 0, 0, 0, 0, 0)  # fmt: skip
        _text(g, "Reached destination", 60.0)
        assert v.guided_target == pytest.approx((5.0, 15.0), abs=0.02)
        # the mission's item 0 and HOME_POSITION are where the vehicle armed (the origin)
        g.mav.command_long_send(1, 1, M.MAV_CMD_REQUEST_MESSAGE, 0, M.MAVLINK_MSG_ID_HOME_POSITION, 0, 0, 0, 0, 0, 0)
        home = g.wait("HOME_POSITION", 3.0)
        assert np.hypot(*latlon_to_ned(home.latitude * 1e-7, home.longitude * 1e-7, LAT0, LON0)) < 0.5
        # Return (QGC's RTL button: DO_SET_MODE RTL; MAV_CMD_NAV_RETURN_TO_LAUNCH does the same)
        g.mav.command_long_send(1, 1, M.MAV_CMD_NAV_RETURN_TO_LAUNCH, 0, 0, 0, 0, 0, 0, 0, 0)
        assert g.ack(M.MAV_CMD_NAV_RETURN_TO_LAUNCH).result == M.MAV_RESULT_ACCEPTED
        g.wait("HEARTBEAT", 3.0, lambda m: m.custom_mode == RTL)
        _text(g, "Reached home", 60.0)
        g.pump(2.0)
        assert np.hypot(v.sim.bus["usv.x"], v.sim.bus["usv.y"]) < 3.5
        # DO_SET_HOME to a point: RTL goes there (and arming no longer moves home)
        g.mav.command_long_send(
            1, 1, M.MAV_CMD_DO_SET_HOME, 0, 0, 0, 0, math.nan, *ned_to_latlon(-10.0, 5.0, LAT0, LON0), 0
        )
        assert g.ack(M.MAV_CMD_DO_SET_HOME).result == M.MAV_RESULT_ACCEPTED
        assert v.home == pytest.approx((-10.0, 5.0), abs=0.5)  # COMMAND_LONG carries lat/lon as float32
        g.mav.command_long_send(1, 1, M.MAV_CMD_DO_SET_HOME, 0, 0, 0, 0, 0, 95.0, 5.0, 0)
        assert g.ack(M.MAV_CMD_DO_SET_HOME).result == M.MAV_RESULT_DENIED
        qgc_set_mode(g, HOLD)
        qgc_set_mode(g, RTL)
        _text(g, "Reached home", 60.0)
    finally:
        g.close()
        v.stop()
    df = _track(v)
    guided = df[df["mavlink.mode"] == GUIDED]
    assert _dist(guided, 20.0, 0.0).min() < 3.5 and _dist(guided, 20.0, 15.0).min() < 3.5
    assert _dist(guided, 5.0, 15.0).min() < 3.5  # WP_RADIUS 3 m on the GPS fix
    assert guided["usv.u_d"].max() == pytest.approx(1.0, abs=1e-6)  # DO_CHANGE_SPEED 1 m/s in GUIDED ...
    rtl = df[df["mavlink.mode"] == RTL]
    # ... and CRUISE_SPEED (0.7) again after the mode change. The pilot fires every 20 ms and the log samples
    # every 50 ms, so the row of the switch may hold the speed the pilot computed up to 20 ms before it (seen once:
    # a loiter leg at 1 m/s restarted just before the RTL command); every later row is after a firing in RTL
    entered = (df["mavlink.mode"] == RTL) & (df["mavlink.mode"].shift(1) != RTL)
    settled = rtl[~entered[rtl.index]]
    assert len(settled) > 100 and settled["usv.u_d"].max() <= 0.7 + 1e-9
    assert _dist(rtl, -10.0, 5.0).min() < 3.5


def test_loiter_holds_within_radius_against_a_current(tmp_path):
    """LOITER with a 0.2 m/s current setting the boat east (abeam): it drifts out, comes back, and stays within
    LOIT_RADIUS (plus what it drifts while turning back)."""
    v = MavlinkVehicle(
        "usv-remote",
        overrides={"environment.current.speed": 0.2, "environment.current.direction_deg": 90.0},
        listen="udp:127.0.0.1:0",
        speed=10.0,
        out_root=tmp_path,
        mav={"origin_lat_deg": LAT0, "origin_lon_deg": LON0},
    ).start()
    g = GCS(v.address)
    try:
        g.wait("HEARTBEAT", 3.0)
        g.mav.command_long_send(1, 1, M.MAV_CMD_COMPONENT_ARM_DISARM, 0, 1, 0, 0, 0, 0, 0, 0)
        g.ack(M.MAV_CMD_COMPONENT_ARM_DISARM)
        qgc_set_mode(g, LOITER)
        t0 = v.sim.t
        g.pump(15.0, until=lambda m: v.sim.t > t0 + 90.0)
        assert v.sim.t > t0 + 60.0, v.sim.t
        assert v.mode == LOITER
    finally:
        g.close()
        v.stop()
    df = _track(v)
    lo = df[df["mavlink.mode"] == LOITER]
    d = _dist(lo, *v.loiter_center)
    assert lo["t"].iloc[-1] - lo["t"].iloc[0] > 60.0
    assert d.max() < 2.0 + 1.5, d.max()  # LOIT_RADIUS 2 m, plus the drift while turning back
    assert (lo["usv.u_d"] > 0.1).any(), "the boat never moved back: the current did not push it out"
    assert d.iloc[-200:].max() < 3.5


def test_failsafe_actions_rtl_and_smart_rtl(tmp_path):
    """FS_ACTION = RTL: the controlling ground station goes silent in GUIDED -> RTL after FS_GCS_TIMEOUT,
    home reached. FS_ACTION = SMART_RTL: the path flown (out east, then north) is retraced."""
    v = _vehicle(tmp_path, gcs_timeout_s=1.5, fs_action=1)
    g = GCS(v.address)
    try:
        g.wait("HEARTBEAT", 3.0)
        g.mav.command_long_send(1, 1, M.MAV_CMD_COMPONENT_ARM_DISARM, 0, 1, 0, 0, 0, 0, 0, 0)
        g.ack(M.MAV_CMD_COMPONENT_ARM_DISARM)
        g.mav.command_long_send(1, 1, M.MAV_CMD_DO_REPOSITION, 0, -1, M.MAV_DO_REPOSITION_FLAGS_CHANGE_MODE, 0,
                                math.nan, *ned_to_latlon(0.0, 15.0, LAT0, LON0), 0)  # fmt: skip
        assert g.ack(M.MAV_CMD_DO_REPOSITION).result == M.MAV_RESULT_ACCEPTED
        _text(g, "Reached destination", 60.0)
        g.send_heartbeats = False  # silent: the vehicle's failsafe, not the ground station, moves it now
        m = _text(g, "Failsafe", 10.0)
        assert "GCS link lost, RTL" in m.text
        assert v.mode == RTL and v.failsafe
        _text(g, "Reached home", 60.0)
        g.send_heartbeats = True
        g.pump(1.0)
        assert not v.failsafe and v.mode == RTL  # link back: the failsafe clears, the mode stays
        # SMART_RTL: out east 15 m then north 15 m; the failsafe retraces the path (east leg, not the diagonal)
        g.mav.param_set_send(1, 1, b"FS_ACTION", 3, M.MAV_PARAM_TYPE_INT8)
        g.wait("PARAM_VALUE", 3.0, lambda m: m.param_value == 3)
        for n, e in ((0.0, 15.0), (15.0, 15.0)):
            g.mav.command_long_send(1, 1, M.MAV_CMD_DO_REPOSITION, 0, -1, M.MAV_DO_REPOSITION_FLAGS_CHANGE_MODE,
                                    0, math.nan, *ned_to_latlon(n, e, LAT0, LON0), 0)  # fmt: skip
            assert g.ack(M.MAV_CMD_DO_REPOSITION).result == M.MAV_RESULT_ACCEPTED
            _text(g, "Reached destination", 60.0)
        t_back = v.sim.t
        g.send_heartbeats = False
        assert "GCS link lost, SMART_RTL" in _text(g, "Failsafe", 10.0).text
        _text(g, "Reached home", 90.0)
        g.send_heartbeats = True
        g.pump(0.5)
    finally:
        g.close()
        v.stop()
    df = _track(v)
    back = df[(df["t"] > t_back) & (df["mavlink.mode"] == SMART_RTL)]
    assert len(back) and _dist(back, 0.0, 0.0).min() < 3.5  # home again
    mid = back[(back["usv.x"] > 3.0) & (back["usv.x"] < 10.0)]  # on the way down from the north point
    assert len(mid) and (mid["usv.y"] > 10.0).all(), "SMART_RTL cut the corner instead of retracing the path"


def test_fs_gcs_enable_2_continues_the_mission(tmp_path):
    v = _vehicle(tmp_path, speed=12.0, gcs_timeout_s=1.0, fs_gcs_enable=2)
    g = GCS(v.address)
    try:
        g.wait("HEARTBEAT", 3.0)
        upload_mission(g, [(0.0, 0.0), (12.0, 0.0), (12.0, 12.0)], LAT0, LON0)
        qgc_start_mission(g)
        g.send_heartbeats = False
        assert "continuing AUTO" in _text(g, "Failsafe", 10.0).text
        g.wait("MISSION_ITEM_REACHED", 60.0, lambda m: m.seq == 2)
        assert v.reached == [1, 2]
    finally:
        g.close()
        v.stop()


def test_change_speed_lasts_until_the_mode_changes_and_smart_rtl_needs_a_path(tmp_path):
    """DO_CHANGE_SPEED in AUTO is the route pilot's speed until the mission ends (HOLD), then CRUISE_SPEED
    again; SMART_RTL is refused before the first arming (no path), and RTL / SMART_RTL / GUIDED / LOITER are
    refused by a scenario without a route hook. A fake wall clock steps the vehicle."""
    from oceangnc.mavlink.protocol import AUTO as A

    now = [0.0]
    v = MavlinkVehicle("usv-remote", listen="udp:127.0.0.1:0", out_root=None, clock=lambda: now[0])
    pilot = next(b for b in v.sim.blocks if type(b).__name__ == "RoutePilot")
    assert v._set_mode(SMART_RTL, "test") == M.MAV_RESULT_DENIED  # disarmed since start: no path
    v.mission = [v._item(0, 0.0, 0.0), v._item(1, 12.0, 0.0)]
    v._arm(True)
    assert v._set_mode(A, "test") == M.MAV_RESULT_ACCEPTED
    assert v._nav_command(M.MAV_CMD_DO_CHANGE_SPEED, 1, 1.1, 0, 0) == M.MAV_RESULT_ACCEPTED
    assert pilot.cruise_speed == pytest.approx(1.1) and v.params["CRUISE_SPEED"].get() == pytest.approx(0.7)
    while v.sim.t < 60.0 and v.mode == A:
        now[0] += 0.05
        v.step_once()
    assert v.mode == HOLD and v.reached == [1]
    assert pilot.cruise_speed == pytest.approx(0.7)  # back to CRUISE_SPEED with the mode change
    v.close()
    w = MavlinkVehicle("usv-waypoints-7", listen="udp:127.0.0.1:0", out_root=None, clock=lambda: now[0])
    w._arm(True)
    for num in (RTL, SMART_RTL, GUIDED, LOITER):
        assert w._set_mode(num, "test") == M.MAV_RESULT_DENIED
    assert w.mode == HOLD
    w.close()
