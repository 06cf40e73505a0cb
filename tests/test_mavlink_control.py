"""Only the controlling ground station keeps a vehicle out of failsafe (issue 41).

A third party (system 66) sends one command and then heartbeats while the controlling ground station
(system 255, which armed the vehicle and chose its mode) is silent. ArduPilot's GCS failsafe is fed by the
heartbeats of SYSID_MYGCS only (GCS_MAVLINK::handle_heartbeat), so the failsafe must come on time whatever the
command was - a read such as MAV_CMD_REQUEST_MESSAGE above all. Only an accepted control act (arming or
disarming, a mode change, a mission start) hands control over, and then the new controller's heartbeats are the
ones that count. Swept over every MAV_CMD id of pymavlink's dialect, as COMMAND_LONG and as COMMAND_INT, to
the Rover (usv-remote), the towed UUV (system 2 of combined-survey) and the BlueROV2 (rov-station-keeping).

The messages are handed to the vehicle's dispatch directly and its failsafes run on a fake clock: no
simulation is stepped, no wall time is waited.
"""

from __future__ import annotations

import pytest

from oceangnc.mavlink.protocol import mavlink as M
from oceangnc.mavlink.vehicle import MavlinkVehicle

GCS_ID, INTRUDER = 255, 66
ROVER_MANUAL, ROVER_HOLD, SUB_MANUAL = 0, 4, 19
#: the control acts: accepted from a ground station, they make it the controller
CONTROL_ACTS = {
    M.MAV_CMD_COMPONENT_ARM_DISARM,
    M.MAV_CMD_DO_SET_MODE,
    M.MAV_CMD_MISSION_START,
    M.MAV_CMD_NAV_RETURN_TO_LAUNCH,
    M.MAV_CMD_NAV_LOITER_UNLIM,
    M.MAV_CMD_DO_REPOSITION,
}
#: parameters a vehicle accepts (the reads among them answered with their message): the attack as reported
#: used REQUEST_MESSAGE for AUTOPILOT_VERSION; every other id is also sent with all parameters zero
ACCEPTED_PARAMS = {
    M.MAV_CMD_REQUEST_MESSAGE: (M.MAVLINK_MSG_ID_AUTOPILOT_VERSION,),
    M.MAV_CMD_SET_MESSAGE_INTERVAL: (M.MAVLINK_MSG_ID_HEARTBEAT, 1e6),
    M.MAV_CMD_GET_MESSAGE_INTERVAL: (M.MAVLINK_MSG_ID_HEARTBEAT,),
    M.MAV_CMD_DO_CHANGE_SPEED: (1, 1.0),
    M.MAV_CMD_DO_SET_HOME: (1,),
    M.MAV_CMD_DO_SET_MISSION_CURRENT: (1,),
    M.MAV_CMD_COMPONENT_ARM_DISARM: (1,),
    M.MAV_CMD_DO_SET_MODE: (1, ROVER_MANUAL),
}
TIMEOUT = 1.0  # FS_GCS_TIMEOUT here, s (fake clock)
STEP = 0.1


class FakeClock:
    def __init__(self):
        self.t = 1000.0

    def __call__(self):
        return self.t


class Sender:
    """Messages from one system, packed so that the vehicle sees their source system."""

    def __init__(self, sysid: int):
        self.mav = M.MAVLink(None, srcSystem=sysid, srcComponent=190)

    def __call__(self, v, msg) -> None:
        msg.pack(self.mav)
        v._handle(msg)

    def heartbeat(self, v) -> None:
        self(v, self.mav.heartbeat_encode(M.MAV_TYPE_GCS, M.MAV_AUTOPILOT_INVALID, 0, 0, 0))

    def command(self, v, target: int, cmd: int, p=(), as_int: bool = False) -> None:
        p = [float(x) for x in p] + [0.0] * (7 - len(p))
        if as_int:
            x, y = round(p[4] * 1e7), round(p[5] * 1e7)
            enc = self.mav.command_int_encode(target, 1, 0, cmd, 0, 0, *p[:4], x, y, p[6])
        else:
            enc = self.mav.command_long_encode(target, 1, cmd, 0, *p)
        self(v, enc)


class Acks:
    """What the vehicle answers (every system's packets): the COMMAND_ACKs, in order."""

    def __init__(self, v):
        self.parser = M.MAVLink(None)
        self.acks: list[tuple[int, int]] = []
        v.mav.file = v.mav_uuv.file = self

    def write(self, b) -> None:
        for m in self.parser.parse_buffer(bytes(b)) or []:
            if m.get_type() == "COMMAND_ACK":
                self.acks.append((m.command, m.result))


def _failsafes(v, now: float) -> None:
    v._watchdog(now)
    for sub in (v.sub1, v.sub2):
        if sub is not None:
            sub.watchdog(now, gcs=sub is v.sub1)


def _in_failsafe(v) -> bool:
    if v.sub1 is not None:  # ArduSub's GCS failsafe: FS_GCS_ENABLE 2, disarm
        return v.sub1.failsafe and not v.armed
    return v.failsafe and v.mode == ROVER_HOLD


def _take_control(v, clk, gcs) -> None:
    """The controlling ground station's acts: heartbeat, arm, the pilot's mode (Rover MANUAL, ArduSub MANUAL)."""
    gcs.heartbeat(v)
    if v.estop:
        gcs.command(v, 1, M.MAV_CMD_DO_FLIGHTTERMINATION, (0,))
    gcs.command(v, 1, M.MAV_CMD_COMPONENT_ARM_DISARM, (1,))
    mode = SUB_MANUAL if v.sub1 is not None else ROVER_MANUAL
    gcs(v, gcs.mav.set_mode_encode(1, M.MAV_MODE_FLAG_CUSTOM_MODE_ENABLED, mode))
    gcs.heartbeat(v)
    _failsafes(v, clk.t)
    assert v._controller() == GCS_ID and v.armed and not _in_failsafe(v)


VEHICLES = {
    "rover": ("usv-remote", 1),
    "towed-uuv": ("combined-survey", 2),
    "bluerov2": ("rov-station-keeping", 1),
}


@pytest.mark.parametrize("which", list(VEHICLES))
def test_a_third_partys_command_and_heartbeats_never_hold_off_the_failsafe(which):
    scenario, target = VEHICLES[which]
    clk = FakeClock()
    v = MavlinkVehicle(scenario, listen="udp:127.0.0.1:0", out_root=None, clock=clk, mav={"gcs_timeout_s": TIMEOUT})
    gcs, intruder = Sender(GCS_ID), Sender(INTRUDER)
    answers = Acks(v)
    cmds = sorted(M.enums["MAV_CMD"])
    handed_over, attacks = set(), 0
    try:
        for cmd in cmds:
            for params in {(), ACCEPTED_PARAMS.get(cmd, ())}:
                for as_int in (False, True):
                    clk.t += STEP
                    _take_control(v, clk, gcs)
                    t_last = clk.t  # the controlling ground station's last heartbeat
                    intruder.heartbeat(v)
                    n = len(answers.acks)
                    intruder.command(v, target, cmd, params, as_int)
                    assert len(answers.acks) == n + 1 and answers.acks[-1][0] == cmd, f"command {cmd}: one answer"
                    acked = answers.acks[-1]
                    control_act = cmd in CONTROL_ACTS and acked[1] == M.MAV_RESULT_ACCEPTED
                    t_fs = None
                    while clk.t < t_last + TIMEOUT + 1.0:
                        clk.t += STEP
                        intruder.heartbeat(v)  # 10 Hz heartbeats of the third party
                        _failsafes(v, clk.t)
                        if t_fs is None and _in_failsafe(v):
                            t_fs = clk.t
                    what = f"{'COMMAND_INT' if as_int else 'COMMAND_LONG'} {cmd} {params} to system {target}"
                    if cmd == M.MAV_CMD_DO_REPOSITION and acked[1] == M.MAV_RESULT_ACCEPTED:
                        control_act = v._controller() == INTRUDER  # a control act when it changed the mode
                    if control_act:  # an explicit act hands control over: the new controller's heartbeats count
                        handed_over.add(cmd)
                        assert v._controller() == INTRUDER, what
                        assert t_fs is None, f"{what}: the new controller's heartbeats did not count"
                    else:
                        attacks += 1
                        assert v._controller() == GCS_ID, f"{what} took control"
                        assert t_fs is not None, f"{what} + heartbeats held off the failsafe"
                        assert t_last + TIMEOUT < t_fs <= t_last + TIMEOUT + 2 * STEP + 1e-9, what
        assert attacks > 2 * len(cmds)
        assert {M.MAV_CMD_COMPONENT_ARM_DISARM, M.MAV_CMD_DO_SET_MODE} <= handed_over <= CONTROL_ACTS
    finally:
        v.stop()


def test_a_third_partys_sticks_neither_steer_nor_feed_the_link():
    """ArduPilot accepts MANUAL_CONTROL and RC_CHANNELS_OVERRIDE only from its ground station (and counts them
    as its heartbeat): a third party's stick stream neither moves the stick nor holds off the failsafe."""
    clk = FakeClock()
    v = MavlinkVehicle("usv-remote", listen="udp:127.0.0.1:0", out_root=None, clock=clk, mav={"gcs_timeout_s": TIMEOUT})
    gcs, intruder = Sender(GCS_ID), Sender(INTRUDER)
    try:
        _take_control(v, clk, gcs)
        t_last = clk.t
        t_fs = None
        while clk.t < t_last + TIMEOUT + 0.5:
            clk.t += STEP
            intruder(v, intruder.mav.manual_control_encode(1, 800, 0, 0, 300, 0))
            intruder(v, intruder.mav.rc_channels_override_encode(1, 1, 1900, 0, 1900, 0, 0, 0, 0, 0))
            assert v.stick == (0.0, 0.0)
            _failsafes(v, clk.t)
            if t_fs is None and _in_failsafe(v):
                t_fs = clk.t
        assert t_fs is not None and t_fs <= t_last + TIMEOUT + 2 * STEP + 1e-9
        # the controlling ground station's stick does reach the vehicle, and feeds its link
        _take_control(v, clk, gcs)
        gcs(v, gcs.mav.manual_control_encode(1, 500, 0, 0, 0, 0))
        assert v.stick == (0.5, 0.0) and v.t_gcs == clk.t
    finally:
        v.stop()
