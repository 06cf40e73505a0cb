"""ArduPilot logs: MAVLink telemetry (``.tlog``) and DataFlash (``.bin``), read with pymavlink."""

from __future__ import annotations

import math
import struct
from pathlib import Path

import numpy as np

from ....errors import InputError
from ._common import mav_type_class, mav_type_name, north_east, servo_map, servo_norm, truncated, vehicle


# -- MAVLink telemetry log (.tlog) ------------------------------------------------------------------------


def read_tlog(
    path: Path, allow_truncated: bool = False, system: int | None = None, origin=None, servos: str | None = None, **_
):
    """MAVLink telemetry log: records of an 8-byte big-endian UNIX time (us) and one MAVLink frame.

    Time base: the vehicle's clock (``time_boot_ms`` / ``time_usec``) where a message has one, else the
    record's time stamp shifted by the median offset between the two (so both share one axis).
    """
    from ...mavlink_dialect import mavlink as M

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
            truncated(
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
    if offs:
        meta["unix_offset_s"] = off  # the records' UNIX stamps minus the vehicle clock

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
    gp_depth = gp  # the depth (relative altitude: barometer / pressure sensor) needs no GPS fix: an ROV has none
    raw = get("GPS_RAW_INT")
    if gp and raw:  # the estimate's position while the GPS had no 3D fix (fix_type < 3) is not used
        tr = np.array([t_of(s, m) for s, m in raw])
        order = np.argsort(tr, kind="stable")
        tr, fix = tr[order], np.array([m.fix_type >= 3 for _, m in raw])[order]
        tg = np.array([t_of(s, m) for s, m in gp])
        k = np.searchsorted(tr, tg, side="right") - 1
        ok = (k >= 0) & fix[np.clip(k, 0, None)]
        if not ok.all():
            meta.setdefault("notes", []).append(
                f"GLOBAL_POSITION_INT: {int((~ok).sum())} of {ok.size} positions while GPS_RAW_INT had no 3D fix "
                "(fix_type < 3) dropped (the depth, relative_alt, is kept)"
            )
            gp = [r for r, keep in zip(gp, ok) if keep]
    if gp:
        x, y, o = north_east([m.lat * 1e-7 for _, m in gp], [m.lon * 1e-7 for _, m in gp], origin)
        if x is not None:
            t = np.array([t_of(s, m) for s, m in gp])
            out["usv.x"], out["usv.y"] = (t, x), (t, y)
            meta["origin_deg"] = list(o)
        put("usv.vn", gp, lambda m: m.vx * 0.01)
        put("usv.ve", gp, lambda m: m.vy * 0.01)
    hb = autopilot_heartbeat([m for _, m in get("HEARTBEAT")])
    if hb is not None and mav_type_class(int(hb.type)) == "submarine":
        put("usv.z", gp_depth, lambda m: -m.relative_alt * 1e-3)
    elif gp_depth:
        meta.setdefault("notes", []).append(  # ArduRover's leaps when home is set (0.2 -> 584 m in SITL)
            "GLOBAL_POSITION_INT.relative_alt not imported: a surface vehicle's altitude (above home) is not a depth"
        )
    att = get("ATTITUDE")
    put("usv.psi", att, lambda m: m.yaw)
    put("usv.phi", att, lambda m: m.roll)
    put("usv.theta", att, lambda m: m.pitch)
    put("usv.r", att, lambda m: m.yawspeed)
    params = {}
    for _, m in get("PARAM_VALUE"):
        params[str(m.param_id).rstrip("\x00")] = float(m.param_value)
    if hb is not None:
        mt = int(hb.type)
        meta["vehicle"] = vehicle(
            mav_type_class(mt), f"HEARTBEAT type {mt} ({mav_type_name(mt)}) of component {hb.get_srcComponent()}"
        )
    else:
        meta["vehicle"] = vehicle(None, f"no HEARTBEAT from system {sysid}")
    so = get("SERVO_OUTPUT_RAW")
    logged = [n for n in range(1, 17) if so and hasattr(so[0][1], f"servo{n}_raw")]
    smap, notes = servo_map(params, servos, logged, _aerial(meta))
    meta["servo_map"] = {k: v[0] for k, v in smap.items()}
    meta["notes"] = notes + meta.get("notes", [])
    if so:
        t = np.array([t_of(s, m) for s, m in so])
        for sig, (n, trim, lo, hi, rev) in smap.items():
            out[sig] = (t, servo_norm([getattr(m, f"servo{n}_raw") for _, m in so], trim, lo, hi, rev))
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


#: MAV_COMP_ID_AUTOPILOT1, and MAV_AUTOPILOT_INVALID (a component that is no flight controller: camera, gimbal,
#: companion computer, e.g. BlueOS's camera manager, component 100, MAV_TYPE_CAMERA)
_AUTOPILOT_COMPONENT, _AUTOPILOT_INVALID = 1, 8


def autopilot_heartbeat(heartbeats: list):
    """The heartbeat that types the vehicle: component 1's (the autopilot), else the first from a component
    whose ``autopilot`` field names a flight stack, else the first (MAVLink common.xml: MAV_COMPONENT,
    MAV_AUTOPILOT). A BlueOS tlog's first system-1 heartbeat comes from its camera (component 100)."""
    if not heartbeats:
        return None
    for pick in (
        lambda m: m.get_srcComponent() == _AUTOPILOT_COMPONENT,
        lambda m: int(m.autopilot) != _AUTOPILOT_INVALID,
    ):
        found = next((m for m in heartbeats if pick(m)), None)
        if found is not None:
            return found
    return heartbeats[0]


# -- ArduPilot DataFlash (.bin) --------------------------------------------------------------------------


def _scan_dataflash(path: Path, data: bytes, allow: bool, meta: dict) -> None:
    """Walk the records with the FMT lengths: corrupt (no header where one must be) or truncated tail."""
    lengths = {0x80: 89}
    pos, n = 0, 0
    while pos < len(data):
        if len(data) - pos < 3:
            truncated(path, f"{len(data) - pos} stray byte(s) at the end", allow, meta)
            return
        if data[pos] != 0xA3 or data[pos + 1] != 0x95:
            raise InputError(f"{path}: corrupt DataFlash log: no record header at byte {pos} (after {n} records)")
        typ = data[pos + 2]
        if typ not in lengths:
            raise InputError(f"{path}: corrupt DataFlash log: record type {typ} at byte {pos} has no FMT")
        ln = lengths[typ]
        if pos + ln > len(data):
            truncated(path, f"record {n} at byte {pos} needs {ln} bytes, {len(data) - pos} left", allow, meta)
            return
        if typ == 0x80:
            lengths[data[pos + 3]] = data[pos + 4]
        pos += ln
        n += 1
    meta["records"] = n


#: ArduPilot firmware (the MSG / VER firmware string) -> vehicle class; Rover and Copter refined by FRAME_CLASS
FIRMWARE = {
    "ArduRover": "rover",
    "ArduCopter": "multirotor",
    "ArduPlane": "fixed-wing",
    "ArduSub": "submarine",
    "AntennaTracker": "antenna tracker",
    "Blimp": "airship",
}
#: the firmware strings of ArduPilot before 3.5 (``THISFIRMWARE`` "APM:Copter V3.3", "APM:Rover v2.50", "APM:Plane
#: V3.4.0", "APM:AntennaTracker V0.7"; ArduSub wrote "ArduSub" from its first release) -> today's name
LEGACY_FIRMWARE = {
    "APM:Copter": "ArduCopter",
    "APM:Rover": "ArduRover",
    "APM:Plane": "ArduPlane",
    "APM:AntennaTracker": "AntennaTracker",
    "APM:Sub": "ArduSub",
}
#: VER.BU (APM_BUILD_DIRECTORY) -> firmware
_BUILD = {
    1: "ArduRover",
    2: "ArduCopter",
    3: "ArduPlane",
    4: "AntennaTracker",
    7: "ArduSub",
    12: "Blimp",
    13: "ArduCopter",
}


def ardupilot_vehicle(firmware: str | None, params: dict, where: str) -> dict:
    """The vehicle class of an ArduPilot log from its firmware string and FRAME_CLASS (Rover: 1 rover, 2 boat,
    3 balance bot; Copter: 6, 11, 13 helicopters)."""
    if not firmware:
        return vehicle(None, "no firmware string (MSG / VER) in the log")
    name = next((k for k in FIRMWARE if firmware.startswith(k)), None)
    if name is None:
        name = next((v for k, v in LEGACY_FIRMWARE.items() if firmware.startswith(k)), None)
    if name is None:
        return vehicle(None, f"{where} '{firmware}' (not a known ArduPilot firmware)")
    kind = FIRMWARE[name]
    fc = params.get("FRAME_CLASS")
    src = f"{where} '{firmware}'"
    if fc is not None:
        fc = int(round(float(fc)))
        src += f", FRAME_CLASS={fc}"
    if name == "ArduRover":
        kind = {1: "ground rover", 2: "boat", 3: "ground rover"}.get(fc) if fc is not None else None
        if kind is None:
            return {**vehicle(None, src), "type": "rover (boat or ground: FRAME_CLASS not logged)"}
    elif name == "ArduCopter" and (fc in (6, 11, 13) or "heli" in firmware.lower()):
        kind = "helicopter"  # the traditional-helicopter build says "Heli" in its firmware string
    return vehicle(kind, src)


#: sensors with instances: the log's message names (ArduPilot 4 writes one message with an instance field I;
#: older logs GPS2, IMU2, IMU3) -> sensor
_INSTANCED = {"GPS": ("gps", 0), "GPS2": ("gps", 1), "IMU": ("imu", 0), "IMU2": ("imu", 1), "IMU3": ("imu", 2)}
#: GPS Status (fix type) from which a fix is used: 3 = 3D (4 DGPS, 5 RTK float, 6 RTK fixed)
GPS_FIX_3D = 3


def pick_instances(rows: dict, instances: dict | None, path: Path, meta: dict) -> dict:
    """One instance of each sensor (``{"imu": [rows], "gps": [rows]}``): ``instances[sensor]`` or the
    lowest (the primary); records which in ``meta["instances"]`` and a note when there is a choice."""
    want = dict(instances or {})
    bad = [k for k in want if k not in ("imu", "gps")]
    if bad:
        raise InputError(f"--instance {bad[0]}=...: unknown sensor; sensors with instances: imu, gps")
    out = {}
    for sensor in ("imu", "gps"):
        have = rows.get(sensor, {})
        if not have:
            if sensor in want:
                raise InputError(f"{path}: --instance {sensor}={want[sensor]}: the log has no {sensor.upper()} records")
            continue
        present = sorted(have)
        use = int(want.get(sensor, present[0]))
        if use not in have:
            raise InputError(
                f"{path}: --instance {sensor}={use}: no such {sensor.upper()} instance; the log has "
                f"{', '.join(map(str, present))}"
            )
        out[sensor] = have[use]
        meta.setdefault("instances", {})[sensor] = {"used": use, "present": present}
        if len(present) > 1:
            how = "--instance" if sensor in want else "the first (primary)"
            meta.setdefault("notes", []).append(
                f"{sensor.upper()}: instance {use} of {', '.join(map(str, present))} ({how}; "
                f"--instance {sensor}=N for another)"
            )
    return out


def read_dataflash(
    path: Path, allow_truncated: bool = False, origin=None, servos: str | None = None, instances=None, **_
):
    """ArduPilot DataFlash log via ``pymavlink.DFReader``: GPS (Status fix type, Lat, Lng deg, Spd m/s, GCrs
    deg), ATT (Roll, Pitch, Yaw deg), IMU (GyrZ rad/s), RCOU (C1..C14 PWM us, mapped by the SERVOn_FUNCTION
    parameters, see :func:`servo_map`); PARM (parameters), MSG / VER (firmware: the vehicle type); time
    TimeUS. GPS and IMU: one instance (field I, or GPS2 / IMU2 / IMU3), :func:`pick_instances`; GPS samples
    without a 3D fix (Status < 3) are dropped and counted."""
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
    sensors: dict[str, dict] = {}
    params: dict = {}
    firmware = None
    try:
        while True:
            try:
                m = log.recv_msg()
            except Exception as e:  # noqa: BLE001
                raise InputError(f"{path}: corrupt DataFlash log: {e}") from None
            if m is None:
                break
            kind = m.get_type()
            if kind in ("ATT", "RCOU", "CTUN", "BARO"):
                d = m.to_dict()
                if "TimeUS" in d:
                    rows.setdefault(kind, []).append(d)
            elif kind in _INSTANCED:
                d = m.to_dict()
                if "TimeUS" in d:
                    sensor, i = _INSTANCED[kind]
                    sensors.setdefault(sensor, {}).setdefault(int(d.get("I", i)), []).append(d)
            elif kind == "PARM":
                params[str(m.Name)] = float(m.Value)
            elif kind == "MSG" and firmware is None:
                text = str(getattr(m, "Message", ""))
                if any(text.startswith(k) for k in (*FIRMWARE, *LEGACY_FIRMWARE)):
                    firmware, where = text.strip(), "MSG"
            elif kind == "VER" and firmware is None:
                fws = str(getattr(m, "FWS", "") or "").strip()
                if fws:
                    firmware, where = fws, "VER.FWS"
                elif getattr(m, "BU", None) in _BUILD:
                    firmware, where = _BUILD[m.BU], f"VER.BU={m.BU}"
    finally:
        log.close()
    meta["vehicle"] = ardupilot_vehicle(firmware, params, where if firmware else "")
    if firmware:
        meta["firmware"] = firmware
    meta["parameters"] = len(params)
    out: dict = {}

    def col(kind, f, scale=1.0):
        r = rows.get(kind, [])
        if r and f in r[0]:
            return np.array([x["TimeUS"] * 1e-6 for x in r]), np.array([x[f] for x in r], float) * scale
        return None

    picked = pick_instances(sensors, instances, path, meta)
    rows["IMU"] = picked.get("imu", [])
    g = picked.get("gps", [])
    if g and "Status" in g[0]:
        n = len(g)
        g = [r for r in g if r["Status"] >= GPS_FIX_3D]
        if len(g) < n:
            use = meta["instances"]["gps"]["used"]
            meta.setdefault("notes", []).append(
                f"GPS instance {use}: {n - len(g)} of {n} samples without a 3D fix (Status < {GPS_FIX_3D}) dropped"
            )
            meta["gps_no_fix_dropped"] = n - len(g)
    if g:
        t = np.array([x["TimeUS"] * 1e-6 for x in g])
        x, y, o = north_east([r["Lat"] for r in g], [r["Lng"] for r in g], origin)
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
    depth = submarine_depth(rows, meta)
    if depth is not None:
        out["usv.z"] = depth
    rc = rows.get("RCOU", [])
    logged = [n for n in range(1, 33) if rc and f"C{n}" in rc[0]]
    smap, notes = servo_map(params, servos, logged, _aerial(meta))
    meta["servo_map"] = {k: v[0] for k, v in smap.items()}
    meta["notes"] = notes + meta.get("notes", [])
    for sig, (n, trim, lo, hi, rev) in smap.items():
        c = col("RCOU", f"C{n}")
        if c is not None:
            out[sig] = (c[0], servo_norm(c[1], trim, lo, hi, rev))
    meta["messages"] = sorted(k for k, v in rows.items() if v)
    if "usv.x" not in out and "usv.psi" not in out:
        raise InputError(
            f"{path}: DataFlash log has no GPS or ATT records (it has: {', '.join(sorted(log.name_to_id)[:15])})"
        )
    return out, meta


def submarine_depth(rows: dict, meta: dict):
    """An ArduSub log's depth (m, down positive) as ``(t, z)``: ``-CTUN.Alt``, the altitude estimate the
    depth controller holds (ArduSub ``Log_Write_Control_Tuning``: Alt, m, up, 0 at the surface), else
    ``-BARO.Alt`` of the first barometer instance (the depth sensor when it is the primary). None for other
    vehicles: a boat's or a drone's logged altitude is not a depth."""
    if (meta.get("vehicle") or {}).get("type") != "submarine":
        return None
    for kind in ("CTUN", "BARO"):
        r = rows.get(kind, [])
        if kind == "BARO":
            r = [x for x in r if int(x.get("I", 0)) == min(int(y.get("I", 0)) for y in r)] if r else r
        if r and "Alt" in r[0]:
            meta.setdefault("notes", []).append(f"usv.z (depth) from -{kind}.Alt")
            return np.array([x["TimeUS"] * 1e-6 for x in r]), -np.array([x["Alt"] for x in r], float)
    return None


def _aerial(meta: dict) -> str | None:
    """The vehicle class when it is known to be no boat (its outputs are then no thrusters), else None."""
    v = meta.get("vehicle") or {}
    return v.get("type") if v.get("marine") is False else None
