"""PX4 ULog (``.ulg``), read with pyulog: local position (NED), attitude quaternion, motor outputs."""

from __future__ import annotations

from pathlib import Path


from ....errors import InputError
from ._common import north_east, quat_euler, truncated


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
            truncated(
                path, f"message {n} at byte {pos} needs {size + 3} bytes, {len(data) - pos} left", allow_truncated, meta
            )
            break
        pos += 3 + size
        n += 1
    else:
        if pos != len(data):
            truncated(path, f"{len(data) - pos} stray byte(s) at the end", allow_truncated, meta)
    try:
        ul = ULog(str(path))
    except Exception as e:  # noqa: BLE001
        raise InputError(f"{path}: cannot read ULog: {type(e).__name__}: {e}") from None
    if getattr(ul, "file_corruption", False):
        truncated(path, "pyulog found a corrupt or incomplete message", allow_truncated, meta)
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
        x, y, o = north_east(lat, lon, origin)
        if x is not None:
            out["usv.x"], out["usv.y"] = (ts(g), x), (ts(g), y)
            meta["origin_deg"] = list(o)
    at = topics.get("vehicle_attitude")
    if at is not None and "q[0]" in at.data:
        r, p, y = quat_euler(*(at.data[f"q[{i}]"].astype(float) for i in range(4)))
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
