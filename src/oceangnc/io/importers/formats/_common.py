"""Conversions shared by the readers: servo PWM, lat/lon to north/east, quaternions, truncation."""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np

from ....errors import InputError

PWM_CENTER, PWM_SPAN = 1500.0, 400.0
#: servo outputs 1 and 3 of an ArduPilot Rover: skid steering (SERVOn_FUNCTION 73 ThrottleLeft / 74
#: ThrottleRight, twin thrusters) or rudder (26 GroundSteering / 70 Throttle, ArduPilot's default)
SERVO_LAYOUTS = {"skid": ("act.left", "act.right"), "rudder": ("act.steer", "act.throttle")}


def servo_names(layout: str) -> tuple[str, str]:
    if layout not in SERVO_LAYOUTS:
        raise InputError(f"--servos {layout}: allowed {', '.join(SERVO_LAYOUTS)}")
    return SERVO_LAYOUTS[layout]


def pwm(v):
    """Servo PWM (us) -> -1..1 about 1500 us with +-400 us full scale; 0 and 65535 (no output) -> NaN."""
    v = np.asarray(v, float)
    out = np.clip((v - PWM_CENTER) / PWM_SPAN, -1.0, 1.0)
    out[(v <= 0) | (v >= 65535)] = np.nan
    return out


def north_east(lat, lon, origin):
    """lat, lon (deg) -> north, east (m) about ``origin`` (default the first valid fix), and the origin."""
    from ...geo import latlon_to_ned

    lat = np.asarray(lat, float)
    lon = np.asarray(lon, float)
    ok = np.isfinite(lat) & np.isfinite(lon) & ((np.abs(lat) > 1e-9) | (np.abs(lon) > 1e-9))
    if not ok.any():
        return None, None, None
    o = origin if origin is not None else (float(lat[ok][0]), float(lon[ok][0]))
    ne = np.array([latlon_to_ned(a, b, o[0], o[1]) if k else (np.nan, np.nan) for a, b, k in zip(lat, lon, ok)])
    return ne[:, 0], ne[:, 1], o


def quat_euler(w, x, y, z):
    """ZYX Euler angles (roll, pitch, yaw) of unit quaternions (w, x, y, z)."""
    roll = np.arctan2(2 * (w * x + y * z), 1 - 2 * (x * x + y * y))
    pitch = np.arcsin(np.clip(2 * (w * y - z * x), -1, 1))
    yaw = np.arctan2(2 * (w * z + x * y), 1 - 2 * (y * y + z * z))
    return roll, pitch, yaw


def truncated(path: Path, what: str, allow: bool, meta: dict) -> None:
    """Record a truncated log in ``meta``; InputError unless the truncation is allowed."""
    meta["truncated"] = what
    if not allow:
        raise InputError(f"{path}: truncated log ({what}); pass --allow-truncated to import the complete records")


# -- vehicle type ---------------------------------------------------------------------------------------------

#: classes a log's vehicle is put in; identification of a boat accepts the marine ones (and an unknown type)
MARINE = ("boat", "submarine")
_MAV_TYPE_CLASS = {
    1: "fixed-wing",
    2: "multirotor",
    3: "multirotor",
    4: "helicopter",
    5: "antenna tracker",
    7: "airship",
    8: "balloon",
    9: "rocket",
    10: "ground rover",
    11: "boat",
    12: "submarine",
    13: "multirotor",
    14: "multirotor",
    15: "multirotor",
    16: "flapping wing",
    17: "kite",
    19: "VTOL",
    20: "VTOL",
    21: "VTOL",
    22: "VTOL",
    23: "VTOL",
    24: "VTOL",
    25: "VTOL",
    28: "parafoil",
    29: "multirotor",
    35: "multirotor",
    43: "multirotor",
}


def mav_type_class(mav_type: int) -> str | None:
    """MAVLink ``MAV_TYPE`` -> vehicle class (None for generic / unknown / not a vehicle)."""
    return _MAV_TYPE_CLASS.get(int(mav_type))


def mav_type_name(mav_type: int) -> str:
    from ...mavlink_dialect import mavlink as M

    e = M.enums["MAV_TYPE"].get(int(mav_type))
    return e.name if e is not None else f"MAV_TYPE {int(mav_type)}"


def vehicle(kind: str | None, source: str) -> dict:
    """The ``vehicle`` entry of an import report: class, where it was read, marine or not (None: unknown)."""
    return {"type": kind or "unknown", "from": source, "marine": (kind in MARINE) if kind else None}


# -- ArduPilot servo outputs ----------------------------------------------------------------------------------

#: ArduPilot ``SERVOn_FUNCTION`` values of a boat's thrusters and rudder -> standard signal
SERVO_FUNCTIONS = {73: "act.left", 74: "act.right", 26: "act.steer", 70: "act.throttle"}
_FUNCTION_NAMES = {73: "ThrottleLeft", 74: "ThrottleRight", 26: "GroundSteering", 70: "Throttle"}
#: Motor1..8 and Motor9..12: a multirotor's (or a Sub's vectored thrusters')
MOTOR_FUNCTIONS = frozenset(range(33, 41)) | frozenset(range(82, 86))


def servo_map(params: dict, servos: str | None, channels, kind: str | None = None) -> tuple[dict, list[str]]:
    """Which servo output carries which standard signal: ``{signal: (channel, trim, min, max, reversed)}``
    and the notes that say how it was decided.

    ``servos`` given (``--servos skid|rudder``): outputs 1 and 3 as that layout. Else the log's
    ``SERVOn_FUNCTION`` parameters (73/74 left/right throttle of skid steering, 26 steering, 70 throttle),
    with each output's SERVOn_TRIM/MIN/MAX/REVERSED; a log whose outputs are motors (33-40: a
    multirotor's) maps none; a log without the parameters reads outputs 1 and 3 as skid steering, unless
    ``kind`` names the vehicle's class when it is known to be no boat (a ground rover, a multirotor). ``channels``: the output numbers the log records.
    """

    def cal(n):
        g = params.get
        return (
            n,
            float(g(f"SERVO{n}_TRIM", PWM_CENTER)),
            float(g(f"SERVO{n}_MIN", PWM_CENTER - PWM_SPAN)),
            float(g(f"SERVO{n}_MAX", PWM_CENTER + PWM_SPAN)),
            bool(round(float(g(f"SERVO{n}_REVERSED", 0)))),
        )

    fn = {}
    for n in range(1, 33):
        v = params.get(f"SERVO{n}_FUNCTION")
        if v is not None and math.isfinite(float(v)):
            fn[n] = int(round(float(v)))
    if servos is not None:
        a, b = servo_names(servos)
        notes = [f"servo outputs 1 and 3 as --servos {servos} ({a}, {b})"]
        found = {k: n for n, k in ((n, SERVO_FUNCTIONS.get(f)) for n, f in fn.items()) if k}
        if fn and (found.get(a) not in (None, 1) or found.get(b) not in (None, 3)):
            notes.append(
                "the log's SERVOn_FUNCTION says otherwise ("
                + ", ".join(f"SERVO{n}_FUNCTION={f}" for n, f in sorted(fn.items()) if f in SERVO_FUNCTIONS)
                + "); --servos wins"
            )
        return {a: cal(1), b: cal(3)}, notes
    if not fn and kind is not None and kind not in MARINE:
        return {}, [
            f"no actuators imported: no SERVOn_FUNCTION parameters in the log and the vehicle is a {kind} "
            "(--servos skid|rudder reads outputs 1 and 3 anyway)"
        ]
    if not fn:
        a, b = servo_names("skid")
        return {a: cal(1), b: cal(3)}, [
            "no SERVOn_FUNCTION parameters in the log: outputs 1 and 3 read as skid steering (act.left, "
            "act.right); --servos rudder for steering / throttle"
        ]
    have = set(channels)
    out, used = {}, []
    for n, f in sorted(fn.items()):
        sig = SERVO_FUNCTIONS.get(f)
        if sig is None or sig in out:
            continue
        if n not in have:
            used.append(f"SERVO{n}_FUNCTION={f} ({_FUNCTION_NAMES[f]}) but output {n} is not logged")
            continue
        out[sig] = cal(n)
        used.append(f"SERVO{n}_FUNCTION={f} ({_FUNCTION_NAMES[f]}) -> {sig}")
    if out:
        return out, ["servo outputs from the log's parameters: " + ", ".join(used)]
    motors = sorted(n for n, f in fn.items() if f in MOTOR_FUNCTIONS)
    why = (
        f"outputs {', '.join(map(str, motors))} are motors (SERVOn_FUNCTION 33-40)"
        if motors
        else "no output is a thruster or rudder (SERVOn_FUNCTION 73, 74, 26, 70)"
    )
    return {}, [f"no actuators imported: {why}" + (f"; {'; '.join(used)}" if used else "")]


def servo_norm(v, trim: float, lo: float, hi: float, reverse: bool):
    """Servo PWM (us) -> -1..1 about the output's trim (ArduPilot's SERVOn_TRIM / MIN / MAX / REVERSED);
    0 and 65535 (no output) -> NaN."""
    v = np.asarray(v, float)
    up, down = max(hi - trim, 1e-9), max(trim - lo, 1e-9)
    x = np.where(v >= trim, (v - trim) / up, (v - trim) / down)
    x = np.clip(-x if reverse else x, -1.0, 1.0)
    x[(v <= 0) | (v >= 65535)] = np.nan
    return x
