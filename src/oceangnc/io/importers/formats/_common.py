"""Conversions shared by the readers: servo PWM, lat/lon to north/east, quaternions, truncation."""

from __future__ import annotations

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
    from ....mavlink.geo import latlon_to_ned

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
