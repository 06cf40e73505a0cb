"""Writers of real field-log files for the import tests, each from its format's specification.

* DataFlash (.bin): ArduPilot's self-describing format, as ``pymavlink.DFReader`` reads it: every record
  is ``0xA3 0x95 <type>`` + payload; type 128 (FMT) defines a type: Type B, Length B (whole record),
  Name 4s, Format 16s, Columns 64s (format chars: Q uint64, B uint8, b int8, H uint16, h int16, f float,
  L int32 x 1e-7 deg, N char[16], Z char[64]).
  pymavlink ships no DataFlash writer, so we write the FMT/GPS/ATT/IMU/RCOU records ourselves.
* ULog (.ulg): PX4's format (docs.px4.io "ULog File Format"): 16-byte header ``ULog\\x01\\x12\\x35``,
  version, start time (us); then messages ``uint16 size, uint8 type`` + body: 'B' flag bits (40 bytes),
  'F' formats ``name:type field;...``, 'A' add-logged (multi_id, msg_id, name), 'D' data (msg_id + payload).
* ROS 2 bags: the ``rosbags`` Writer with its own serializer.
"""

from __future__ import annotations

import math
import struct
from pathlib import Path

import numpy as np

from oceangnc.io.geo import ned_to_latlon

KGF = 9.80665

# -- DataFlash ---------------------------------------------------------------------------------------------

_DF_STRUCT = {"Q": "Q", "B": "B", "H": "H", "f": "f", "L": "i", "I": "I", "b": "b", "h": "h", "N": "16s", "Z": "64s"}


class DataFlashWriter:
    def __init__(self, path):
        self.f = open(path, "wb")  # noqa: SIM115 (closed by close())
        self.types = {}
        self._fmt(128, "FMT", "BBnNZ", "Type,Length,Name,Format,Columns", raw_len=89)

    def _fmt(self, typ, name, fmt, cols, raw_len=None):
        ln = raw_len or 3 + struct.calcsize("<" + "".join(_DF_STRUCT[c] for c in fmt))
        body = struct.pack("<BB4s16s64s", typ, ln, name.encode(), fmt.encode(), cols.encode())
        self.f.write(b"\xa3\x95\x80" + body)
        self.types[name] = (typ, fmt)

    def define(self, typ, name, fmt, cols):
        self._fmt(typ, name, fmt, cols)

    def write(self, name, *values):
        typ, fmt = self.types[name]
        values = [v.encode() if isinstance(v, str) else v for v in values]  # N (char[16]), Z (char[64])
        self.f.write(b"\xa3\x95" + bytes([typ]) + struct.pack("<" + "".join(_DF_STRUCT[c] for c in fmt), *values))

    def close(self):
        self.f.close()


def pwm_of(T, full_fwd, full_rev):
    full = np.where(T >= 0, full_fwd, full_rev)
    return np.round(1500 + 400 * np.clip(T / full, -1, 1)).astype(int)


def write_dataflash(
    path,
    df,
    lat0,
    lon0,
    tmax_n,
    trev_n,
    firmware=None,
    params=None,
    outputs=(1, 3),
    reverse=(),
    instances=1,
    no_fix_s=0.0,
):
    """GPS at 5 Hz, ATT / IMU / RCOU at 10 Hz from a simulated run's truth ``df`` (t, usv.*); ``firmware`` (a MSG
    such as "ArduRover V4.5.7 (abc)") and ``params`` (PARM records) first, as ArduPilot writes them; the
    port / starboard thrust on the RCOU ``outputs``, PWM mirrored about 1500 on those in ``reverse``.
    ``instances`` > 1: IMU and GPS with ArduPilot 4's instance field I, every instance at the same TimeUS
    (instance k reads a yaw rate k x 0.05 rad/s high and a position k x 3 m north); for the first
    ``no_fix_s`` s every GPS has no fix (Status 1) and reports a position 500 m off."""
    w = DataFlashWriter(path)
    w.define(129, "PARM", "QNf", "TimeUS,Name,Value")
    w.define(134, "MSG", "QZ", "TimeUS,Message")
    if firmware:
        w.write("MSG", 1000, firmware)
    for k, v in (params or {}).items():
        w.write("PARM", 1000, k, float(v))
    if instances > 1:
        w.define(130, "GPS", "QBBIHLLff", "TimeUS,I,Status,GMS,GWk,Lat,Lng,Spd,GCrs")
        w.define(132, "IMU", "QBf", "TimeUS,I,GyrZ")
    else:
        w.define(130, "GPS", "QBIHLLff", "TimeUS,Status,GMS,GWk,Lat,Lng,Spd,GCrs")  # GPS week and ms, as ArduPilot
        w.define(132, "IMU", "Qf", "TimeUS,GyrZ")
    w.define(131, "ATT", "Qfff", "TimeUS,Roll,Pitch,Yaw")
    w.define(133, "RCOU", "QHHHH", "TimeUS,C1,C2,C3,C4")
    inst = [(k,) for k in range(instances)] if instances > 1 else [()]
    t = df["t"].to_numpy()
    vn = df["usv.u"] * np.cos(df["usv.psi"]) - df["usv.v"] * np.sin(df["usv.psi"])
    ve = df["usv.u"] * np.sin(df["usv.psi"]) + df["usv.v"] * np.cos(df["usv.psi"])
    pl = pwm_of(df["usv.thrust_port"].to_numpy(), tmax_n, trev_n)
    pr = pwm_of(df["usv.thrust_stbd"].to_numpy(), tmax_n, trev_n)
    for i in range(len(df)):
        us = round(t[i] * 1e6) + 1_000_000
        if i % 2 == 0:
            fix = t[i] >= no_fix_s
            for k in inst:
                dn = 3.0 * (k[0] if k else 0) + (0.0 if fix else 500.0)
                lat, lon = ned_to_latlon(df["usv.x"].iat[i] + dn, df["usv.y"].iat[i], lat0, lon0)
                w.write(
                    "GPS",
                    us,
                    *k,
                    3 if fix else 1,
                    302_400_000 + us // 1000,
                    2390,
                    round(lat * 1e7),
                    round(lon * 1e7),
                    math.hypot(vn.iat[i], ve.iat[i]),
                    math.degrees(math.atan2(ve.iat[i], vn.iat[i])) % 360,
                )
        w.write("ATT", us, 0.0, 0.0, math.degrees(df["usv.psi"].iat[i]) % 360)
        for k in inst:
            w.write("IMU", us, *k, df["usv.r"].iat[i] + 0.05 * (k[0] if k else 0))
        ch = [1500, 1500, 1500, 1500]
        for n, v in zip(outputs, (int(pl[i]), int(pr[i]))):
            ch[n - 1] = 3000 - v if n in reverse else v
        w.write("RCOU", us, *ch)
    w.close()


# -- ULog --------------------------------------------------------------------------------------------------

_UL_TYPES = {"uint64_t": "Q", "float": "f", "double": "d", "uint8_t": "B", "int32_t": "i", "bool": "?"}


class ULogWriter:
    def __init__(self, path, t0_us=0):
        self.f = open(path, "wb")  # noqa: SIM115 (closed by close())
        self.f.write(b"ULog\x01\x12\x35" + bytes([1]) + struct.pack("<Q", t0_us))
        self._msg("B", bytes(8) + bytes(8) + struct.pack("<QQQ", 0, 0, 0))
        self.topics = {}
        self._subscribed = False

    def _msg(self, kind, body):
        self.f.write(struct.pack("<HB", len(body), ord(kind)) + body)

    def topic(self, name, fields):
        """``fields``: list of (type, name) after the timestamp; arrays as ('float[4]', 'q')."""
        spec = "uint64_t timestamp;" + "".join(f"{t} {n};" for t, n in fields)
        self._msg("F", f"{name}:{spec}".encode())
        st = "<Q"
        for t, _ in fields:
            base, _, n = t.partition("[")
            st += (n.rstrip("]") if n else "") + _UL_TYPES[base]
        msg_id = len(self.topics)
        self.topics[name] = (msg_id, st)

    def param(self, name, value):
        """A parameter ('P': uint8 key length, key "int32_t NAME" or "float NAME", value) in the definitions."""
        typ = "int32_t" if isinstance(value, int) else "float"
        key = f"{typ} {name}".encode()
        self._msg("P", bytes([len(key)]) + key + struct.pack("<" + _UL_TYPES[typ], value))

    def write(self, name, t_us, *values):
        if not self._subscribed:  # the definitions section ends with the first 'A' message
            self._subscribed = True
            for n, (i, _) in self.topics.items():
                self._msg("A", struct.pack("<BH", 0, i) + n.encode())
        msg_id, st = self.topics[name]
        self._msg("D", struct.pack("<H", msg_id) + struct.pack(st, t_us, *values))

    def close(self):
        self.f.close()


def write_ulog(path, df, tmax_n, trev_n, params=None):
    w = ULogWriter(path)
    for k, v in (params or {}).items():
        w.param(k, v)
    w.topic(
        "vehicle_local_position",
        [("float", "x"), ("float", "y"), ("float", "z"), ("float", "vx"), ("float", "vy"), ("float", "vz")],
    )
    w.topic("vehicle_attitude", [("float[4]", "q")])
    w.topic("vehicle_angular_velocity", [("float[3]", "xyz")])
    w.topic("actuator_motors", [("float[12]", "control")])
    t = df["t"].to_numpy()
    psi = df["usv.psi"].to_numpy()
    vn = df["usv.u"] * np.cos(psi) - df["usv.v"] * np.sin(psi)
    ve = df["usv.u"] * np.sin(psi) + df["usv.v"] * np.cos(psi)
    for i in range(len(df)):
        us = round(t[i] * 1e6) + 500_000
        w.write("vehicle_local_position", us, df["usv.x"].iat[i], df["usv.y"].iat[i], 0.0, vn.iat[i], ve.iat[i], 0.0)
        w.write("vehicle_attitude", us, math.cos(psi[i] / 2), 0.0, 0.0, math.sin(psi[i] / 2))
        w.write("vehicle_angular_velocity", us, 0.0, 0.0, df["usv.r"].iat[i])
        tp, ts = df["usv.thrust_port"].iat[i], df["usv.thrust_stbd"].iat[i]
        left = tp / (tmax_n if tp >= 0 else trev_n)
        right = ts / (tmax_n if ts >= 0 else trev_n)
        w.write("actuator_motors", us, left, right, *([0.0] * 10))
    w.close()


# -- ROS 2 bag ----------------------------------------------------------------------------------------------


def write_rosbag(path: Path, df, tmax_n, trev_n, odom_topic="/odom", fix_origin=None, storage="sqlite3"):
    """Odometry (ENU / FLU, REP 103), Imu and a Float64MultiArray actuator topic, via rosbags' Writer;
    with ``fix_origin`` = (lat, lon) a NavSatFix topic ``/fix`` instead of the odometry; ``storage``
    sqlite3 (.db3) or mcap."""
    from rosbags.rosbag2 import StoragePlugin, Writer
    from rosbags.typesys import Stores, get_typestore

    ts = get_typestore(Stores.ROS2_HUMBLE)
    Odometry = ts.types["nav_msgs/msg/Odometry"]
    Imu = ts.types["sensor_msgs/msg/Imu"]
    F64 = ts.types["std_msgs/msg/Float64MultiArray"]
    Header = ts.types["std_msgs/msg/Header"]
    Time = ts.types["builtin_interfaces/msg/Time"]
    Pose = ts.types["geometry_msgs/msg/Pose"]
    PWC = ts.types["geometry_msgs/msg/PoseWithCovariance"]
    Twist = ts.types["geometry_msgs/msg/Twist"]
    TWC = ts.types["geometry_msgs/msg/TwistWithCovariance"]
    P = ts.types["geometry_msgs/msg/Point"]
    Q = ts.types["geometry_msgs/msg/Quaternion"]
    V = ts.types["geometry_msgs/msg/Vector3"]
    Layout = ts.types["std_msgs/msg/MultiArrayLayout"]
    Fix = ts.types["sensor_msgs/msg/NavSatFix"]
    FixStatus = ts.types["sensor_msgs/msg/NavSatStatus"]
    cov = np.zeros(36)
    with Writer(path, version=8, storage_plugin=getattr(StoragePlugin, storage.upper())) as w:
        co = w.add_connection(odom_topic, Odometry.__msgtype__, typestore=ts) if fix_origin is None else None
        cf = w.add_connection("/fix", Fix.__msgtype__, typestore=ts) if fix_origin is not None else None
        ci = w.add_connection("/imu", Imu.__msgtype__, typestore=ts)
        ca = w.add_connection("/actuators", F64.__msgtype__, typestore=ts)
        for i in range(len(df)):
            t = float(df["t"].iat[i]) + 100.0
            ns = round(t * 1e9)
            hdr = Header(stamp=Time(sec=int(t), nanosec=round((t - int(t)) * 1e9)), frame_id="odom")
            psi = float(df["usv.psi"].iat[i])
            yaw = math.pi / 2 - psi  # ENU yaw
            q = Q(x=0.0, y=0.0, z=math.sin(yaw / 2), w=math.cos(yaw / 2))
            pose = Pose(position=P(x=float(df["usv.y"].iat[i]), y=float(df["usv.x"].iat[i]), z=0.0), orientation=q)
            tw = Twist(
                linear=V(x=float(df["usv.u"].iat[i]), y=-float(df["usv.v"].iat[i]), z=0.0),
                angular=V(x=0.0, y=0.0, z=-float(df["usv.r"].iat[i])),
            )
            od = Odometry(
                header=hdr,
                child_frame_id="base_link",
                pose=PWC(pose=pose, covariance=cov),
                twist=TWC(twist=tw, covariance=cov),
            )
            if co is not None:
                w.write(co, ns, ts.serialize_cdr(od, Odometry.__msgtype__))
            else:
                lat, lon = ned_to_latlon(float(df["usv.x"].iat[i]), float(df["usv.y"].iat[i]), *fix_origin)
                fx = Fix(
                    header=hdr,
                    status=FixStatus(status=0, service=1),
                    latitude=lat,
                    longitude=lon,
                    altitude=0.0,
                    position_covariance=np.zeros(9),
                    position_covariance_type=0,
                )
                w.write(cf, ns, ts.serialize_cdr(fx, Fix.__msgtype__))
            if i % 2 == 0:
                im = Imu(
                    header=hdr,
                    orientation=q,
                    orientation_covariance=np.zeros(9),
                    angular_velocity=V(x=0.0, y=0.0, z=-float(df["usv.r"].iat[i])),
                    angular_velocity_covariance=np.zeros(9),
                    linear_acceleration=V(x=0.0, y=0.0, z=9.81),
                    linear_acceleration_covariance=np.zeros(9),
                )
                w.write(ci, ns, ts.serialize_cdr(im, Imu.__msgtype__))
            tp, tsb = df["usv.thrust_port"].iat[i], df["usv.thrust_stbd"].iat[i]
            a = F64(
                layout=Layout(dim=[], data_offset=0),
                data=np.array([tp / (tmax_n if tp >= 0 else trev_n), tsb / (tmax_n if tsb >= 0 else trev_n)]),
            )
            w.write(ca, ns, ts.serialize_cdr(a, F64.__msgtype__))


def as_pre_iron_bag(path: Path, distro: str = "humble") -> None:
    """Turn a sqlite3 bag written by rosbags' Writer into the layout rosbag2 of Foxy / Galactic / Humble
    writes: no ``message_definitions`` table (and no ``type_description_hash``), metadata.yaml version 5
    (Humble; 4 for Foxy) without ``ros_distro``; Humble (rosbag2 0.15.4 on) keeps its distro in the
    ``schema`` table (version 3), Foxy and Galactic have no ``schema`` table."""
    import io
    import sqlite3

    from ruamel.yaml import YAML

    (db,) = path.glob("*.db3")
    con = sqlite3.connect(db)
    con.executescript(
        """
        DROP TABLE message_definitions;
        DROP TABLE metadata;
        CREATE TABLE topics_old(id INTEGER PRIMARY KEY, name TEXT NOT NULL, type TEXT NOT NULL,
          serialization_format TEXT NOT NULL, offered_qos_profiles TEXT NOT NULL);
        INSERT INTO topics_old SELECT id, name, type, serialization_format, offered_qos_profiles FROM topics;
        DROP TABLE topics;
        ALTER TABLE topics_old RENAME TO topics;
        """
    )
    if distro == "humble":
        con.execute("UPDATE schema SET schema_version = 3, ros_distro = ?", (distro,))
    else:
        con.execute("DROP TABLE schema")
    con.commit()
    con.close()
    yaml = YAML(typ="safe")
    meta = yaml.load((path / "metadata.yaml").read_text())
    info = meta["rosbag2_bagfile_information"]
    info["version"] = 5 if distro == "humble" else 4
    for k in ("ros_distro", "custom_data"):
        info.pop(k, None)
    for t in info["topics_with_message_count"]:
        t["topic_metadata"].pop("type_description_hash", None)
    buf = io.StringIO()
    yaml.dump(meta, buf)
    (path / "metadata.yaml").write_text(buf.getvalue())


# -- MAVLink telemetry log (.tlog) -------------------------------------------------------------------------


def write_tlog(path, df, lat0, lon0, mav_type, params=None, tmax_n=1.0, trev_n=1.0, no_fix_s=None):
    """A telemetry log as a ground station records it, with pymavlink's own encoder and log file: records of an
    8-byte big-endian time (us) and one MAVLink 2 frame. System 1 sends HEARTBEAT (``mav_type``) at 1 Hz,
    PARAM_VALUE for each of ``params`` once, then GLOBAL_POSITION_INT, ATTITUDE and SERVO_OUTPUT_RAW (port
    thrust on output 1, starboard on 3) at 10 Hz; with ``no_fix_s`` also GPS_RAW_INT at 1 Hz, without a fix
    (fix_type 1) and the estimate 300 m off before that time."""
    from pymavlink import mavutil
    from pymavlink.dialects.v20 import ardupilotmega as mav2

    f = mavutil.mavlogfile(str(path), write=True)
    enc = mav2.MAVLink(None, srcSystem=1, srcComponent=1)
    t0 = 1_700_000_000_000_000

    def rec(t_s, msg):
        f.write(struct.pack(">Q", t0 + round(t_s * 1e6)) + msg.pack(enc))

    for i, (k, v) in enumerate((params or {}).items()):
        rec(0.0, enc.param_value_encode(k.encode(), float(v), mav2.MAV_PARAM_TYPE_REAL32, len(params), i))
    t = df["t"].to_numpy()
    psi = df["usv.psi"].to_numpy()
    pl = pwm_of(df["usv.thrust_port"].to_numpy(), tmax_n, trev_n) if "usv.thrust_port" in df else None
    pr = pwm_of(df["usv.thrust_stbd"].to_numpy(), tmax_n, trev_n) if "usv.thrust_stbd" in df else None
    for i in range(len(df)):
        ms = round(t[i] * 1000) + 1000
        if i % 10 == 0:
            rec(ms / 1000, enc.heartbeat_encode(mav_type, mav2.MAV_AUTOPILOT_ARDUPILOTMEGA, 0, 0, 0))
        fix = no_fix_s is None or t[i] >= no_fix_s
        lat, lon = ned_to_latlon(df["usv.x"].iat[i] + (0.0 if fix else 300.0), df["usv.y"].iat[i], lat0, lon0)
        if no_fix_s is not None and i % 10 == 0:
            rec(
                ms / 1000,
                enc.gps_raw_int_encode(
                    ms * 1000, 3 if fix else 1, round(lat * 1e7), round(lon * 1e7), 0, 100, 100, 0, 0, 10
                ),
            )
        c, sn = math.cos(psi[i]), math.sin(psi[i])
        vn = df["usv.u"].iat[i] * c - df["usv.v"].iat[i] * sn
        ve = df["usv.u"].iat[i] * sn + df["usv.v"].iat[i] * c
        vx, vy = round(vn * 100), round(ve * 100)  # cm/s
        rec(ms / 1000, enc.global_position_int_encode(ms, round(lat * 1e7), round(lon * 1e7), 0, 0, vx, vy, 0, 0))
        rec(ms / 1000, enc.attitude_encode(ms, 0.0, 0.0, float(psi[i]), 0.0, 0.0, float(df["usv.r"].iat[i])))
        a = int(pl[i]) if pl is not None else 1500
        b = int(pr[i]) if pr is not None else 1500
        rec(ms / 1000, enc.servo_output_raw_encode(ms * 1000, 0, a, 1500, b, 1500, 1500, 1500, 1500, 1500))
    f.close()
