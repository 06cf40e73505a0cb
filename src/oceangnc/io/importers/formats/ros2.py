"""ROS 2 bags, read with rosbags: ``nav_msgs/Odometry`` and ``sensor_msgs/Imu`` (ENU / FLU -> NED / FRD), ``sensor_msgs/NavSatFix``, actuators."""

from __future__ import annotations

from pathlib import Path

import numpy as np

from ....errors import InputError
from ._common import north_east, quat_euler
from .ros2_services import TopicsOnlyReader, service_channels


# -- ROS 2 bag ---------------------------------------------------------------------------------------------

DEFAULT_TOPICS = {"odometry": "/odom", "imu": "/imu", "navsat": "/fix", "actuators": "/actuators"}

#: ROS 2 distribution (``ros_distro`` of the bag) -> rosbags' built-in typestore; bags written before Iron
#: (Foxy, Galactic, Humble sqlite3) hold no message definitions, so the types come from the distro's store
DISTRO_STORES = {
    "dashing": "ROS2_DASHING",
    "eloquent": "ROS2_ELOQUENT",
    "foxy": "ROS2_FOXY",
    "galactic": "ROS2_GALACTIC",
    "humble": "ROS2_HUMBLE",
    "iron": "ROS2_IRON",
    "jazzy": "ROS2_JAZZY",
    "kilted": "ROS2_KILTED",
    "rolling": "LATEST",
}
#: the store tried when the bag does not say which distribution wrote it
FALLBACK_DISTRO = "humble"


def bag_distro(bag: Path) -> tuple[str | None, str]:
    """The ROS 2 distribution that wrote a bag, and where it was read: ``ros_distro`` of metadata.yaml
    (rosbag2 metadata version 8, Jazzy on) or of the sqlite3 ``schema`` table (Humble 0.15.4 on)."""
    import sqlite3

    folder = bag if bag.is_dir() else bag.parent
    info: dict = {}
    meta = folder / "metadata.yaml"
    if meta.is_file():
        try:
            from ruamel.yaml import YAML  # rosbags' own YAML library

            info = (YAML(typ="safe").load(meta.read_text()) or {}).get("rosbag2_bagfile_information", {}) or {}
        except Exception:  # noqa: BLE001 - rosbags reports an unreadable metadata.yaml itself
            info = {}
        d = str(info.get("ros_distro") or "").strip().lower()
        if d in DISTRO_STORES:
            return d, "ros_distro in metadata.yaml"
    dbs = [bag] if bag.suffix == ".db3" else sorted(folder.glob("*.db3"))
    for db in dbs[:1]:
        try:
            con = sqlite3.connect(f"file:{db}?mode=ro", uri=True)
            try:
                row = con.execute("SELECT ros_distro FROM schema").fetchone()
            finally:
                con.close()
        except sqlite3.Error:
            continue
        d = str(row[0] if row else "").strip().lower()
        if d in DISTRO_STORES:
            return d, f"ros_distro in the schema table of {db.name}"
    if meta.is_file() and info.get("version") == 4:
        return "foxy", "metadata.yaml version 4 (written by Foxy)"
    return None, "the bag does not name its distro"


def _open_reader(bag: Path, ros_distro: str | None, meta: dict):
    """An open rosbags AnyReader: the bag's own message definitions when it has them (Iron on, MCAP),
    else the typestore of the distribution that wrote it (``ros_distro`` given, or read from the bag, or
    humble); ``meta["typestore"]`` says which was used."""
    from rosbags.highlevel import AnyReader
    from rosbags.typesys import Stores, get_typestore

    if ros_distro is not None:
        key = ros_distro.strip().lower()
        if key not in DISTRO_STORES:
            raise InputError(f"--ros-distro {ros_distro}: allowed {', '.join(DISTRO_STORES)}")
    skipped = service_channels(bag)
    if skipped:
        reader = TopicsOnlyReader(bag)
        meta["typestore"] = "the bag's own message definitions"
        meta.setdefault("notes", []).append(
            f"{len(skipped)} service or action channel(s) skipped ({', '.join(skipped[:4])}"
            f"{', ...' if len(skipped) > 4 else ''}): only topics are imported"
        )
        meta["skipped_channels"] = skipped
        return reader
    reader = AnyReader([bag])
    try:
        reader.open()
        meta["typestore"] = "the bag's own message definitions"
        return reader
    except Exception as e:  # noqa: BLE001
        if "no type definitions" not in str(e):
            raise
    if ros_distro is not None:
        distro, where = ros_distro.strip().lower(), f"--ros-distro {ros_distro}"
    else:
        distro, where = bag_distro(bag)
        if distro is None:
            distro, where = FALLBACK_DISTRO, f"{where}: {FALLBACK_DISTRO} assumed, --ros-distro to choose"
    store = DISTRO_STORES[distro]
    reader = AnyReader([bag], default_typestore=get_typestore(getattr(Stores, store)))
    reader.open()
    meta["typestore"] = f"{store.lower()} typestore (the bag has no message definitions; {where})"
    meta["ros_distro"] = distro
    meta.setdefault("notes", []).append(f"message types from the {meta['typestore']}")
    return reader


def read_rosbag2(
    path: Path, allow_truncated: bool = False, topics: dict | None = None, origin=None, ros_distro=None, **_
):
    """ROS 2 bag (sqlite3 or mcap, a bag folder or one storage file) via ``rosbags``: nav_msgs/Odometry,
    sensor_msgs/Imu, sensor_msgs/NavSatFix and an actuator topic (std_msgs Float32/64MultiArray: data[0]
    left, data[1] right, -1..1), topics configurable (``topics={"odometry": "/my/odom", ...}``); a topic
    named explicitly must exist. Bags without message definitions (Foxy, Galactic, Humble sqlite3) are
    read with the typestore of the distribution that wrote them (:func:`bag_distro`, default humble)."""
    given = dict(topics or {})
    unknown_roles = [k for k in given if k not in DEFAULT_TOPICS]
    if unknown_roles:
        raise InputError(f"--topic {unknown_roles[0]}=...: unknown role; roles: {', '.join(DEFAULT_TOPICS)}")
    want = {**DEFAULT_TOPICS, **given}
    # a bag folder; a storage file inside one (its folder, with metadata.yaml); or a bare .db3 / .mcap file
    bag = path if path.is_dir() or not (path.parent / "metadata.yaml").is_file() else path.parent
    meta: dict = {}
    out: dict = {}
    try:
        reader = _open_reader(bag, ros_distro, meta)
        try:
            have = {c.topic: c for c in reader.connections}
            meta["topics"] = sorted(have)
            for role, topic in given.items():
                if topic not in have:
                    raise InputError(f"{path}: no topic {topic} ({role}); the bag has: {', '.join(sorted(have))}")
            conns = {role: have[t] for role, t in want.items() if t in have}
            if not conns:
                skipped = meta.get("skipped_channels", [])
                raise InputError(
                    f"{path}: none of the topics {', '.join(want.values())}; the bag has: "
                    f"{', '.join(sorted(have))}"
                    + (f" (and {len(skipped)} service or action channel(s), skipped)" if skipped else "")
                    + "; name them with --topic odometry=/my/odom"
                )
            known = set(reader.typestore.fielddefs)
            for role, c in conns.items():
                if c.msgtype not in known:
                    raise InputError(
                        f"{path}: topic {c.topic} ({role}) has type {c.msgtype}, unknown to the "
                        f"{meta.get('typestore', 'typestore')}"
                    )
            rows: dict[str, list] = {r: [] for r in conns}
            by_id = {c.id: r for r, c in conns.items()}
            for c, t_ns, raw in reader.messages(connections=list(conns.values())):
                rows[by_id[c.id]].append((t_ns * 1e-9, reader.deserialize(raw, c.msgtype)))
        finally:
            reader.close()
    except InputError:
        raise
    except Exception as e:  # noqa: BLE001
        how = f" with the {meta['typestore']}" if "ros_distro" in meta else ""
        raise InputError(f"{path}: cannot read ROS 2 bag{how}: {type(e).__name__}: {e}") from None

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
        roll, pitch, yaw = quat_euler(*Q.T)
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
            _, _, yaw = quat_euler(*Q.T)
            out["usv.psi"] = (t, (np.pi / 2 - yaw + np.pi) % (2 * np.pi) - np.pi)
    if rows.get("navsat") and "usv.x" not in out:
        nf = rows["navsat"]
        fixed = [(a, m) for a, m in nf if m.status.status >= 0]  # NavSatStatus.STATUS_NO_FIX = -1
        if len(fixed) < len(nf):
            meta.setdefault("notes", []).append(
                f"{want['navsat']}: {len(nf) - len(fixed)} of {len(nf)} NavSatFix messages without a fix "
                "(status -1) dropped"
            )
        nf = fixed
        t = np.array([stamp(a, m) for a, m in nf])
        x, y, o = north_east([m.latitude for _, m in nf], [m.longitude for _, m in nf], origin)
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
    if any(len(t) and np.nanmin(t) > 1e9 for t, _ in out.values()):
        meta["unix_offset_s"] = 0.0  # ROS time: seconds since the UNIX epoch
    if "usv.x" not in out and "usv.psi" not in out:
        raise InputError(
            f"{path}: no odometry, IMU or NavSatFix messages on {', '.join(conns[r].topic for r in conns)}"
        )
    return out, meta
