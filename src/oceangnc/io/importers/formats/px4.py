"""PX4 ULog (``.ulg``), read with pyulog: local position (NED), attitude quaternion, motor outputs."""

from __future__ import annotations

from pathlib import Path

import numpy as np


from ....errors import InputError
from ._common import mav_type_class, mav_type_name, north_east, quat_euler, truncated, vehicle


# -- PX4 ULog ------------------------------------------------------------------------------------------------

#: SYS_AUTOSTART ranges of PX4's airframe families (docs.px4.io "Airframes Reference") -> vehicle class
AUTOSTART = (
    ((4000, 12999), "multirotor"),
    ((13000, 13999), "VTOL"),
    ((14000, 15999), "multirotor"),
    ((16000, 16999), "helicopter"),
    ((24000, 24999), "multirotor"),
    ((50000, 59999), "rover (boat or ground)"),
    ((60000, 60999), "submarine"),
)
#: vehicle_status.vehicle_type
_VEHICLE_TYPE = {1: "multirotor", 2: "fixed-wing", 3: "rover (boat or ground)", 4: "airship"}


def px4_vehicle(ul, topics) -> dict:
    """The vehicle class of a PX4 log: parameter MAV_TYPE (set by the airframe), vehicle_status.system_type
    (older logs), SYS_AUTOSTART (the airframe family), vehicle_status.vehicle_type / is_vtol."""
    p = getattr(ul, "initial_parameters", {}) or {}
    vs = topics.get("vehicle_status")
    if "MAV_TYPE" in p and mav_type_class(p["MAV_TYPE"]):
        mt = int(p["MAV_TYPE"])
        return vehicle(mav_type_class(mt), f"parameter MAV_TYPE={mt} ({mav_type_name(mt)})")
    if vs is not None and "system_type" in vs.data and len(vs.data["system_type"]):
        mt = int(vs.data["system_type"][-1])
        if mav_type_class(mt):
            return vehicle(mav_type_class(mt), f"vehicle_status.system_type={mt} ({mav_type_name(mt)})")
    sa = int(p.get("SYS_AUTOSTART", 0) or 0)
    for (lo, hi), kind in AUTOSTART:
        if lo <= sa <= hi:
            return _px4_kind(kind, f"SYS_AUTOSTART={sa}")
    if vs is not None and "vehicle_type" in vs.data and len(vs.data["vehicle_type"]):
        vt = int(vs.data["vehicle_type"][-1])
        vtol = "is_vtol" in vs.data and bool(vs.data["is_vtol"][-1])
        kind = "VTOL" if vtol else _VEHICLE_TYPE.get(vt)
        if kind:
            return _px4_kind(kind, f"vehicle_status.vehicle_type={vt}" + (", is_vtol" if vtol else ""))
    return vehicle(None, "no MAV_TYPE, SYS_AUTOSTART or vehicle_status in the log")


def _px4_kind(kind: str, src: str) -> dict:
    if kind.startswith("rover"):  # a rover or a boat: not told apart here
        return {**vehicle(None, src), "type": kind}
    return vehicle(kind, src)


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
    topics = {d.name: d for d in ul.data_list if d.multi_id == 0}  # instance 0 of each topic: the primary
    meta["topics"] = sorted(topics)
    multi = sorted({d.name for d in ul.data_list if d.multi_id > 0})
    if multi:
        meta["instances"] = {
            n: {"used": 0, "present": sorted(d.multi_id for d in ul.data_list if d.name == n)} for n in multi
        }
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
        tg = ts(g)
        if "fix_type" in g.data:  # 3 = 3D fix and better; the rest dropped and counted
            fix = np.asarray(g.data["fix_type"]) >= 3
            if not fix.all():
                meta.setdefault("notes", []).append(
                    f"vehicle_gps_position: {int((~fix).sum())} of {fix.size} samples without a 3D fix "
                    "(fix_type < 3) dropped"
                )
            lat, lon, tg = np.asarray(lat)[fix], np.asarray(lon)[fix], tg[fix]
        x, y, o = north_east(lat, lon, origin)
        if x is not None:
            out["usv.x"], out["usv.y"] = (tg, x), (tg, y)
            meta["origin_deg"] = list(o)
    at = topics.get("vehicle_attitude")
    if at is not None and "q[0]" in at.data:
        r, p, y = quat_euler(*(at.data[f"q[{i}]"].astype(float) for i in range(4)))
        out["usv.phi"], out["usv.theta"], out["usv.psi"] = (ts(at), r), (ts(at), p), (ts(at), y)
    av = topics.get("vehicle_angular_velocity")
    if av is not None and "xyz[2]" in av.data:
        out["usv.r"] = (ts(av), av.data["xyz[2]"].astype(float))
    meta["vehicle"] = px4_vehicle(ul, topics)
    kind = meta["vehicle"]["type"]
    am = topics.get("actuator_motors")
    aerial = meta["vehicle"]["marine"] is False and not kind.startswith(("rover", "ground"))
    if am is not None and aerial:
        meta["notes"] = [f"no actuators imported: actuator_motors of a {kind} are not a boat's thrusters"]
    elif am is not None and "control[1]" in am.data:
        out["act.left"] = (ts(am), am.data["control[0]"].astype(float))
        out["act.right"] = (ts(am), am.data["control[1]"].astype(float))
    if "usv.x" not in out and "usv.psi" not in out:
        raise InputError(
            f"{path}: ULog has no vehicle_local_position, vehicle_gps_position or vehicle_attitude "
            f"topic (it has: {', '.join(meta['topics'][:15]) or 'none'})"
        )
    return out, meta
