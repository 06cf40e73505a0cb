"""ArduSub vehicles over MAVLink (issues 28 and 30): the towed UUV of ``combined-survey`` (system 2) holds a
commanded depth in ALT_HOLD / GUIDED by its winch and flies an uploaded mission; the BlueROV2 Heavy of
``rov-station-keeping`` (system 1) is a MAV_TYPE_SUBMARINE with FRAME_CONFIG 2 (vectored_6dof) whose modes
and sticks follow ArduSub's conventions; the Otter is a Rover boat. Every run is on 127.0.0.1 with a fake
clock stepped by the test (bounded in simulated time; no wall-clock waits)."""

from __future__ import annotations

import math
import socket

import numpy as np
import pandas as pd
import pytest

from oceangnc.io.geo import ned_to_latlon
from oceangnc.mavlink.protocol import mavlink as M
from oceangnc.mavlink.vehicle import MavlinkVehicle

STEP_S = 0.04  # simulated (= fake wall) seconds per loop pass
ALT_HOLD, AUTO, GUIDED, POSHOLD, MANUAL, STABILIZE = 2, 3, 4, 16, 19, 0


class FakeClock:
    def __init__(self):
        self.t = 1000.0

    def __call__(self):
        return self.t


class Loop:
    """A ground station (system 255) and the vehicle stepped together: ``run`` advances the fake clock and
    the vehicle, sends heartbeats (and a stick), and keeps every message the vehicle sent."""

    def __init__(self, scenario: str, tmp_path, **kw):
        self.clk = FakeClock()
        self.v = MavlinkVehicle(scenario, listen="udp:127.0.0.1:0", out_root=tmp_path, clock=self.clk, **kw)
        self.sock = socket.socket(socket.AF_INET, socket.SOCK_DGRAM)
        self.sock.bind(("127.0.0.1", 0))
        self.sock.setblocking(False)
        loop = self

        class _W:
            def write(self, b):
                loop.sock.sendto(bytes(b), loop.v.address)

        self.mav = M.MAVLink(_W(), srcSystem=255, srcComponent=190)
        self.parser = M.MAVLink(None)
        self.parser.robust_parsing = True
        self.received: list = []
        self.stick: tuple | None = None  # (target, x, y, z, r) sent as MANUAL_CONTROL every pass
        self.heartbeats = True

    def _drain(self) -> list:
        new = []
        while True:
            try:
                data, _ = self.sock.recvfrom(65535)
            except BlockingIOError:
                return new
            for m in self.parser.parse_buffer(data) or []:
                if m.get_type() != "BAD_DATA":
                    new.append(m)
                    self.received.append(m)

    def run(self, seconds: float, until=None):
        """Step up to ``seconds`` of simulated time; the first message satisfying ``until`` or None."""
        for _ in range(max(1, round(seconds / STEP_S))):
            self.clk.t += STEP_S
            if self.heartbeats:
                self.mav.heartbeat_send(M.MAV_TYPE_GCS, M.MAV_AUTOPILOT_INVALID, 0, 0, 0)
            if self.stick is not None:
                self.mav.manual_control_send(*self.stick, 0)
            self.v.step_once()
            for m in self._drain():
                if until is not None and until(m):
                    return m
        return None

    def wait(self, kind: str, sysid: int, cond=lambda m: True, seconds: float = 2.0):
        m = self.run(seconds, lambda m: m.get_type() == kind and m.get_srcSystem() == sysid and cond(m))
        assert m is not None, f"no {kind} from system {sysid} within {seconds} s"
        return m

    def command(self, sysid: int, cmd: int, *p) -> int:
        p = list(p) + [0.0] * (7 - len(p))
        self.mav.command_long_send(sysid, 1, cmd, 0, *p)
        return self.wait("COMMAND_ACK", sysid, lambda m: m.command == cmd).result

    def set_mode(self, sysid: int, mode: int) -> int:
        self.mav.set_mode_send(sysid, M.MAV_MODE_FLAG_CUSTOM_MODE_ENABLED, mode)
        return self.wait("COMMAND_ACK", sysid, lambda m: m.command == M.MAVLINK_MSG_ID_SET_MODE).result

    def upload(self, sysid: int, items) -> int:
        """Mission upload to ``sysid``: ``items`` (north, east, alt) m, the first one home."""
        c = self.v.cfg_mav
        self.mav.mission_count_send(sysid, 1, len(items), 0)
        for seq, (n, e, alt) in enumerate(items):
            req = self.wait("MISSION_REQUEST_INT", sysid, lambda m, s=seq: m.seq == s)
            lat, lon = ned_to_latlon(n, e, c.origin_lat_deg, c.origin_lon_deg)
            frame = M.MAV_FRAME_GLOBAL_RELATIVE_ALT_INT if seq else M.MAV_FRAME_GLOBAL_INT
            self.mav.mission_item_int_send(sysid, 1, req.seq, frame, M.MAV_CMD_NAV_WAYPOINT, 0, 1, 0, 0, 0, 0,
                                           round(lat * 1e7), round(lon * 1e7), alt, 0)  # fmt: skip
        return self.wait("MISSION_ACK", sysid).type

    def close(self) -> pd.DataFrame | None:
        self.v.stop()
        self.sock.close()
        if self.v.run_dir is None:
            return None
        return pd.read_parquet(self.v.run_dir / "log.parquet")


def _window(df, t0, t1):
    return df[(df["t"] >= t0) & (df["t"] <= t1)]


def test_towed_uuv_holds_a_commanded_depth_in_alt_hold_and_guided(tmp_path):
    """Round trip through the MAVLink front end, the depth reference law and the winch: the UUV holds the
    depth where ALT_HOLD was engaged, follows the z stick down, and goes to a GUIDED depth target
    (SET_POSITION_TARGET_LOCAL_NED z), each logged depth settling within 0.15 m of the reference."""
    lp = Loop("combined-survey", tmp_path)
    try:
        v = lp.v
        hb = lp.wait("HEARTBEAT", 2)
        assert hb.type == M.MAV_TYPE_SUBMARINE and hb.custom_mode == MANUAL  # ArduSub boots in MANUAL
        assert lp.command(2, M.MAV_CMD_COMPONENT_ARM_DISARM, 1) == M.MAV_RESULT_ACCEPTED
        lp.run(10.0)  # MANUAL, stick neutral: the winch holds the length while the start-up bob dies out
        assert lp.set_mode(2, ALT_HOLD) == M.MAV_RESULT_ACCEPTED
        assert lp.wait("HEARTBEAT", 2, lambda m: m.custom_mode == ALT_HOLD).base_mode & M.MAV_MODE_FLAG_SAFETY_ARMED
        t_alt = v.sim.t
        lp.run(15.0)
        t_stick = v.sim.t
        lp.stick = (2, 0, 0, 0, 0)  # z = 0: full down (500 is neutral)
        lp.run(2.0)
        lp.stick = (2, 0, 0, 500, 0)  # neutral: the reference stays where the stick left it
        lp.run(1.0)
        z_after_stick = float(v.sim.bus["uuv.depth_cmd"])
        lp.stick = None
        lp.run(25.0)
        t_guided = v.sim.t
        assert lp.set_mode(2, GUIDED) == M.MAV_RESULT_ACCEPTED
        mask = 0b110111111000 & ~M.POSITION_TARGET_TYPEMASK_Z_IGNORE | M.POSITION_TARGET_TYPEMASK_X_IGNORE
        mask |= M.POSITION_TARGET_TYPEMASK_Y_IGNORE
        lp.mav.set_position_target_local_ned_send(0, 2, 1, M.MAV_FRAME_LOCAL_NED, mask, 0, 0, 2.2, 0, 0, 0, 0, 0, 0,
                                                  0, 0)  # fmt: skip
        lp.run(35.0)
        t_end = v.sim.t
    finally:
        df = lp.close()
    assert df is not None
    # ALT_HOLD: the depth when engaged is the reference and is held
    at = df.iloc[(df["t"] - t_alt).abs().argmin()]
    w = _window(df, t_alt + 0.5, t_stick)
    z_engaged = float(w["uuv.depth_cmd"].iloc[0])
    assert abs(z_engaged - at["uuv.z"]) < 0.08
    assert np.allclose(w["uuv.depth_cmd"], z_engaged, atol=1e-9)
    assert (_window(w, t_alt + 5.0, t_stick)["uuv.z"] - z_engaged).abs().max() < 0.15
    # the stick moved the reference down by about 2 s of PILOT_SPEED_DN (0.5 m/s), less the dead band
    assert 0.6 < z_after_stick - z_engaged < 1.05
    w = _window(df, t_guided - 8.0, t_guided)
    assert (w["uuv.z"] - z_after_stick).abs().max() < 0.15
    # GUIDED: the depth target is reached and held
    w = _window(df, t_end - 10.0, t_end)
    assert np.allclose(w["uuv.depth_cmd"], 2.2, atol=1e-9)
    assert (w["uuv.z"] - 2.2).abs().max() < 0.15
    assert df["winch.speed_cmd"].abs().max() > 0.1  # the winch did the work


def test_towed_uuv_flies_an_uploaded_mission_of_depths_along_the_tow(tmp_path):
    """System 2 takes a 3-item mission (MISSION_COUNT / REQUEST_INT / ITEM_INT / ACK from system 2), flies it
    in AUTO while the USV flies its own route, and reports each item reached (MISSION_ITEM_REACHED from
    system 2) at the item's depth (alt = -depth)."""
    lp = Loop("combined-survey", tmp_path)
    items = [(0.0, 0.0, 0.0), (4.0, 4.0, -4.0), (9.0, 9.0, -2.5), (16.0, 7.0, -3.5)]
    reached = {}
    try:
        v = lp.v
        lp.wait("HEARTBEAT", 2)
        usv_mission = [dict(it) for it in v.mission]
        assert lp.upload(2, items) == M.MAV_MISSION_ACCEPTED
        lp.mav.mission_request_list_send(2, 1, 0)
        assert lp.wait("MISSION_COUNT", 2).count == len(items)
        assert v.mission == usv_mission  # system 1's own mission (home + the scenario's route) is untouched
        assert lp.command(1, M.MAV_CMD_COMPONENT_ARM_DISARM, 1) == M.MAV_RESULT_ACCEPTED
        assert lp.set_mode(2, AUTO) == M.MAV_RESULT_ACCEPTED
        lp.mav.set_mode_send(1, M.MAV_MODE_FLAG_CUSTOM_MODE_ENABLED, 10)  # the USV in AUTO on its route
        for _ in range(3):
            m = lp.wait("MISSION_ITEM_REACHED", 2, seconds=60.0)
            reached[m.seq] = (float(v.sim.bus["uuv.z"]), float(v.sim.bus["uuv.x"]), float(v.sim.bus["uuv.y"]))
        lp.wait("HEARTBEAT", 2, lambda m: m.custom_mode == POSHOLD)
    finally:
        lp.close()
    assert list(reached) == [1, 2, 3]
    for seq, (z, x, y) in reached.items():
        n, e, alt = items[seq]
        assert abs(z + alt) <= 0.5, (seq, z)
        assert math.hypot(x - n, y - e) < 4.0, (seq, x, y)


@pytest.mark.parametrize("vehicle", ["bluerov2-heavy"])
def test_rov_is_an_ardusub_vehicle_with_its_frame_modes_and_sticks(tmp_path, vehicle):
    """rov-station-keeping over MAVLink: MAV_TYPE_SUBMARINE, FRAME_CONFIG 2 (vectored_6dof), MANUAL_CONTROL
    z = 500 is neutral (no heave force in MANUAL), z = 1000 an upward (negative) heave force, z = 0 a downward
    one, x a surge force; ALT_HOLD holds the depth where it was engaged; POSHOLD holds the position; CIRCLE is
    refused."""
    lp = Loop("rov-station-keeping", tmp_path, overrides={"vehicle": vehicle})
    try:
        v = lp.v
        hb = lp.wait("HEARTBEAT", 1)
        assert hb.type == M.MAV_TYPE_SUBMARINE and hb.autopilot == M.MAV_AUTOPILOT_ARDUPILOTMEGA
        assert hb.custom_mode == MANUAL
        lp.mav.param_request_read_send(1, 1, b"FRAME_CONFIG", -1)
        assert lp.wait("PARAM_VALUE", 1, lambda m: m.param_id == "FRAME_CONFIG").param_value == 2.0
        assert lp.command(1, M.MAV_CMD_COMPONENT_ARM_DISARM, 1) == M.MAV_RESULT_ACCEPTED
        lp.stick = (1, 0, 0, 500, 0)
        lp.run(1.0)
        b = v.sim.bus
        assert b["vehicle.tau_Z"] == 0.0 and b["vehicle.tau_X"] == 0.0 and b["vehicle.tau_N"] == 0.0
        lp.stick = (1, 600, 0, 1000, 0)
        lp.run(0.5)
        assert b["vehicle.tau_Z"] < -10.0 and b["vehicle.tau_X"] > 10.0  # z above 500: up (Z is down positive)
        lp.stick = (1, 0, 0, 0, 0)
        lp.run(4.0)
        assert b["vehicle.tau_Z"] > 10.0 and b["vehicle.z"] > 0.5  # z below 500: down, and it dives
        lp.stick = (1, 0, 0, 500, 0)
        lp.run(1.0)
        lp.stick = None
        assert lp.set_mode(1, 7) == M.MAV_RESULT_DENIED  # CIRCLE: not flown
        assert lp.set_mode(1, ALT_HOLD) == M.MAV_RESULT_ACCEPTED
        z0 = float(b["vehicle.z"])
        lp.run(20.0)
        z_alt = float(b["vehicle.z"])
        assert lp.set_mode(1, POSHOLD) == M.MAV_RESULT_ACCEPTED
        p0 = (float(b["vehicle.x"]), float(b["vehicle.y"]))
        lp.run(30.0)
        p1 = (float(b["vehicle.x"]), float(b["vehicle.y"]), float(b["vehicle.z"]))
        assert lp.wait("HEARTBEAT", 1, lambda m: m.custom_mode == POSHOLD).type == M.MAV_TYPE_SUBMARINE
    finally:
        lp.close()
    assert abs(z_alt - z0) < 0.1, (z0, z_alt)
    assert math.hypot(p1[0] - p0[0], p1[1] - p0[1]) < 0.3, (p0, p1)  # in the 0.2 m/s current
    assert abs(p1[2] - z_alt) < 0.1


def test_rov_takes_mavproxys_rc_override_with_ardusubs_channel_map(tmp_path):
    """RC_CHANNELS_OVERRIDE as MAVProxy sends it (``rc 5 1700``: all 18 channels, 0 on those not overridden,
    MAVProxy's mavproxy_rc.send_rc) flies the ROV by ArduSub's map: channel 5 forward, 6 lateral, 3 throttle
    (above 1500 up), 4 yaw; a released channel (0) is neutral, not full down, and UINT16_MAX keeps its value.
    In MANUAL and STABILIZE; refused out of range (PWM 3000); ``rc clear`` (all 0) stops the forces."""

    def rc(lp, seconds=1.0, **chans):  # MAVProxy's override array: 18 channels, 0 = not overridden, resent
        ch = [0] * 18
        for k, v in chans.items():
            ch[int(k[2:]) - 1] = v
        for _ in range(round(seconds / 0.2)):
            lp.mav.rc_channels_override_send(1, 1, *ch)
            lp.run(0.2)

    lp = Loop("rov-station-keeping", tmp_path)
    try:
        b = lp.v.sim.bus
        lp.wait("HEARTBEAT", 1)
        assert lp.command(1, M.MAV_CMD_COMPONENT_ARM_DISARM, 1) == M.MAV_RESULT_ACCEPTED
        rc(lp, 4.0, ch5=1700)  # rc 5 1700: half forward (after the arming ramp)
        fwd = float(b["vehicle.tau_X"])
        assert fwd > 10.0 and b["vehicle.tau_Y"] == 0.0 and b["vehicle.tau_Z"] == 0.0 and b["vehicle.tau_N"] == 0.0
        rc(lp, ch5=1900)  # full forward: twice the force of half
        assert float(b["vehicle.tau_X"]) == pytest.approx(2.0 * fwd, rel=1e-6)
        rc(lp, ch5=65535, ch3=1900, ch4=1600, ch6=1300)  # forward kept; up, yaw to starboard, lateral to port
        assert float(b["vehicle.tau_X"]) == pytest.approx(2.0 * fwd, rel=1e-6)
        assert b["vehicle.tau_Z"] < -10.0 and b["vehicle.tau_N"] > 0.0 and b["vehicle.tau_Y"] < -1.0
        rc(lp, ch5=3000)  # out of range: refused, nothing changes
        assert float(b["vehicle.tau_X"]) == pytest.approx(2.0 * fwd, rel=1e-6)
        rc(lp)  # rc clear: every channel released
        assert b["vehicle.tau_X"] == b["vehicle.tau_Y"] == b["vehicle.tau_Z"] == b["vehicle.tau_N"] == 0.0
        assert lp.set_mode(1, STABILIZE) == M.MAV_RESULT_ACCEPTED
        rc(lp, ch5=1700)
        assert float(b["vehicle.tau_X"]) == pytest.approx(fwd, rel=1e-6)
    finally:
        lp.close()


def test_rov_goes_to_a_guided_target_and_flies_a_mission(tmp_path):
    """The ROV through the same front end as the towed UUV: GUIDED to SET_POSITION_TARGET_LOCAL_NED (north,
    east, depth), reached within 0.3 m; then a 2-item AUTO mission, both items reached (MISSION_ITEM_REACHED
    from system 1) at their depths, then POSHOLD."""
    lp = Loop("rov-station-keeping", tmp_path)
    try:
        v = lp.v
        b = v.sim.bus
        lp.wait("HEARTBEAT", 1)
        assert lp.command(1, M.MAV_CMD_COMPONENT_ARM_DISARM, 1) == M.MAV_RESULT_ACCEPTED
        assert lp.set_mode(1, GUIDED) == M.MAV_RESULT_ACCEPTED
        lp.mav.set_position_target_local_ned_send(0, 1, 1, M.MAV_FRAME_LOCAL_NED, 0b110111111000, 3.0, -2.0, 2.0,
                                                  0, 0, 0, 0, 0, 0, 0, 0)  # fmt: skip
        lp.run(40.0)
        guided = (float(b["vehicle.x"]), float(b["vehicle.y"]), float(b["vehicle.z"]))
        assert lp.upload(1, [(0.0, 0.0, 0.0), (0.0, 0.0, -1.5), (-3.0, 2.0, -3.0)]) == M.MAV_MISSION_ACCEPTED
        assert lp.set_mode(1, AUTO) == M.MAV_RESULT_ACCEPTED
        reached = []
        for _ in range(2):
            m = lp.wait("MISSION_ITEM_REACHED", 1, seconds=60.0)
            reached.append((m.seq, float(b["vehicle.z"])))
        assert lp.wait("HEARTBEAT", 1, lambda m: m.custom_mode == POSHOLD).type == M.MAV_TYPE_SUBMARINE
    finally:
        lp.close()
    assert math.dist(guided, (3.0, -2.0, 2.0)) < 0.3, guided
    assert [s for s, _ in reached] == [1, 2]
    assert abs(reached[0][1] - 1.5) <= 0.5 and abs(reached[1][1] - 3.0) <= 0.5, reached


@pytest.mark.parametrize("mode", ["guided", "auto"])
def test_rov_goes_astern_at_depth_and_stays_in_the_water(tmp_path, mode):
    """Issue 38: a target 20 m astern at 2 m depth, straight from the surface (GUIDED, or an AUTO mission
    of one item). Before the fix the ROV pitched to -51 deg (a saturated surge scaled the pitch moment
    down with it; the Munk moment of the translating hull pitched it) and climbed 3 m out of the water.
    Now: the hull is never clear of the water (depth of the origin > -h/2), pitch stays within 15 deg,
    the depth is held within 0.3 m once the ROV has reached it (within 0.1 m) and the target is reached."""
    from oceangnc.models.vehicle import load_vehicle

    lp = Loop("rov-station-keeping", tmp_path)
    try:
        lp.wait("HEARTBEAT", 1)
        assert lp.command(1, M.MAV_CMD_COMPONENT_ARM_DISARM, 1) == M.MAV_RESULT_ACCEPTED
        if mode == "guided":
            assert lp.set_mode(1, GUIDED) == M.MAV_RESULT_ACCEPTED
            lp.mav.set_position_target_local_ned_send(0, 1, 1, M.MAV_FRAME_LOCAL_NED, 0b110111111000, -20.0, 0.0,
                                                      2.0, 0, 0, 0, 0, 0, 0, 0, 0)  # fmt: skip
            lp.run(50.0)
        else:
            assert lp.upload(1, [(0.0, 0.0, 0.0), (-20.0, 0.0, -2.0)]) == M.MAV_MISSION_ACCEPTED
            assert lp.set_mode(1, AUTO) == M.MAV_RESULT_ACCEPTED
            assert lp.wait("MISSION_ITEM_REACHED", 1, seconds=60.0).seq == 1
    finally:
        df = lp.close()
    h = load_vehicle("bluerov2-heavy").hydrostatics.height
    assert df["vehicle.z"].min() > -0.5 * h, df["vehicle.z"].min()
    assert np.degrees(np.abs(df["vehicle.theta"])).max() < 15.0
    t_ref = df.loc[(df["vehicle.z"] - 2.0).abs() < 0.1, "t"].min()
    held = df[df["t"] >= t_ref]
    assert len(held) > 100 and (held["vehicle.z"] - 2.0).abs().max() < 0.3, (held["vehicle.z"] - 2.0).abs().max()
    end = df.iloc[-1]
    # GUIDED holds the target; AUTO reports the item reached at its acceptance radius and holds there
    assert math.hypot(end["vehicle.x"] + 20.0, end["vehicle.y"]) < (1.0 if mode == "guided" else 2.5)


def test_rov_estop_zeroes_the_thrust_and_rearming_ramps_it_back(tmp_path):
    """MANUAL with the stick held: DO_FLIGHTTERMINATION zeroes every thruster command at once; after the reset and a
    new arm the thrust comes back as a ramp (oceangnc.core.estop, 2 s), not a step; a stick stream that stops
    is taken as neutral after FS_PILOT_TIMEOUT (3 s)."""
    lp = Loop("rov-station-keeping", tmp_path)
    names = None
    try:
        v = lp.v
        b = v.sim.bus
        names = [k for k in b if k.startswith("vehicle.thrust_") and not k.endswith("_cmd")]

        def thrust() -> float:
            return max(abs(float(b[k])) for k in names)

        lp.wait("HEARTBEAT", 1)
        assert lp.command(1, M.MAV_CMD_COMPONENT_ARM_DISARM, 1) == M.MAV_RESULT_ACCEPTED
        lp.stick = (1, 800, 0, 500, 0)
        lp.run(3.0)
        steady = thrust()
        assert steady > 10.0
        assert lp.command(1, M.MAV_CMD_DO_FLIGHTTERMINATION, 1) == M.MAV_RESULT_ACCEPTED
        lp.run(0.5)
        assert v.estop and not v.armed
        assert all(float(b[k + "_cmd"]) == 0.0 for k in names)  # the commands at once; the thrusters' own
        assert thrust() < 0.02 * steady  # first-order lag (0.1 s in the vehicle file) lets the output decay
        assert lp.command(1, M.MAV_CMD_DO_FLIGHTTERMINATION, 0) == M.MAV_RESULT_ACCEPTED
        assert lp.command(1, M.MAV_CMD_COMPONENT_ARM_DISARM, 1) == M.MAV_RESULT_ACCEPTED
        ramp = []
        for _ in range(round(2.5 / STEP_S)):
            lp.run(STEP_S)
            ramp.append(thrust())
        lp.stick = None
        lp.run(4.0)
        assert v.sub1.stick == [0.0, 0.0, 0.0, 0.0] and float(b["vehicle.tau_X"]) == 0.0
    finally:
        lp.close()
    assert ramp[0] < 0.1 * steady, (ramp[:3], steady)  # no step back to the held stick's thrust
    assert ramp[12] < 0.6 * steady < ramp[-1] * 1.2, (ramp[12], ramp[-1], steady)  # half-way, then there


def test_rov_gcs_failsafe_is_ardusubs(tmp_path):
    """ArduSub's GCS failsafe on the ROV: the controlling ground station silent for FS_GCS_TIMEOUT (5 s)
    disarms it (FS_GCS_ENABLE 2, ArduSub's default) - not before; with FS_GCS_ENABLE 4 it enters SURFACE and
    stays armed; Rover's FS_ACTION / FS_TIMEOUT / LOIT_RADIUS are not in its table."""
    lp = Loop("rov-station-keeping", tmp_path)
    try:
        v = lp.v
        assert {"FS_ACTION", "FS_TIMEOUT", "LOIT_RADIUS"}.isdisjoint(v.params)
        lp.wait("HEARTBEAT", 1)
        assert lp.command(1, M.MAV_CMD_COMPONENT_ARM_DISARM, 1) == M.MAV_RESULT_ACCEPTED
        assert lp.set_mode(1, ALT_HOLD) == M.MAV_RESULT_ACCEPTED
        lp.heartbeats = False
        lp.run(4.5)
        assert v.armed  # not yet
        lp.run(1.0)
        assert not v.armed and any("GCS link lost, disarming" in e for _, e in v.events)
        lp.heartbeats = True
        lp.mav.param_set_send(1, 1, b"FS_GCS_ENABLE", 4, M.MAV_PARAM_TYPE_INT8)
        assert lp.wait("PARAM_VALUE", 1, lambda m: m.param_id == "FS_GCS_ENABLE").param_value == 4.0
        assert lp.command(1, M.MAV_CMD_COMPONENT_ARM_DISARM, 1) == M.MAV_RESULT_ACCEPTED
        lp.heartbeats = False
        lp.run(5.5)
        assert v.armed and v.sub1.mode == 9  # SURFACE
    finally:
        lp.close()


def test_rov_through_qgroundcontrols_connect_and_start_mission(tmp_path):
    """The client repeating QGroundControl's connect sequence (tests/mavlink_gcs.py, sysid 255/190) gets every
    answer from the ROV (FRAME_CONFIG 2 among the parameters); a mission uploaded as every ground station does
    is started as QGroundControl starts one on a disarmed ArduPilot vehicle (GUIDED - ArduSub's 4 -, arm,
    MISSION_START) and flown to its last item. Threaded vehicle at 20x, waits bounded in wall time."""
    from mavlink_gcs import GCS, qgc_connect, qgc_set_mode, upload_mission

    v = MavlinkVehicle("rov-station-keeping", listen="udp:127.0.0.1:0", speed=20.0, out_root=None).start()
    g = GCS(v.address)
    try:
        out = qgc_connect(g)
        assert all(r in (M.MAV_RESULT_ACCEPTED, M.MAV_RESULT_UNSUPPORTED) for r in out["acks"].values())
        assert out["params"]["FRAME_CONFIG"] == 2.0 and out["version"].uid == 1
        c = v.cfg_mav
        upload_mission(g, [(0.0, 0.0), (1.5, 0.0), (1.5, 1.5)], c.origin_lat_deg, c.origin_lon_deg)
        qgc_set_mode(g, GUIDED)
        g.mav.command_long_send(1, 1, M.MAV_CMD_COMPONENT_ARM_DISARM, 0, 1, 0, 0, 0, 0, 0, 0)
        assert g.ack(M.MAV_CMD_COMPONENT_ARM_DISARM).result == M.MAV_RESULT_ACCEPTED
        g.mav.command_long_send(1, 1, M.MAV_CMD_MISSION_START, 0, 0, 0, 0, 0, 0, 0, 0)
        assert g.ack(M.MAV_CMD_MISSION_START).result == M.MAV_RESULT_ACCEPTED
        assert g.wait("MISSION_ITEM_REACHED", 20.0, lambda m: m.seq == 2).seq == 2
    finally:
        g.close()
        v.stop()
    assert v.sub1.reached == [1, 2]


def test_otter_is_a_rover_boat_with_rover_modes(tmp_path):
    """otter-waypoints over MAVLink: MAV_TYPE_SURFACE_BOAT with Rover's modes (HOLD at start, MANUAL refused
    because the scenario takes no stick, an ArduSub-only number refused), no FRAME_CONFIG."""
    lp = Loop("otter-waypoints", tmp_path)
    try:
        hb = lp.wait("HEARTBEAT", 1)
        assert hb.type == M.MAV_TYPE_SURFACE_BOAT and hb.custom_mode == 4  # Rover HOLD
        assert lp.v.sub1 is None and "FRAME_CONFIG" not in lp.v.params
        assert lp.set_mode(1, 19) == M.MAV_RESULT_DENIED  # 19 is ArduSub's MANUAL, not a Rover mode
        assert lp.set_mode(1, 10) == M.MAV_RESULT_ACCEPTED  # Rover AUTO: the scenario's own route
        assert lp.wait("HEARTBEAT", 1, lambda m: m.custom_mode == 10).type == M.MAV_TYPE_SURFACE_BOAT
    finally:
        lp.close()
