"""Missions as ArduPilot accepts them (issue 39): a NaN in each parameter of NAV_WAYPOINT, DO_CHANGE_SPEED and
NAV_LOITER_TIME is accepted exactly where AP_Mission::sanity_check_params (and, for a command stored with a
location, mavlink_int_to_mission_cmd's altitude check) accepts it, and a refused upload leaves no mission that
AUTO would fly. The messages go to the vehicle's dispatch directly (no simulation is stepped)."""

from __future__ import annotations

import math

import pytest

from oceangnc.io.geo import ned_to_latlon
from oceangnc.mavlink.protocol import mavlink as M
from oceangnc.mavlink.vehicle import MavlinkVehicle

AUTO = 10
WP, SPEED, LOITER = M.MAV_CMD_NAV_WAYPOINT, M.MAV_CMD_DO_CHANGE_SPEED, M.MAV_CMD_NAV_LOITER_TIME
#: ArduPilot's answer to a NaN in param1..4 and in z (AP_Mission.cpp at 000acc46: only NAV_WAYPOINT's param4
#: may be NaN among these; z must be a finite altitude for the commands stored with a location)
AP_ANSWER = {
    (WP, 1): "MAV_MISSION_INVALID_PARAM1",
    (WP, 2): "MAV_MISSION_INVALID_PARAM2",
    (WP, 3): "MAV_MISSION_INVALID_PARAM3",
    (WP, 4): "MAV_MISSION_ACCEPTED",
    (WP, 7): "MAV_MISSION_INVALID_PARAM7",
    (SPEED, 1): "MAV_MISSION_INVALID_PARAM1",
    (SPEED, 2): "MAV_MISSION_INVALID_PARAM2",
    (SPEED, 3): "MAV_MISSION_INVALID_PARAM3",
    (SPEED, 4): "MAV_MISSION_INVALID_PARAM4",
    (SPEED, 7): "MAV_MISSION_ACCEPTED",  # z is not read by DO_CHANGE_SPEED
    (LOITER, 1): "MAV_MISSION_INVALID_PARAM1",
    (LOITER, 2): "MAV_MISSION_INVALID_PARAM2",
    (LOITER, 3): "MAV_MISSION_INVALID_PARAM3",
    (LOITER, 4): "MAV_MISSION_INVALID_PARAM4",
    (LOITER, 7): "MAV_MISSION_INVALID_PARAM7",
}


class Client:
    """A ground station (system 245, MAVSDK's id) talking to the vehicle's dispatch; keeps MISSION_ACKs."""

    def __init__(self, v):
        self.v = v
        self.mav = M.MAVLink(None, srcSystem=245, srcComponent=190)
        self.parser = M.MAVLink(None)
        self.acks: list[tuple[int, int]] = []  # (type, target_system)
        v.mav.file = self

    def write(self, b) -> None:
        for m in self.parser.parse_buffer(bytes(b)) or []:
            if m.get_type() == "MISSION_ACK":
                self.acks.append((m.type, m.target_system))

    def send(self, msg) -> None:
        msg.pack(self.mav)
        self.v._handle(msg)

    def upload(self, items) -> int:
        """items: (command, p1, p2, p3, p4, north, east, z); item 0 is home. The last MISSION_ACK's type."""
        c = self.v.cfg_mav
        self.send(self.mav.mission_count_encode(1, 1, len(items), 0))
        for seq, (cmd, p1, p2, p3, p4, n, e, z) in enumerate(items):
            lat, lon = ned_to_latlon(n, e, c.origin_lat_deg, c.origin_lon_deg)
            x, y, frame = round(lat * 1e7), round(lon * 1e7), M.MAV_FRAME_GLOBAL_RELATIVE_ALT_INT
            self.send(self.mav.mission_item_int_encode(1, 1, seq, frame, cmd, 0, 1, p1, p2, p3, p4, x, y, z, 0))
            if self.acks and self.acks[-1][0] != M.MAV_MISSION_ACCEPTED:
                break
        assert self.acks and self.acks[-1][1] == 245  # answered to the uploader, not to another system
        return self.acks[-1][0]


@pytest.fixture(scope="module")
def vehicle():
    v = MavlinkVehicle("usv-remote", listen="udp:127.0.0.1:0", out_root=None)
    yield v
    v.stop()


def _item(cmd, nan_at: int):
    p = [0.0, 0.0, 0.0, 0.0, 20.0, 10.0, 0.0]  # p1..p4, north, east, z
    if cmd == SPEED:
        p[1] = 1.0  # ground speed 1 m/s
    if cmd == LOITER:
        p[0] = 5.0  # 5 s
    p[nan_at - 1 if nan_at <= 4 else 6] = math.nan
    return (cmd, *p)


@pytest.mark.parametrize("cmd, at", list(AP_ANSWER))
def test_a_nan_is_accepted_exactly_where_ardupilot_accepts_it(vehicle, cmd, at):
    v = vehicle
    g = Client(v)
    home = (WP, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0)
    wp = (WP, 0.0, 0.0, 0.0, 0.0, 30.0, 0.0, 0.0)
    assert g.upload([home, wp, (WP, 0, 0, 0, 0, 40.0, 0.0, 0.0)]) == M.MAV_MISSION_ACCEPTED
    assert len(v.mission) == 3
    got = g.upload([home, wp, _item(cmd, at)])
    assert got == getattr(M, AP_ANSWER[(cmd, at)]), M.enums["MAV_MISSION_RESULT"][got].name
    if got == M.MAV_MISSION_ACCEPTED:
        assert len(v.mission) == 3 and v.mission[2]["command"] == cmd
    else:  # no part of the refused upload is kept, nor the previous mission: AUTO has nothing to fly
        assert len(v.mission) == 1
        g.send(g.mav.set_mode_encode(1, M.MAV_MODE_FLAG_CUSTOM_MODE_ENABLED, AUTO))
        assert v.mode != AUTO


def test_an_infinite_parameter_is_refused_even_where_nan_is_allowed(vehicle):
    g = Client(vehicle)
    home = (WP, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0)
    assert g.upload([home, (WP, 0.0, 0.0, 0.0, math.inf, 30.0, 0.0, 0.0)]) == M.MAV_MISSION_INVALID_PARAM4
