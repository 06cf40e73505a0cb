"""ArduPilot's semantics that ground stations rely on (issue 39), on a fake clock with the simulation stepped:
MISSION_CURRENT carries MAVLink 2's total / mission_state / mission_mode in every message of a mission; a
GUIDED target streamed after arrival neither restarts the leg nor repeats "Reached destination"; an
RC_CHANNELS_OVERRIDE stream at Mission Planner's 1 Hz holds MANUAL (ArduPilot's RC_OVERRIDE_TIME, 3 s), its
loss gives the stick failsafe without a word about the GCS link; the towed UUV (system 2) sends SYS_STATUS."""

from __future__ import annotations

from oceangnc.io.geo import ned_to_latlon
from oceangnc.mavlink.protocol import mavlink as M
from oceangnc.mavlink.vehicle import MavlinkVehicle

MANUAL, HOLD, AUTO, GUIDED = 0, 4, 10, 15
STEP_S = 0.04


class FakeClock:
    def __init__(self):
        self.t = 1000.0

    def __call__(self):
        return self.t


class Bench:
    """The vehicle on a fake clock, a ground station (255) handing it messages, and every message it sends."""

    def __init__(self, scenario: str = "usv-remote"):
        self.clk = FakeClock()
        self.v = MavlinkVehicle(scenario, listen="udp:127.0.0.1:0", out_root=None, clock=self.clk)
        self.v._anchor = (self.clk(), self.v.sim.t)
        self.mav = M.MAVLink(None, srcSystem=255, srcComponent=190)
        self.parser = M.MAVLink(None)
        self.sent: list = []
        self.v.mav.file = self.v.mav_uuv.file = self
        self.v.fixed_peers = [("127.0.0.1", 9)]  # a listener, so that telemetry is due (it reaches write())
        self.heartbeats = True

    def write(self, b) -> None:
        self.sent += [m for m in self.parser.parse_buffer(bytes(b)) or [] if m.get_type() != "BAD_DATA"]

    def send(self, msg) -> None:
        msg.pack(self.mav)
        self.v._handle(msg)

    def run(self, seconds: float, every=None) -> None:
        """Step ``seconds`` (heartbeats at 25 Hz; ``every(k)`` called each step to send more)."""
        for k in range(round(seconds / STEP_S)):
            self.clk.t += STEP_S
            if self.heartbeats:
                self.send(self.mav.heartbeat_encode(M.MAV_TYPE_GCS, M.MAV_AUTOPILOT_INVALID, 0, 0, 0))
            if every is not None:
                every(k)
            self.v.step_once()

    def command(self, cmd: int, *p) -> None:
        self.send(self.mav.command_long_encode(1, 1, cmd, 0, *(list(p) + [0.0] * (7 - len(p)))))

    def mode(self, num: int) -> None:
        self.send(self.mav.set_mode_encode(1, M.MAV_MODE_FLAG_CUSTOM_MODE_ENABLED, num))

    def latlon(self, n: float, e: float) -> tuple[int, int]:
        c = self.v.cfg_mav
        lat, lon = ned_to_latlon(n, e, c.origin_lat_deg, c.origin_lon_deg)
        return round(lat * 1e7), round(lon * 1e7)

    def close(self) -> None:
        self.v.stop()


def test_mission_current_carries_total_state_and_mode_in_every_message():
    b = Bench()
    try:
        pts = [(0.0, 0.0), (6.0, 0.0), (6.0, 6.0)]
        b.send(b.mav.mission_count_encode(1, 1, len(pts), 0))
        for seq, (n, e) in enumerate(pts):
            frame, wp = M.MAV_FRAME_GLOBAL_RELATIVE_ALT_INT, M.MAV_CMD_NAV_WAYPOINT
            b.send(b.mav.mission_item_int_encode(1, 1, seq, frame, wp, 0, 1, 0, 0, 0, 0, *b.latlon(n, e), 0, 0))
        b.command(M.MAV_CMD_COMPONENT_ARM_DISARM, 1)
        b.mode(AUTO)
        b.run(60.0)
        assert b.v.reached == [1, 2]
        cur = [m for m in b.sent if m.get_type() == "MISSION_CURRENT"]
        assert len(cur) > 10
        assert all(m.total == 2 for m in cur), sorted({m.total for m in cur})
        assert all(m.mission_mode in (1, 2) for m in cur)
        states = [m.mission_state for m in cur]
        assert M.MISSION_STATE_ACTIVE in states and states[-1] == M.MISSION_STATE_COMPLETE
        assert all(s != 0 for s in states)  # 0: MISSION_STATE_UNKNOWN (the field left out)
    finally:
        b.close()


def test_a_streamed_guided_target_is_reached_once():
    """MAVSDK Offboard-style: the same SET_POSITION_TARGET_GLOBAL_INT about 9 times a second, on past the
    arrival: one "Guided to", one "Reached destination", the boat stays there."""
    b = Bench()
    try:
        b.command(M.MAV_CMD_COMPONENT_ARM_DISARM, 1)
        b.mode(GUIDED)
        lat, lon = b.latlon(8.0, 0.0)
        mask = 0b0000111111111000  # position only

        def target(k):
            if k % 3 == 0:
                frame = M.MAV_FRAME_GLOBAL_RELATIVE_ALT_INT
                b.send(b.mav.set_position_target_global_int_encode(0, 1, 1, frame, mask, lat, lon, *[0] * 9))

        b.run(40.0, every=target)
        texts = [t for _, t in b.v.events]
        assert sum("Reached destination" in t for t in texts) == 1, texts
        assert sum(t.startswith("Guided to") for t in texts) == 1
        x, y = b.v.sim.bus["usv.x"], b.v.sim.bus["usv.y"]
        assert abs(x - 8.0) < 3.0 and abs(y) < 3.0 and b.v.mode == GUIDED
    finally:
        b.close()


def test_rc_override_at_one_hz_holds_manual_and_its_loss_is_the_stick_failsafe_only():
    b = Bench()
    try:
        b.command(M.MAV_CMD_COMPONENT_ARM_DISARM, 1)
        b.mode(MANUAL)
        assert b.v.params["RC_OVERRIDE_TIME"].get() == 3.0

        last = []

        def rc(k):  # Mission Planner: an override a second (throttle a little up), for 60 s
            if k % 25 == 0 and k * STEP_S < 60.0:
                b.send(b.mav.rc_channels_override_encode(1, 1, 1500, 0, 1600, 0, 0, 0, 0, 0))
                last.append(b.clk.t)

        b.run(60.0, every=rc)
        assert b.v.mode == MANUAL and not b.v.stick_failsafe and b.v.stick[0] > 0.2
        b.run(last[-1] + 2.9 - b.clk.t)
        assert b.v.mode == MANUAL  # the last override still holds (RC_OVERRIDE_TIME 3 s)
        b.run(0.3)
        assert b.v.mode == HOLD and b.v.stick_failsafe
        b.run(2.0)  # the ground station's heartbeats go on: no GCS link event either way
        texts = [t for _, t in b.v.events]
        assert any("stick stream lost" in t for t in texts)
        assert not any("GCS link" in t for t in texts), texts
        b.mode(MANUAL)  # the operator takes the stick again
        assert not b.v.stick_failsafe and b.v.mode == MANUAL
    finally:
        b.close()


def test_towed_uuv_sends_sys_status():
    b = Bench("combined-survey")
    try:
        b.run(2.0)
        st = [m for m in b.sent if m.get_type() == "SYS_STATUS" and m.get_srcSystem() == 2]
        assert st and st[-1].onboard_control_sensors_present & M.MAV_SYS_STATUS_SENSOR_GPS
        assert st[-1].onboard_control_sensors_health & M.MAV_SYS_STATUS_PREARM_CHECK
    finally:
        b.close()
