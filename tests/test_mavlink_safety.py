"""MAVLink safety defects of issue 26, each shown with plain pymavlink clients on 127.0.0.1 (bounded
waits): only the controlling ground station keeps the link alive, a NaN cannot release the e-stop,
bad command parameters are refused with an answer, a refused mission item gets its MISSION_ACK."""

from __future__ import annotations

import math
import time

import pytest

from mavlink_gcs import GCS, served, wait_for
from oceangnc.mavlink.protocol import mavlink as M
from oceangnc.mavlink.vehicle import MavlinkVehicle

MANUAL, HOLD, AUTO = 0, 4, 10


@pytest.fixture
def vehicle(tmp_path):
    with served(mav={"gcs_timeout_s": 1.0}, speed=2.0) as vg:
        yield vg


class Intruder(GCS):
    """Another system on the network (sysid 66): heartbeats only."""

    def __init__(self, address):
        super().__init__(address)
        gcs = self

        class _W:
            def write(self, b):
                gcs.sock.sendto(bytes(b), gcs.address)

        self.mav = M.MAVLink(_W(), srcSystem=66, srcComponent=1)


def _arm_manual(g):
    g.wait("HEARTBEAT", 3.0)
    g.mav.command_long_send(1, 1, M.MAV_CMD_COMPONENT_ARM_DISARM, 0, 1, 0, 0, 0, 0, 0, 0)
    assert g.ack(M.MAV_CMD_COMPONENT_ARM_DISARM).result == M.MAV_RESULT_ACCEPTED
    g.mav.set_mode_send(1, M.MAV_MODE_FLAG_CUSTOM_MODE_ENABLED, MANUAL)
    g.wait("HEARTBEAT", 3.0, lambda m: m.custom_mode == MANUAL)


def test_another_systems_heartbeats_do_not_hold_off_the_failsafe(vehicle):
    v, g = vehicle
    _arm_manual(g)
    other = Intruder(v.address)
    try:
        g.send_heartbeats = False  # the controlling ground station goes silent ...
        t0 = time.monotonic()
        other.pump(4.0, until=lambda m: v.mode == HOLD)  # ... while sysid 66 sends heartbeats at 10 Hz
        assert v.mode == HOLD and v.failsafe, "a third party's heartbeats held the link"
        assert time.monotonic() - t0 < 4.0
        assert v.gcs_sysid == 255
        assert any("GCS link lost" in s for _, s in v.events)
        # the intruder's heartbeats do not clear the failsafe either; the controlling GCS's do
        other.pump(0.5)
        assert v.failsafe
        g.send_heartbeats = True
        g.pump(0.5)
        assert not v.failsafe and v.mode == HOLD
    finally:
        other.close()


def test_one_hz_heartbeats_without_a_stick_keep_manual(tmp_path):
    """ArduPilot's FS_GCS_TIMEOUT (5 s by default): a ground station with no joystick and 1 Hz
    heartbeats keeps MANUAL; the stick failsafe only concerns a stick stream that was flowing."""
    v = MavlinkVehicle("usv-remote", listen="udp:127.0.0.1:0", speed=2.0, out_root=None)
    v.start()
    g = GCS(v.address)
    try:
        g.heartbeat_hz = 1.0
        _arm_manual(g)
        g.pump(3.0)
        assert v.mode == MANUAL and not v.failsafe
        assert v.cfg_mav.gcs_timeout_s == 5.0
        g.pump(0.6, stick=(300, 0))  # a stick stream starts, then stops: the stick failsafe (RC_OVERRIDE_TIME 3 s)
        assert wait_for(lambda: v.mode == HOLD, 5.0) and v.stick_failsafe and not v.failsafe
        assert any("stick stream lost" in s for _, s in v.events)
    finally:
        g.close()
        v.stop()


def test_a_nan_does_not_release_the_estop_and_bad_parameters_are_denied(vehicle):
    v, g = vehicle
    _arm_manual(g)
    g.mav.command_long_send(1, 1, M.MAV_CMD_DO_FLIGHTTERMINATION, 0, 1, 0, 0, 0, 0, 0, 0)
    assert g.ack(M.MAV_CMD_DO_FLIGHTTERMINATION).result == M.MAV_RESULT_ACCEPTED
    assert v.estop and not v.armed
    for bad in (math.nan, math.inf, -math.inf, 0.3):
        g.mav.command_long_send(1, 1, M.MAV_CMD_DO_FLIGHTTERMINATION, 0, bad, 0, 0, 0, 0, 0, 0)
        assert g.ack(M.MAV_CMD_DO_FLIGHTTERMINATION).result == M.MAV_RESULT_DENIED
        assert v.estop, f"param1 = {bad} released the e-stop"
    g.mav.command_long_send(1, 1, M.MAV_CMD_COMPONENT_ARM_DISARM, 0, 1, 0, 0, 0, 0, 0, 0)
    assert g.ack(M.MAV_CMD_COMPONENT_ARM_DISARM).result == M.MAV_RESULT_DENIED  # still latched
    g.mav.command_long_send(1, 1, M.MAV_CMD_COMPONENT_ARM_DISARM, 0, math.nan, 0, 0, 0, 0, 0, 0)
    assert g.ack(M.MAV_CMD_COMPONENT_ARM_DISARM).result == M.MAV_RESULT_DENIED
    # a NaN in a parameter the command does not read is refused as well (nothing changes)
    g.mav.command_long_send(1, 1, M.MAV_CMD_DO_SET_MODE, 0, 1, HOLD, 0, 0, math.nan, 0, 0)
    assert g.ack(M.MAV_CMD_DO_SET_MODE).result == M.MAV_RESULT_DENIED
    assert v.mode == MANUAL
    mode = v.mode
    g.mav.command_long_send(1, 1, M.MAV_CMD_MISSION_START, 0, 1e30, 0, 0, 0, 0, 0, 0)
    assert g.ack(M.MAV_CMD_MISSION_START).result == M.MAV_RESULT_DENIED
    assert v.mode == mode
    g.mav.command_int_send(1, 1, 0, M.MAV_CMD_DO_SET_MODE, 0, 0, math.inf, HOLD, 0, 0, 0, 0, 0)
    assert g.ack(M.MAV_CMD_DO_SET_MODE).result == M.MAV_RESULT_DENIED
    assert v.counts["rx_out_of_range"] >= 7
    # the proper reset still works
    g.mav.command_long_send(1, 1, M.MAV_CMD_DO_FLIGHTTERMINATION, 0, 0, 0, 0, 0, 0, 0, 0)
    assert g.ack(M.MAV_CMD_DO_FLIGHTTERMINATION).result == M.MAV_RESULT_ACCEPTED
    assert not v.estop


@pytest.mark.parametrize(
    "lat,param1,error",
    [(95.0, 0.0, "MAV_MISSION_INVALID_PARAM5_X"), (47.4, math.nan, "MAV_MISSION_INVALID_PARAM1")],
)
def test_a_refused_mission_item_gets_its_mission_ack(vehicle, lat, param1, error):
    v, g = vehicle
    g.wait("HEARTBEAT", 3.0)
    before = [dict(it) for it in v.mission]
    g.mav.mission_count_send(1, 1, 2, 0)
    req = g.wait("MISSION_REQUEST_INT", 3.0, lambda m: m.seq == 0)
    assert req.seq == 0
    home = (int(47.3977 * 1e7), int(8.5456 * 1e7))
    g.mav.mission_item_int_send(1, 1, 0, 0, M.MAV_CMD_NAV_WAYPOINT, 0, 1, 0, 0, 0, 0, *home, 0.0, 0)
    g.wait("MISSION_REQUEST_INT", 3.0, lambda m: m.seq == 1)
    g.mav.mission_item_int_send(
        1, 1, 1, 0, M.MAV_CMD_NAV_WAYPOINT, 0, 1, param1, 0, 0, 0, int(lat * 1e7), home[1], 0.0, 0
    )
    ack = g.wait("MISSION_ACK", 3.0)
    assert ack.type == getattr(M, error)
    # no part of the refused upload is kept, and AUTO does not fly the previous mission as if it were this one
    # (issue 39: AP_Mission refuses the item; the client believes its own mission failed)
    assert v.mission == before[:1]
    g.mav.set_mode_send(1, M.MAV_MODE_FLAG_CUSTOM_MODE_ENABLED, AUTO)
    assert g.ack(M.MAVLINK_MSG_ID_SET_MODE).result == M.MAV_RESULT_DENIED
