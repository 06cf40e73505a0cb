"""Readers of each field-log format -> raw series ``{signal: (t s, values SI)}`` and metadata.

Conventions converted at this edge (and nowhere else):

* ArduPilot (DataFlash and MAVLink): angles in deg or cdeg -> rad; lat/lon in deg or 1e-7 deg ->
  north/east m about the origin (:mod:`oceangnc.mavlink.geo`); speeds in cm/s -> m/s; servo PWM
  about 1500 us with +-400 us full scale -> -1..1 (skid-steer boat: output 1 = left/port throttle,
  output 3 = right/starboard throttle, ArduPilot SERVOn_FUNCTION 73/74).
* PX4 ULog: ``vehicle_local_position`` is already NED (x north, y east, z down, m); attitude
  quaternion (w, x, y, z) -> Euler ZYX; ``actuator_motors.control[0/1]`` (-1..1) left/right.
* ROS 2 (REP 103/105): ``nav_msgs/Odometry`` pose is ENU (x east, y north, z up) with a FLU body:
  north = y, east = x, down = -z, heading psi_NED = pi/2 - yaw_ENU, r_NED = -omega_z(FLU),
  body velocity (u, v) = (vx, -vy); ``sensor_msgs/Imu`` the same; ``sensor_msgs/NavSatFix`` lat/lon deg.
"""

from __future__ import annotations

import math
import struct
from pathlib import Path

import numpy as np

from ...errors import InputError

PWM_CENTER, PWM_SPAN = 1500.0, 400.0
#: servo outputs 1 and 3 of an ArduPilot Rover: skid steering (SERVOn_FUNCTION 73 ThrottleLeft / 74
#: ThrottleRight, twin thrusters) or rudder (26 GroundSteering / 70 Throttle, ArduPilot's default)
SERVO_LAYOUTS = {"skid": ("act.left", "act.right"), "rudder": ("act.steer", "act.throttle")}


def _servo_names(layout: str) -> tuple[str, str]:
    if layout not in SERVO_LAYOUTS:
        raise InputError(f"--servos {layout}: allowed {', '.join(SERVO_LAYOUTS)}")
    return SERVO_LAYOUTS[layout]


def _pwm(v):
    v = np.asarray(v, float)
    out = np.clip((v - PWM_CENTER) / PWM_SPAN, -1.0, 1.0)
    out[(v <= 0) | (v >= 65535)] = np.nan
    return out


def _ne(lat, lon, origin):
    from ...mavlink.geo import latlon_to_ned

    lat = np.asarray(lat, float)
    lon = np.asarray(lon, float)
    ok = np.isfinite(lat) & np.isfinite(lon) & ((np.abs(lat) > 1e-9) | (np.abs(lon) > 1e-9))
    if not ok.any():
        return None, None, None
    o = origin if origin is not None else (float(lat[ok][0]), float(lon[ok][0]))
    ne = np.array([latlon_to_ned(a, b, o[0], o[1]) if k else (np.nan, np.nan) for a, b, k in zip(lat, lon, ok)])
    return ne[:, 0], ne[:, 1], o


def _quat_euler(w, x, y, z):
    """ZYX Euler angles (roll, pitch, yaw) of unit quaternions (w, x, y, z)."""
    roll = np.arctan2(2 * (w * x + y * z), 1 - 2 * (x * x + y * y))
    pitch = np.arcsin(np.clip(2 * (w * y - z * x), -1, 1))
    yaw = np.arctan2(2 * (w * z + x * y), 1 - 2 * (y * y + z * z))
    return roll, pitch, yaw


def _truncated(path: Path, what: str, allow: bool, meta: dict) -> None:
    meta["truncated"] = what
    if not allow:
        raise InputError(f"{path}: truncated log ({what}); pass --allow-truncated to import the complete records")


# -- MAVLink telemetry log (.tlog) ------------------------------------------------------------------------


def read_tlog(
    path: Path, allow_truncated: bool = False, system: int | None = None, origin=None, servos: str = "skid", **_
):
    """MAVLink telemetry log: records of an 8-byte big-endian UNIX time (us) and one MAVLink frame.

    Time base: the vehicle's clock (``time_boot_ms`` / ``time_usec``) where a message has one, else the
    record's time stamp shifted by the median offset between the two (so both share one axis).
    """
    from ...mavlink.protocol import mavlink as M

    data = path.read_bytes()
    if len(data) < 20:
        raise InputError(f"{path}: {len(data)} bytes: not a telemetry log (no complete record)")
    parser = M.MAVLink(None)
    parser.robust_parsing = True
    pos, n_bad, n_ok = 0, 0, 0
    recs: dict[str, list] = {}
    meta: dict = {}
    while pos + 8 < len(data):
        stamp = struct.unpack(">Q", data[pos : pos + 8])[0] * 1e-6
        b = data[pos + 8]
        if b == 0xFD and pos + 10 < len(data):
            n = data[pos + 9] + 12 + (13 if data[pos + 10] & 1 else 0)
        elif b == 0xFE and pos + 9 < len(data):
            n = data[pos + 9] + 8
        else:
            n_bad += 1
            pos += 1
            if n_bad > 1000 and n_bad > n_ok:
                raise InputError(
                    f"{path}: corrupt telemetry log: no MAVLink frame at byte {pos} ({n_bad} bad bytes, {n_ok} frames)"
                )
            continue
        if pos + 8 + n > len(data):
            _truncated(
                path, f"last record at byte {pos} needs {n} bytes, {len(data) - pos - 8} left", allow_truncated, meta
            )
            break
        parser.buf = bytearray()
        parser.buf_index = 0
        parser.expected_length = M.HEADER_LEN_V1 + 2
        msgs = parser.parse_buffer(data[pos + 8 : pos + 8 + n]) or []
        pos += 8 + n
        for m in msgs:
            kind = m.get_type()
            if kind == "BAD_DATA" or kind.startswith("UNKNOWN"):
                n_bad += 1
                continue
            n_ok += 1
            if system is not None and m.get_srcSystem() != system:
                continue
            if system is None and kind in ("HEARTBEAT",) and m.type == M.MAV_TYPE_GCS:
                continue
            recs.setdefault(f"{m.get_srcSystem()}:{kind}", []).append((stamp, m))
    if n_ok == 0:
        raise InputError(f"{path}: corrupt telemetry log: no valid MAVLink message")
    if n_bad > 0.2 * (n_ok + n_bad):
        raise InputError(f"{path}: corrupt telemetry log: {n_bad} bad frames of {n_ok + n_bad}")
    systems = sorted(
        {int(k.split(":")[0]) for k in recs if k.endswith(":HEARTBEAT")} or {int(k.split(":")[0]) for k in recs}
    )
    sysid = system if system is not None else (systems[0] if systems else 1)

    def get(kind):
        return recs.get(f"{sysid}:{kind}", [])

    # clock offset: record stamp - vehicle time
    offs = [s - m.time_boot_ms * 1e-3 for s, m in get("GLOBAL_POSITION_INT") + get("ATTITUDE")]
    off = float(np.median(offs)) if offs else 0.0

    def t_of(s, m):
        if hasattr(m, "time_boot_ms"):
            return m.time_boot_ms * 1e-3
        if hasattr(m, "time_usec") and m.get_type() not in ("GPS_RAW_INT",):
            return m.time_usec * 1e-6
        return s - off

    out: dict = {}

    def put(name, rows, fn):
        if rows:
            out[name] = (np.array([t_of(s, m) for s, m in rows]), np.array([fn(m) for _, m in rows], float))

    gp = get("GLOBAL_POSITION_INT")
    if gp:
        x, y, o = _ne([m.lat * 1e-7 for _, m in gp], [m.lon * 1e-7 for _, m in gp], origin)
        if x is not None:
            t = np.array([t_of(s, m) for s, m in gp])
            out["usv.x"], out["usv.y"] = (t, x), (t, y)
            meta["origin_deg"] = list(o)
        put("usv.vn", gp, lambda m: m.vx * 0.01)
        put("usv.ve", gp, lambda m: m.vy * 0.01)
        put("usv.z", gp, lambda m: -m.relative_alt * 1e-3)
    att = get("ATTITUDE")
    put("usv.psi", att, lambda m: m.yaw)
    put("usv.phi", att, lambda m: m.roll)
    put("usv.theta", att, lambda m: m.pitch)
    put("usv.r", att, lambda m: m.yawspeed)
    so = get("SERVO_OUTPUT_RAW")
    if so:
        t = np.array([t_of(s, m) for s, m in so])
        s1, s3 = _servo_names(servos)
        out[s1] = (t, _pwm([m.servo1_raw for _, m in so]))
        out[s3] = (t, _pwm([m.servo3_raw for _, m in so]))
    nv = get("NAMED_VALUE_FLOAT")
    for name, sig in (("cable_T", "cable.top_tension"), ("uuv_depth", "uuv.z")):
        rows = [(s, m) for s, m in nv if m.name.rstrip("\x00") == name]
        put(sig, rows, lambda m: m.value)
    meta.update(
        {
            "system": sysid,
            "systems": systems,
            "frames": n_ok,
            "bad_frames": n_bad,
            "messages": sorted({k.split(":")[1] for k in recs if k.startswith(f"{sysid}:")}),
        }
    )
    if "usv.x" not in out and "usv.psi" not in out:
        raise InputError(
            f"{path}: system {sysid} has no GLOBAL_POSITION_INT or ATTITUDE messages "
            f"(it has: {', '.join(meta['messages'][:12]) or 'none'})"
        )
    return out, meta


# -- ArduPilot DataFlash (.bin) --------------------------------------------------------------------------


def _scan_dataflash(path: Path, data: bytes, allow: bool, meta: dict) -> None:
    """Walk the records with the FMT lengths: corrupt (no header where one must be) or truncated tail."""
    lengths = {0x80: 89}
    pos, n = 0, 0
    while pos < len(data):
        if len(data) - pos < 3:
            _truncated(path, f"{len(data) - pos} stray byte(s) at the end", allow, meta)
            return
        if data[pos] != 0xA3 or data[pos + 1] != 0x95:
            raise InputError(f"{path}: corrupt DataFlash log: no record header at byte {pos} (after {n} records)")
        typ = data[pos + 2]
        if typ not in lengths:
            raise InputError(f"{path}: corrupt DataFlash log: record type {typ} at byte {pos} has no FMT")
        ln = lengths[typ]
        if pos + ln > len(data):
            _truncated(path, f"record {n} at byte {pos} needs {ln} bytes, {len(data) - pos} left", allow, meta)
            return
        if typ == 0x80:
            lengths[data[pos + 3]] = data[pos + 4]
        pos += ln
        n += 1
    meta["records"] = n


def read_dataflash(path: Path, allow_truncated: bool = False, origin=None, servos: str = "skid", **_):
    """ArduPilot DataFlash log via ``pymavlink.DFReader``: GPS (Lat, Lng deg, Spd m/s, GCrs deg), ATT
    (Roll, Pitch, Yaw deg), IMU (GyrZ rad/s), RCOU (C1 left, C3 right, PWM us); time TimeUS."""
    from pymavlink import DFReader

    data = path.read_bytes()
    if len(data) < 3 or data[:2] != b"\xa3\x95":
        raise InputError(f"{path}: not a DataFlash log (no 0xA3 0x95 record header at the start)")
    meta: dict = {}
    _scan_dataflash(path, data, allow_truncated, meta)
    try:
        log = DFReader.DFReader_binary(str(path), zero_time_base=True)
    except Exception as e:  # noqa: BLE001
        raise InputError(f"{path}: cannot read DataFlash log: {e}") from None
    rows: dict[str, list] = {}
    while True:
        try:
            m = log.recv_msg()
        except Exception as e:  # noqa: BLE001
            raise InputError(f"{path}: corrupt DataFlash log: {e}") from None
        if m is None:
            break
        kind = m.get_type()
        if kind in ("GPS", "ATT", "IMU", "RCOU"):
            d = m.to_dict()
            if "TimeUS" in d:
                rows.setdefault(kind, []).append(d)
    out: dict = {}

    def col(kind, f, scale=1.0):
        r = rows.get(kind, [])
        if r and f in r[0]:
            return np.array([x["TimeUS"] * 1e-6 for x in r]), np.array([x[f] for x in r], float) * scale
        return None

    g = rows.get("GPS", [])
    if g:
        t = np.array([x["TimeUS"] * 1e-6 for x in g])
        x, y, o = _ne([r["Lat"] for r in g], [r["Lng"] for r in g], origin)
        if x is not None:
            out["usv.x"], out["usv.y"] = (t, x), (t, y)
            meta["origin_deg"] = list(o)
        if "Spd" in g[0] and "GCrs" in g[0]:
            spd = np.array([r["Spd"] for r in g], float)
            crs = np.radians([r["GCrs"] for r in g])
            out["usv.vn"], out["usv.ve"] = (t, spd * np.cos(crs)), (t, spd * np.sin(crs))
    for f, sig in (("Yaw", "usv.psi"), ("Roll", "usv.phi"), ("Pitch", "usv.theta")):
        c = col("ATT", f, math.pi / 180)
        if c is not None:
            out[sig] = c
    c = col("IMU", "GyrZ")
    if c is not None:
        out["usv.r"] = c
    for f, sig in zip(("C1", "C3"), _servo_names(servos)):
        c = col("RCOU", f)
        if c is not None:
            out[sig] = (c[0], _pwm(c[1]))
    meta["messages"] = sorted(rows)
    if "usv.x" not in out and "usv.psi" not in out:
        raise InputError(
            f"{path}: DataFlash log has no GPS or ATT records (it has: {', '.join(sorted(log.name_to_id)[:15])})"
        )
    return out, meta


# -- PX4 ULog ------------------------------------------------------------------------------------------------


def read_ulog(path: Path, allow_truncated: bool = False, origin=None, **_):
    """PX4 ULog via ``pyulog``: vehicle_local_position (x, y, z, vx, vy m, m/s NED), vehicle_attitude (q),
    vehicle_angular_velocity (xyz rad/s), vehicle_gps_position (fallback position), actuator_motors
    (control[0] left, control[1] right, -1..1); timestamps in us."""
    from pyulog import ULog

    meta: dict = {}
    data = path.read_bytes()
    if len(data) < 16 or data[:7] != b"ULog\x01\x12\x35":
        raise InputError(f"{path}: not a ULog file (no 'ULog' header)")
    pos, n = 16, 0  # walk the messages (uint16 size, uint8 type, body): a tail cut mid-message is truncation
    while pos + 3 <= len(data):
        size = int.from_bytes(data[pos : pos + 2], "little")
        if pos + 3 + size > len(data):
            _truncated(
                path, f"message {n} at byte {pos} needs {size + 3} bytes, {len(data) - pos} left", allow_truncated, meta
            )
            break
        pos += 3 + size
        n += 1
    else:
        if pos != len(data):
            _truncated(path, f"{len(data) - pos} stray byte(s) at the end", allow_truncated, meta)
    try:
        ul = ULog(str(path))
    except Exception as e:  # noqa: BLE001
        raise InputError(f"{path}: cannot read ULog: {type(e).__name__}: {e}") from None
    if getattr(ul, "file_corruption", False):
        _truncated(path, "pyulog found a corrupt or incomplete message", allow_truncated, meta)
    topics = {d.name: d for d in ul.data_list if d.multi_id == 0}
    meta["topics"] = sorted(topics)
    out: dict = {}

    def ts(d):
        return d.data["timestamp"] * 1e-6

    lp = topics.get("vehicle_local_position")
    if lp is not None:
        t = ts(lp)
        for f, sig in (("x", "usv.x"), ("y", "usv.y"), ("z", "usv.z"), ("vx", "usv.vn"), ("vy", "usv.ve")):
            if f in lp.data:
                out[sig] = (t, lp.data[f].astype(float))
    elif "vehicle_gps_position" in topics:
        g = topics["vehicle_gps_position"]
        lat = g.data["latitude_deg"] if "latitude_deg" in g.data else g.data["lat"] * 1e-7
        lon = g.data["longitude_deg"] if "longitude_deg" in g.data else g.data["lon"] * 1e-7
        x, y, o = _ne(lat, lon, origin)
        if x is not None:
            out["usv.x"], out["usv.y"] = (ts(g), x), (ts(g), y)
            meta["origin_deg"] = list(o)
    at = topics.get("vehicle_attitude")
    if at is not None and "q[0]" in at.data:
        r, p, y = _quat_euler(*(at.data[f"q[{i}]"].astype(float) for i in range(4)))
        out["usv.phi"], out["usv.theta"], out["usv.psi"] = (ts(at), r), (ts(at), p), (ts(at), y)
    av = topics.get("vehicle_angular_velocity")
    if av is not None and "xyz[2]" in av.data:
        out["usv.r"] = (ts(av), av.data["xyz[2]"].astype(float))
    am = topics.get("actuator_motors")
    if am is not None and "control[1]" in am.data:
        out["act.left"] = (ts(am), am.data["control[0]"].astype(float))
        out["act.right"] = (ts(am), am.data["control[1]"].astype(float))
    if "usv.x" not in out and "usv.psi" not in out:
        raise InputError(
            f"{path}: ULog has no vehicle_local_position, vehicle_gps_position or vehicle_attitude "
            f"topic (it has: {', '.join(meta['topics'][:15]) or 'none'})"
        )
    return out, meta


# -- ROS 2 bag ---------------------------------------------------------------------------------------------

DEFAULT_TOPICS = {"odometry": "/odom", "imu": "/imu", "navsat": "/fix", "actuators": "/actuators"}


def read_rosbag2(path: Path, allow_truncated: bool = False, topics: dict | None = None, origin=None, **_):
    """ROS 2 bag (sqlite3 or mcap) via ``rosbags``: nav_msgs/Odometry, sensor_msgs/Imu, sensor_msgs/NavSatFix
    and an actuator topic (std_msgs Float32/64MultiArray: data[0] left, data[1] right, -1..1), topics
    configurable (``topics={"odometry": "/my/odom", ...}``); a topic named explicitly must exist."""
    from rosbags.highlevel import AnyReader

    given = dict(topics or {})
    unknown_roles = [k for k in given if k not in DEFAULT_TOPICS]
    if unknown_roles:
        raise InputError(f"--topic {unknown_roles[0]}=...: unknown role; roles: {', '.join(DEFAULT_TOPICS)}")
    want = {**DEFAULT_TOPICS, **given}
    bag = path if path.is_dir() else path.parent
    meta: dict = {}
    out: dict = {}
    try:
        with AnyReader([bag]) as reader:
            have = {c.topic: c for c in reader.connections}
            meta["topics"] = sorted(have)
            for role, topic in given.items():
                if topic not in have:
                    raise InputError(f"{path}: no topic {topic} ({role}); the bag has: {', '.join(sorted(have))}")
            conns = {role: have[t] for role, t in want.items() if t in have}
            if not conns:
                raise InputError(
                    f"{path}: none of the topics {', '.join(want.values())}; the bag has: "
                    f"{', '.join(sorted(have))}; name them with --topic odometry=/my/odom"
                )
            rows: dict[str, list] = {r: [] for r in conns}
            by_id = {c.id: r for r, c in conns.items()}
            for c, t_ns, raw in reader.messages(connections=list(conns.values())):
                rows[by_id[c.id]].append((t_ns * 1e-9, reader.deserialize(raw, c.msgtype)))
    except InputError:
        raise
    except Exception as e:  # noqa: BLE001
        raise InputError(f"{path}: cannot read ROS 2 bag: {type(e).__name__}: {e}") from None

    def stamp(tr, m):
        h = getattr(m, "header", None)
        if h is not None and (h.stamp.sec or h.stamp.nanosec):
            return h.stamp.sec + h.stamp.nanosec * 1e-9
        return tr

    if rows.get("odometry"):
        od = rows["odometry"]
        t = np.array([stamp(a, m) for a, m in od])
        P = np.array([[m.pose.pose.position.x, m.pose.pose.position.y, m.pose.pose.position.z] for _, m in od])
        Q = np.array(
            [
                [
                    m.pose.pose.orientation.w,
                    m.pose.pose.orientation.x,
                    m.pose.pose.orientation.y,
                    m.pose.pose.orientation.z,
                ]
                for _, m in od
            ]
        )
        V = np.array([[m.twist.twist.linear.x, m.twist.twist.linear.y, m.twist.twist.angular.z] for _, m in od])
        roll, pitch, yaw = _quat_euler(*Q.T)
        psi = np.pi / 2 - yaw
        out["usv.x"], out["usv.y"], out["usv.z"] = (t, P[:, 1]), (t, P[:, 0]), (t, -P[:, 2])
        out["usv.psi"] = (t, (psi + np.pi) % (2 * np.pi) - np.pi)
        out["usv.phi"], out["usv.theta"] = (t, roll), (t, -pitch)
        u, v = V[:, 0], -V[:, 1]  # body FLU -> FRD
        out["usv.vn"] = (t, u * np.cos(psi) - v * np.sin(psi))
        out["usv.ve"] = (t, u * np.sin(psi) + v * np.cos(psi))
        out["usv.r"] = (t, -V[:, 2])
    if rows.get("imu"):
        im = rows["imu"]
        t = np.array([stamp(a, m) for a, m in im])
        out["usv.r"] = (t, -np.array([m.angular_velocity.z for _, m in im]))
        if "usv.psi" not in out:
            Q = np.array([[m.orientation.w, m.orientation.x, m.orientation.y, m.orientation.z] for _, m in im])
            _, _, yaw = _quat_euler(*Q.T)
            out["usv.psi"] = (t, (np.pi / 2 - yaw + np.pi) % (2 * np.pi) - np.pi)
    if rows.get("navsat") and "usv.x" not in out:
        nf = rows["navsat"]
        t = np.array([stamp(a, m) for a, m in nf])
        x, y, o = _ne([m.latitude for _, m in nf], [m.longitude for _, m in nf], origin)
        if x is not None:
            out["usv.x"], out["usv.y"] = (t, x), (t, y)
            meta["origin_deg"] = list(o)
    if rows.get("actuators"):
        ac = rows["actuators"]
        t = np.array([a for a, _ in ac])
        d = [np.asarray(m.data, float) for _, m in ac]
        if any(len(x) < 2 for x in d):
            raise InputError(f"{path}: actuator topic {want['actuators']} needs data[0] (left) and data[1] (right)")
        out["act.left"] = (t, np.array([x[0] for x in d]))
        out["act.right"] = (t, np.array([x[1] for x in d]))
    if "usv.x" not in out and "usv.psi" not in out:
        raise InputError(
            f"{path}: no odometry, IMU or NavSatFix messages on {', '.join(conns[r].topic for r in conns)}"
        )
    return out, meta


# -- CSV with a column map ------------------------------------------------------------------------------------

UNIT_SCALE = {
    "": 1.0,
    "si": 1.0,
    "s": 1.0,
    "ms": 1e-3,
    "us": 1e-6,
    "ns": 1e-9,
    "m": 1.0,
    "cm": 0.01,
    "mm": 1e-3,
    "rad": 1.0,
    "deg": math.pi / 180,
    "cdeg": math.pi / 18000,
    "m/s": 1.0,
    "cm/s": 0.01,
    "kn": 1852.0 / 3600.0,
    "km/h": 1 / 3.6,
    "rad/s": 1.0,
    "deg/s": math.pi / 180,
    "1": 1.0,
    "pwm": None,
    "n": 1.0,
    "kgf": 9.80665,
}


def parse_column_map(items) -> dict:
    """``["t=time_s", "usv.psi=heading:deg", ...]`` (or one comma-separated string) -> {signal: (column, unit)}."""
    if isinstance(items, dict):
        return {k: (v if isinstance(v, tuple) else tuple((str(v).split(":", 1) + [""])[:2])) for k, v in items.items()}
    out = {}
    for it in items if isinstance(items, (list, tuple)) else [items]:
        for part in str(it).split(","):
            part = part.strip()
            if not part:
                continue
            if "=" not in part:
                raise InputError(f"--map {part!r}: expected signal=column[:unit]")
            sig, rhs = part.split("=", 1)
            col, _, unit = rhs.partition(":")
            if unit.lower() not in UNIT_SCALE:
                raise InputError(
                    f"--map {part!r}: unknown unit {unit!r}; known: {', '.join(k for k in UNIT_SCALE if k)}"
                )
            out[sig.strip()] = (col.strip(), unit.lower())
    return out


def read_csv(path: Path, allow_truncated: bool = False, column_map=None, origin=None, **_):
    """CSV with a column map: ``t`` (time) and any standard signal; ``lat``/``lon`` (deg) become usv.x/y."""
    import pandas as pd

    cmap = parse_column_map(column_map or {})
    if "t" not in cmap:
        raise InputError(f"{path}: the column map needs the time column (--map t=COLUMN[:unit])")
    try:
        df = pd.read_csv(path)
    except Exception as e:  # noqa: BLE001
        raise InputError(f"{path}: cannot read CSV: {type(e).__name__}: {e}") from None
    missing = [f"{c} (for {s})" for s, (c, _) in cmap.items() if c not in df.columns]
    if missing:
        raise InputError(f"{path}: no column {', '.join(missing)}; it has: {', '.join(map(str, df.columns[:20]))}")
    if len(df) == 0:
        raise InputError(f"{path}: CSV has a header but no rows")

    def val(sig):
        c, unit = cmap[sig]
        v = pd.to_numeric(df[c], errors="coerce").to_numpy(float)
        return _pwm(v) if unit == "pwm" else v * UNIT_SCALE[unit]

    t = val("t")
    out: dict = {}
    meta: dict = {"column_map": {k: ":".join(v).rstrip(":") for k, v in cmap.items()}}
    if "lat" in cmap and "lon" in cmap:
        x, y, o = _ne(df[cmap["lat"][0]].to_numpy(float), df[cmap["lon"][0]].to_numpy(float), origin)
        if x is not None:
            out["usv.x"], out["usv.y"] = (t, x), (t, y)
            meta["origin_deg"] = list(o)
    for sig in cmap:
        if sig in ("t", "lat", "lon"):
            continue
        out[sig] = (t, val(sig))
    return out, meta
