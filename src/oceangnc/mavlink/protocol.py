"""MAVLink constants, the ArduPilot Rover mode table and the message/rate table of the vehicle.

The vehicle speaks MAVLink 2 with the ``ardupilotmega`` dialect of ``pymavlink`` and presents itself
as an ArduPilot Rover (``MAV_AUTOPILOT_ARDUPILOTMEGA``), so ground stations (QGroundControl, Mission
Planner, MAVProxy) show Rover's flight-mode names for the ``custom_mode`` numbers it reports.
"""

from __future__ import annotations

from ..io.mavlink_dialect import mavlink

#: ArduPilot Rover mode numbers (ArduPilot ``Rover/mode.h``) that the vehicle accepts, and what they do.
ROVER_MODES = {
    0: ("MANUAL", "stick straight to the thrusters (open loop): MANUAL_CONTROL / RC_CHANNELS_OVERRIDE"),
    1: ("ACRO", "stick -> speed and yaw-rate setpoints of the scenario's closed loops"),
    4: ("HOLD", "stop: speed and yaw-rate setpoints zero (the failsafe mode)"),
    5: ("LOITER", "hold position within LOIT_RADIUS of where the mode was entered (back on a one-point route)"),
    10: ("AUTO", "fly the mission (MISSION_ITEM_INT waypoints) with the scenario's own guidance"),
    11: ("RTL", "a one-point route home (first fix, the arming point, or DO_SET_HOME), then loiter there"),
    12: ("SMART_RTL", "retrace the path flown since arming back to the arming point, then loiter there"),
    15: (
        "GUIDED",
        "go to a point (DO_REPOSITION, SET_POSITION_TARGET_GLOBAL_INT, MISSION_ITEM current = 2), loiter there",
    ),
}
MODE_NUMBERS = {name: num for num, (name, _) in ROVER_MODES.items()}
MANUAL, ACRO, HOLD, LOITER, AUTO, RTL, SMART_RTL, GUIDED = 0, 1, 4, 5, 10, 11, 12, 15
#: Rover modes a GCS may ask for that this vehicle does not fly (refused with MAV_RESULT_DENIED).
ROVER_OTHER = {3: "STEERING", 6: "FOLLOW", 7: "SIMPLE", 8: "DOCK", 9: "CIRCLE", 16: "INITIALISING"}
#: modes in which the operator's stick drives the vehicle
STICK_MODES = (MANUAL, ACRO)
#: modes that fly short routes of their own through the scenario's guidance (oceangnc.mavlink.nav)
NAV_MODES = (LOITER, RTL, SMART_RTL, GUIDED)

#: telemetry the vehicle sends: message -> (rate Hz, content). Rates are ArduPilot's SRx_* defaults
#: for a telemetry link (SR_EXT_STAT 2, SR_POSITION 3..10, SR_EXTRA1 4..10, SR_EXTRA2 4).
TELEMETRY = {
    "HEARTBEAT": (
        1.0,
        (
            "type SURFACE_BOAT (USV, system 1) / SUBMARINE (UUV, system 2), ArduPilot autopilot, "
            "armed flag, Rover custom_mode, system_status (STANDBY / ACTIVE / CRITICAL in failsafe / "
            "EMERGENCY after an e-stop)"
        ),
    ),
    "SYS_STATUS": (
        1.0,
        (
            "sensors present/enabled/healthy (GPS, gyro, accelerometer, compass, AHRS, motors, battery, "
            "pre-arm check: healthy while arming would be accepted; geofence: healthy, not present), battery "
            "voltage, current and remaining %, comm drop rate = malformed share, errors_count1 malformed, "
            "_count2 unknown, _count3 out of range"
        ),
    ),
    "GPS_RAW_INT": (
        5.0,
        (
            "GPS fix (the scenario's gps.x/gps.y if it has a GPS, else the true position): lat, "
            "lon, alt, fix_type 3 (0 in an outage), ground speed and course"
        ),
    ),
    "GLOBAL_POSITION_INT": (
        10.0,
        (
            "true position as lat/lon about the origin, alt (UUV: origin alt - depth), "
            "relative_alt (UUV: -depth), NED velocity, heading"
        ),
    ),
    "ATTITUDE": (10.0, "roll, pitch, yaw (rad), body rates (rad/s)"),
    "VFR_HUD": (4.0, "ground speed, heading (deg), throttle % (mean thruster command / max), alt, climb"),
    "NAMED_VALUE_FLOAT": (2.0, ("cable_T: cable top tension (N); uuv_depth: UUV depth (m); rx_bad: malformed packets")),
    "MISSION_CURRENT": (
        1.0,
        "mission item being flown (seq), total (items without home), mission_state, mission_mode (1 in AUTO)",
    ),
    "BATTERY_STATUS": (
        1.0,
        "the battery model (oceangnc.mavlink.battery): cell voltages, current, charge and energy drawn, "
        "remaining %, time remaining at the present draw",
    ),
    "HOME_POSITION": (0.0, "home (first fix, arming point or DO_SET_HOME); on request or SET_MESSAGE_INTERVAL"),
    "SERVO_OUTPUT_RAW": (
        10.0,
        (
            "thruster commands as PWM (skid steer, ArduPilot SERVOn_FUNCTION 73/74): servo1 "
            "port, servo3 starboard, 1500 us stop, +-400 us full ahead / astern"
        ),
    ),
}
#: REQUEST_DATA_STREAM's stream ids -> the messages each sets the rate of (ArduPilot's grouping)
STREAMS = {
    mavlink.MAV_DATA_STREAM_RAW_SENSORS: (),
    mavlink.MAV_DATA_STREAM_EXTENDED_STATUS: ("SYS_STATUS", "GPS_RAW_INT", "MISSION_CURRENT"),
    mavlink.MAV_DATA_STREAM_RC_CHANNELS: ("SERVO_OUTPUT_RAW",),
    mavlink.MAV_DATA_STREAM_POSITION: ("GLOBAL_POSITION_INT",),
    mavlink.MAV_DATA_STREAM_EXTRA1: ("ATTITUDE",),
    mavlink.MAV_DATA_STREAM_EXTRA2: ("VFR_HUD",),
    mavlink.MAV_DATA_STREAM_EXTRA3: ("BATTERY_STATUS", "NAMED_VALUE_FLOAT"),
}
#: highest telemetry rate a ground station may ask for (the loop runs at 100 Hz), Hz
MAX_RATE_HZ = 50.0

#: messages the vehicle reacts to
ACCEPTED = {
    "HEARTBEAT": "keeps the GCS link alive (the failsafe watchdog), from the controlling ground station only",
    "COMMAND_LONG / COMMAND_INT": "MAV_CMD_COMPONENT_ARM_DISARM (400), MAV_CMD_DO_SET_MODE (176), "
    "MAV_CMD_DO_FLIGHTTERMINATION (185: e-stop, param1 1 engage / 0 reset), MAV_CMD_DO_SET_MISSION_CURRENT (224), "
    "MAV_CMD_MISSION_START (300: AUTO from item param1), MAV_CMD_DO_REPOSITION (192: GUIDED go-to), "
    "MAV_CMD_DO_CHANGE_SPEED (178), MAV_CMD_DO_SET_HOME (179), MAV_CMD_NAV_RETURN_TO_LAUNCH (20), "
    "MAV_CMD_NAV_LOITER_UNLIM (17: LOITER), MAV_CMD_SET_MESSAGE_INTERVAL (511), MAV_CMD_GET_MESSAGE_INTERVAL (510), "
    "MAV_CMD_REQUEST_MESSAGE (512), MAV_CMD_REQUEST_AUTOPILOT_CAPABILITIES (520), "
    "MAV_CMD_GET_HOME_POSITION (410); others (e.g. MAV_CMD_REQUEST_PROTOCOL_VERSION, as ArduPilot): COMMAND_ACK "
    "UNSUPPORTED",
    "SET_MODE": "custom_mode = Rover mode number (table above)",
    "MANUAL_CONTROL": "x: surge, r: yaw, each -1000..1000 (INT16_MAX: axis unused)",
    "RC_CHANNELS_OVERRIDE": "chan1 steering, chan3 throttle, PWM 1100..1900 about 1500 (Rover convention); "
    "0 / 65535: released; an ArduSub system (a ROV, the towed UUV): chan5 forward, chan6 lateral, chan3 "
    "throttle, chan4 yaw (ArduSub's map), 65535 kept, 0 neutral",
    "SET_POSITION_TARGET_GLOBAL_INT": "GUIDED destination (position targets in a global frame; GUIDED only)",
    "MISSION_COUNT / MISSION_ITEM_INT / MISSION_ITEM": "mission upload (vehicle requests with MISSION_REQUEST_INT); "
    "an item with current = 2 is a GUIDED destination",
    "MISSION_REQUEST_LIST / MISSION_REQUEST_INT / MISSION_REQUEST": "mission download",
    "MISSION_CLEAR_ALL, MISSION_SET_CURRENT, MISSION_ACK": "mission management",
    "PARAM_REQUEST_LIST / PARAM_REQUEST_READ / PARAM_SET": "the parameter protocol (oceangnc.mavlink.params)",
    "REQUEST_DATA_STREAM": "rates of ArduPilot's stream groups (STREAMS)",
    "TIMESYNC": "answered (tc1 = the vehicle's clock, ts1 echoed)",
    "FILE_TRANSFER_PROTOCOL": "MAVFTP: every request answered with a NAK (no file system), so clients fall back "
    "to the message protocols at once",
}

MAV_STATE = mavlink  # alias for readability of the enum constants


def mode_name(num: int) -> str:
    if num in ROVER_MODES:
        return ROVER_MODES[num][0]
    return ROVER_OTHER.get(num, f"mode {num}")
