"""The MAVLink vehicle driven by MAVSDK (the ``mavsdk`` wheel: MAVSDK's C++ core bundled as a shared library,
no separate server process): discover the autopilot, upload a mission with MissionRaw, arm, start the
mission, follow MAVSDK's own mission progress to the end. 127.0.0.1 only, bounded waits."""

from __future__ import annotations

import math
import time

import pytest

from mavlink_gcs import mavsdk_system
from oceangnc.io.geo import ned_to_latlon
from oceangnc.mavlink.protocol import mavlink as M
from oceangnc.mavlink.vehicle import MavlinkVehicle

mavsdk = pytest.importorskip("mavsdk")


def test_mavsdk_mission_raw_arm_start_progress(tmp_path):
    from mavsdk.plugins.action import Action
    from mavsdk.plugins.mission_raw import MissionItem, MissionRaw
    from mavsdk.plugins.telemetry import Telemetry

    v = MavlinkVehicle("usv-remote", listen="udp:127.0.0.1:0", speed=12.0, out_root=tmp_path)
    v.start()
    try:
        sdk, system = mavsdk_system(v)  # noqa: F841 (sdk kept alive)
        tel, act, mis = Telemetry(system), Action(system), MissionRaw(system)
        time.sleep(1.0)  # let telemetry arrive
        assert not tel.armed()  # disarmed at start
        pos = tel.position()
        assert abs(pos.latitude_deg - v.cfg_mav.origin_lat_deg) < 1e-5  # at the origin (NED 0, 0)
        lat0, lon0 = v.cfg_mav.origin_lat_deg, v.cfg_mav.origin_lon_deg
        items = []
        for seq, (n, e) in enumerate([(0.0, 0.0), (12.0, 0.0), (12.0, 12.0), (0.0, 12.0)]):
            lat, lon = ned_to_latlon(n, e, lat0, lon0)
            items.append(
                MissionItem(
                    seq,
                    M.MAV_FRAME_GLOBAL_RELATIVE_ALT_INT if seq else M.MAV_FRAME_GLOBAL_INT,
                    M.MAV_CMD_NAV_WAYPOINT,
                    1 if seq == 0 else 0,
                    1,
                    0.0,
                    0.0,
                    0.0,
                    0.0,
                    round(lat * 1e7),
                    round(lon * 1e7),
                    0.0,
                    0,
                )
            )
        mis.upload_mission(items)
        assert len(v.mission) == 4
        down = mis.download_mission()
        assert [it.seq for it in down] == [0, 1, 2, 3] and abs(down[2].x - items[2].x) <= 1
        act.arm()
        assert v.armed
        mis.start_mission()
        t_end = time.monotonic() + 40.0
        prog = None
        while time.monotonic() < t_end:
            prog = mis.mission_progress()
            if v.reached == [1, 2, 3] and prog.current >= 3:
                break
            time.sleep(0.2)
        assert v.reached == [1, 2, 3], (v.reached, prog.current if prog else None)
        assert prog.current >= 3 and prog.total == 4
        assert v.counts["rx_bad"] == 0
    finally:
        v.stop()


def test_mavsdk_goto_location_and_return_to_launch(tmp_path):
    """MAVSDK's Action.goto_location (DO_SET_MODE GUIDED, then DO_REPOSITION as COMMAND_INT) and
    Action.return_to_launch (DO_SET_MODE RTL) succeed, and the boat goes there and back."""
    from mavsdk.plugins.action import Action
    from mavsdk.plugins.telemetry import Telemetry

    v = MavlinkVehicle("usv-remote", listen="udp:127.0.0.1:0", speed=12.0, out_root=tmp_path)
    v.start()
    try:
        sdk, system = mavsdk_system(v)  # noqa: F841 (sdk kept alive)
        tel, act = Telemetry(system), Action(system)
        time.sleep(1.0)
        act.arm()
        lat, lon = ned_to_latlon(20.0, 5.0, v.cfg_mav.origin_lat_deg, v.cfg_mav.origin_lon_deg)
        act.goto_location(lat, lon, 0.0, 0.0)  # raises ActionError unless accepted
        assert v.mode == 15 and v.guided_target is not None
        t_end = time.monotonic() + 40.0
        while time.monotonic() < t_end and not any("Reached destination" in s for _, s in v.events):
            time.sleep(0.1)
        assert any("Reached destination" in s for _, s in v.events)
        pos = tel.position()
        assert abs(pos.latitude_deg - lat) * 111e3 < 4.0  # MAVSDK's own telemetry shows the boat there
        act.return_to_launch()
        assert v.mode == 11
        t_end = time.monotonic() + 40.0
        while time.monotonic() < t_end and not any("Reached home" in s for _, s in v.events):
            time.sleep(0.1)
        assert any("Reached home" in s for _, s in v.events)
        assert math.hypot(v.sim.bus["usv.x"], v.sim.bus["usv.y"]) < 4.0
    finally:
        v.stop()


def test_mavsdk_armable_battery_and_version(tmp_path):
    """MAVSDK reports the vehicle armable (SYS_STATUS pre-arm check), a battery (the model: 8 LiFePO4 cells,
    full) and the package's version from AUTOPILOT_VERSION."""
    from mavsdk.plugins.info import Info
    from mavsdk.plugins.telemetry import Telemetry

    from oceangnc import __version__

    v = MavlinkVehicle("usv-remote", listen="udp:127.0.0.1:0", speed=1.0, out_root=None)
    v.start()
    try:
        sdk, system = mavsdk_system(v)  # noqa: F841 (sdk kept alive)
        tel, info = Telemetry(system), Info(system)
        t_end = time.monotonic() + 10.0
        while time.monotonic() < t_end and not tel.health().is_armable:
            time.sleep(0.2)
        assert tel.health().is_armable
        bat = tel.battery()
        assert 26.0 < bat.voltage_v < 27.3 and bat.remaining_percent > 99.0
        ver = None
        while time.monotonic() < t_end + 5.0:
            try:
                ver = info.get_version()
                break
            except Exception:  # noqa: BLE001 InfoError until AUTOPILOT_VERSION has arrived
                time.sleep(0.2)
        assert ver is not None
        major, minor, patch = (int(x) for x in __version__.split("+")[0].split(".")[:3])
        assert (ver.flight_sw_major, ver.flight_sw_minor, ver.flight_sw_patch) == (major, minor, patch)
    finally:
        v.stop()


def test_mavsdk_mission_plugin_with_default_items_uploads_starts_completes(tmp_path):
    """MAVSDK's Mission plugin with MissionItem's defaults (yaw_deg NaN -> NAV_WAYPOINT param4 NaN, which
    AP_Mission::sanity_check_params accepts): the upload is accepted, start_mission flies it, the mission
    finishes (issue 39: every MAVSDK mission upload was refused with MAV_MISSION_INVALID_PARAM4)."""
    from mavsdk.plugins.action import Action
    from mavsdk.plugins.mission import Mission, MissionItem, MissionPlan

    v = MavlinkVehicle("usv-remote", listen="udp:127.0.0.1:0", speed=12.0, out_root=tmp_path)
    v.start()
    try:
        sdk, system = mavsdk_system(v)  # noqa: F841 (sdk kept alive)
        act, mis = Action(system), Mission(system)
        lat0, lon0 = v.cfg_mav.origin_lat_deg, v.cfg_mav.origin_lon_deg
        items = []
        for n, e in [(12.0, 0.0), (12.0, 12.0), (0.0, 12.0)]:
            lat, lon = ned_to_latlon(n, e, lat0, lon0)
            it = MissionItem(latitude_deg=lat, longitude_deg=lon, relative_altitude_m=0.0)
            assert math.isnan(it.yaw_deg)  # MAVSDK's default
            items.append(it)
        mis.upload_mission(MissionPlan(items))
        # MAVSDK sends its items from seq 0, and seq 0 is ArduPilot's home slot: items 1.. are flown, as on
        # ArduPilot; each carries MAVSDK's NaN yaw
        wps = [it for it in v.mission[1:] if it["command"] == M.MAV_CMD_NAV_WAYPOINT]
        assert len(v.mission) == 3 and len(wps) == 2 and all(math.isnan(it["p4"]) for it in wps)
        act.arm()
        mis.start_mission()
        t_end = time.monotonic() + 40.0
        while time.monotonic() < t_end and not (v.reached and v.reached[-1] == v.mission[-1]["seq"]):
            time.sleep(0.2)
        assert v.reached == [1, 2], v.reached
        t_end = time.monotonic() + 5.0
        while time.monotonic() < t_end and not mis.is_mission_finished():
            time.sleep(0.2)
        assert mis.is_mission_finished()
    finally:
        v.stop()
