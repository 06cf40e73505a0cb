"""ROS 2 bags, read with rosbags: ``nav_msgs/Odometry`` and ``sensor_msgs/Imu`` (ENU / FLU -> NED / FRD), ``sensor_msgs/NavSatFix``, actuators."""

from __future__ import annotations

from pathlib import Path

import numpy as np

from ....errors import InputError
from ._common import north_east, quat_euler


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
    if "usv.x" not in out and "usv.psi" not in out:
        raise InputError(
            f"{path}: no odometry, IMU or NavSatFix messages on {', '.join(conns[r].topic for r in conns)}"
        )
    return out, meta
