"""ArduSub systems: the towed UUV of the combined scenarios (system 2) and a ROV of a vehicle file (system 1 of
``rov-station-keeping``), each flown in ArduSub's modes (:mod:`oceangnc.mavlink.sub`, laws in
:mod:`oceangnc.control.ardusub`), and the messages addressed to them (docs/mavlink-and-logs.md).

In ``combined-survey``, ``waypoints-square`` and ``field-test`` the UUV is towed by the USV: its controller
keeps it on a station behind the USV (leader-follower, 003 eq. 3.8) and its depth is set by the cable, whose
length the winch changes (``oceangnc mavlink`` enables the winch of a combined scenario). System 2 answers:

* HEARTBEAT: MAV_TYPE_SUBMARINE, ArduSub's custom mode, the shared armed flag;
* AUTOPILOT_VERSION (the package version, MAVLINK2 / PARAM_FLOAT / MISSION_INT / COMMAND_INT), HOME_POSITION;
* the parameter protocol over its own table: SYSID_THISMAV, the station behind the USV as ArduPilot's follow
  offsets (FOLL_OFS_X ahead / FOLL_OFS_Y to starboard in the leader's frame, FOLL_OFS_TYPE 1 = relative to
  the leader's heading, read-only), the UUV's PID gains where its controller has them (UUV_POS_*,
  UUV_ANG_*, UUV_LOS_*), ArduSub's PILOT_SPEED_UP / PILOT_SPEED_DN (the depth reference's speeds, cm/s),
  WPNAV_RADIUS (cm) and FS_PILOT_TIMEOUT (s);
* arm / disarm and the e-stop act on the one vehicle (the USV and the UUV share the thrust enable);
* modes, MANUAL_CONTROL (z: the winch), GUIDED depth targets and missions (:mod:`oceangnc.mavlink.sub`);
  other commands UNSUPPORTED, each with its answer.
"""

from __future__ import annotations

from .params import INT8, INT16, REAL32, Param, _attr, _pid
from .protocol import mavlink
from .sub import SUB_MODES, SubAutopilot  # noqa: F401  (SUB_MODES: public here before)

M = mavlink

SUB_GUIDED = 4


def sub_params(v, sub, block) -> list[Param]:
    """ArduSub's parameters of an ArduSub system ``sub`` flown by law block ``block`` (:mod:`oceangnc.control.ardusub`)."""
    from ..control.ardusub import DEPTH_PARAMS, ROV_PARAMS

    P = ROV_PARAMS.at if sub.horizontal else DEPTH_PARAMS.at
    ps = []
    for name, i, doc in (("PILOT_SPEED_UP", P.up, "pilot's largest climb speed"),
                         ("PILOT_SPEED_DN", P.dn, "pilot's largest descent speed")):  # fmt: skip

        def get(i=i):
            return float(block.pa[i]) * 100.0

        def put(x, i=i):
            block.pa[i] = float(x) / 100.0

        ps.append(Param(name, get, put, 10.0, 500.0, INT16, "cm/s", doc))
    ps.append(Param("WPNAV_RADIUS", lambda: sub.wp_radius_m * 100.0, lambda x: setattr(sub, "wp_radius_m", x / 100.0),
                    5.0, 10000.0, REAL32, "cm", "mission item acceptance radius"))  # fmt: skip
    ps.append(Param("FS_PILOT_TIMEOUT", lambda: sub.pilot_timeout_s, lambda x: setattr(sub, "pilot_timeout_s", x),
                    0.1, 3.0, REAL32, "s", "pilot input lost after this, sticks neutral"))  # fmt: skip
    if sub.horizontal:
        ps.append(Param("JS_GAIN_DEFAULT", lambda: float(block.pa[P.gain]),
                        lambda x: block.pa.__setitem__(P.gain, float(x)), 0.1, 1.0, REAL32, "",
                        "stick gain: full stick = this x the largest force on the axis"))  # fmt: skip
    return ps


def build_uuv_params(v) -> dict[str, Param]:
    ps = [Param("SYSID_THISMAV", lambda: float(v.cfg_mav.uuv_system_id), None, 1, 250, INT16, "", "system id")]
    depth_block = next((b for b in v.sim.blocks if type(b).__name__ == "SubDepth"), None)
    if depth_block is not None:
        ps += sub_params(v, v.sub2, depth_block)
    for b in v.sim.blocks:
        inner = getattr(b, "block", b)
        kind = type(inner).__name__
        if kind == "LeaderFollower":
            g, s = _attr(inner, "lx_d")
            ps.append(Param("FOLL_OFS_X", g, s, -1000.0, 1000.0, REAL32, "m", "station ahead of the USV (< 0 astern)"))
            g, s = _attr(inner, "ly_d")
            ps.append(Param("FOLL_OFS_Y", g, s, -1000.0, 1000.0, REAL32, "m", "station to the USV's starboard"))
            ps.append(Param("FOLL_OFS_TYPE", lambda: 1.0, None, 0, 1, INT8, "", "offsets in the leader's frame"))
        elif kind == "UUVPIDController":
            ps += _pid("UUV_POS", inner.pos, "along-track position", "", "", "")
            ps += _pid("UUV_ANG", inner.ang, "heading", "", "", "")
            ps += _pid("UUV_LOS", inner.los, "line-of-sight", "", "", "")
    return {p.name: p for p in ps}


class UUVMixin:
    """Messages addressed to an ArduSub system (see the module docstring): system 2, and system 1 when it
    is a ROV (``self.sub1``)."""

    def _uuv_ack(self, command: int, result: int) -> None:
        self._acked = (command, result)
        self._send(self.mav_uuv.command_ack_encode(command, result), uuv=True)

    def _uuv_param_value(self, name: str, index: int | None = None) -> None:
        names = list(self.uuv_params)
        p = self.uuv_params[name]
        i = names.index(name) if index is None else index
        self._send(self.mav_uuv.param_value_encode(name.encode(), p.get(), p.kind, len(names), i), uuv=True)

    def _handle_sub(self, sub, m, kind: str) -> bool:
        """Modes, sticks, GUIDED targets and missions of ArduSub system ``sub``; False if ``kind`` is none
        of these (the caller handles it)."""
        if kind == "SET_MODE":
            res = sub.set_mode(int(m.custom_mode), "SET_MODE")
            sub._ack(M.MAVLINK_MSG_ID_SET_MODE, res)
        elif kind == "MANUAL_CONTROL":
            sub.manual_control(m)
        elif kind == "RC_CHANNELS_OVERRIDE":
            sub.rc_override(m)
        elif kind == "SET_POSITION_TARGET_GLOBAL_INT":
            sub.set_position_target_global_int(m)
        elif kind == "SET_POSITION_TARGET_LOCAL_NED":
            sub.set_position_target_local_ned(m)
        elif kind in ("MISSION_COUNT", "MISSION_CLEAR_ALL", "MISSION_SET_CURRENT"):
            getattr(sub, "_on_" + kind.lower())(m)
        elif kind in ("MISSION_REQUEST_LIST", "MISSION_ITEM_INT", "MISSION_ITEM", "MISSION_REQUEST_INT",
                      "MISSION_REQUEST"):  # fmt: skip
            getattr(sub, "_on_" + kind.lower())(m)
        elif kind == "MISSION_ACK":
            pass
        else:
            return False
        return True

    def _sub_command(self, sub, m, cmd: int, p, lat: float, lon: float, alt: float) -> int | None:
        """ArduSub's mode and mission commands for ``sub`` (the result), or None if ``cmd`` is not one."""
        if cmd == M.MAV_CMD_DO_SET_MODE:
            return sub.set_mode(round(p[1]), "DO_SET_MODE")
        if cmd == M.MAV_CMD_MISSION_START:
            if round(p[0]) >= 1:
                sub._set_current(round(p[0]))
            return sub.set_mode(sub._AUTO, "MISSION_START")
        if cmd == M.MAV_CMD_DO_SET_MISSION_CURRENT:
            return sub._set_current(round(p[0]))
        if cmd == M.MAV_CMD_DO_REPOSITION:
            return sub.reposition(lat, lon, alt)
        return None

    def _handle_uuv(self, m, kind: str) -> None:
        sub = self.sub2
        if kind in ("COMMAND_LONG", "COMMAND_INT"):
            self._uuv_command(m)
        elif self._handle_sub(sub, m, kind):
            pass
        elif kind == "PARAM_REQUEST_LIST":
            for i, name in enumerate(self.uuv_params):
                self._uuv_param_value(name, i)
        elif kind == "PARAM_REQUEST_READ":
            names = list(self.uuv_params)
            pid = m.param_id.decode(errors="replace") if isinstance(m.param_id, bytes) else str(m.param_id)
            pid = pid.rstrip("\x00")
            if 0 <= m.param_index < len(names):
                self._uuv_param_value(names[m.param_index], m.param_index)
            elif m.param_index < 0 and pid in self.uuv_params:
                self._uuv_param_value(pid)
        elif kind == "PARAM_SET":
            name = m.param_id.decode(errors="replace") if isinstance(m.param_id, bytes) else str(m.param_id)
            name = name.rstrip("\x00")
            p = self.uuv_params.get(name)
            if p is None:
                self.counts["rx_ignored"] += 1
                return
            why = p.refusal(float(m.param_value))
            if why is None:
                p.set(float(m.param_value))
                self.event(f"UUV {name} set to {p.get():g}")
            else:
                self._oor(f"UUV PARAM_SET {name} = {m.param_value}: {why}")
            self._uuv_param_value(name)
        else:
            self.counts["rx_ignored"] += 1

    def _uuv_command(self, m) -> None:
        cmd = m.command
        p = [m.param1, m.param2, m.param3, m.param4]
        nan_ok = (2, 3) if cmd == M.MAV_CMD_DO_REPOSITION else ()
        own = (M.MAV_CMD_MISSION_START, M.MAV_CMD_DO_SET_MISSION_CURRENT)  # ranges: this system's mission
        why = self._param_error(0 if cmd in own else cmd, p, nan_ok)
        if why is not None:
            self._oor(f"UUV command {cmd}: {why}")
            self._uuv_ack(cmd, M.MAV_RESULT_DENIED)
            return
        if m.get_type() == "COMMAND_INT":
            lat, lon, alt = m.x * 1e-7, m.y * 1e-7, float(m.z)
        else:
            lat, lon, alt = m.param5, m.param6, m.param7
        res = self._sub_command(self.sub2, m, cmd, p, lat, lon, alt)
        if res is not None:
            self._uuv_ack(cmd, res)
        elif cmd == M.MAV_CMD_COMPONENT_ARM_DISARM:
            self._uuv_ack(cmd, self._arm(m.param1 > 0.5))  # one vehicle: the shared thrust enable
        elif cmd == M.MAV_CMD_DO_FLIGHTTERMINATION:
            self._uuv_ack(cmd, self._estop(m.param1 > 0.5))
        elif cmd == M.MAV_CMD_REQUEST_AUTOPILOT_CAPABILITIES or (
            cmd == M.MAV_CMD_REQUEST_MESSAGE and round(m.param1) == M.MAVLINK_MSG_ID_AUTOPILOT_VERSION
        ):
            self._uuv_ack(cmd, M.MAV_RESULT_ACCEPTED)
            self._send_autopilot_version(uuv=True)
        elif cmd == M.MAV_CMD_GET_HOME_POSITION or (
            cmd == M.MAV_CMD_REQUEST_MESSAGE and round(m.param1) == M.MAVLINK_MSG_ID_HOME_POSITION
        ):
            self._uuv_ack(cmd, M.MAV_RESULT_ACCEPTED)
            self._send_home(uuv=True)
        elif cmd == M.MAV_CMD_REQUEST_MESSAGE and round(m.param1) == M.MAVLINK_MSG_ID_SYS_STATUS:
            self._uuv_ack(cmd, M.MAV_RESULT_ACCEPTED)
            self._send_sys_status(uuv=True)
        elif cmd == M.MAV_CMD_REQUEST_MESSAGE and round(m.param1) == M.MAVLINK_MSG_ID_MISSION_CURRENT:
            self._uuv_ack(cmd, M.MAV_RESULT_ACCEPTED)
            self.sub2.send_mission_current()
        elif cmd == M.MAV_CMD_SET_MESSAGE_INTERVAL:
            name = self._stream_name(round(m.param1))
            ok = name in ("HEARTBEAT", "SYS_STATUS", "GLOBAL_POSITION_INT", "ATTITUDE", "VFR_HUD", "MISSION_CURRENT")
            self._uuv_ack(cmd, self._set_interval(round(m.param1), m.param2) if ok else M.MAV_RESULT_UNSUPPORTED)
        else:
            self.counts["rx_ignored"] += 1
            self._uuv_ack(cmd, M.MAV_RESULT_UNSUPPORTED)


#: ArduSub's FRAME_CONFIG values (ArduSub's frame classes) for the thruster layouts of a vehicle file
FRAME_CONFIGS = {0: "bluerov1", 1: "vectored", 2: "vectored_6dof", 3: "vectored_6dof_90deg", 4: "simplerov-3",
                 5: "simplerov-4", 6: "simplerov-5", 7: "custom"}  # fmt: skip


def frame_config(vf) -> int:
    """ArduSub's FRAME_CONFIG of a vehicle file: 2 (vectored_6dof, the BlueROV2 Heavy) for 4 vectored
    horizontal + 4 vertical thrusters, 1 (vectored, the BlueROV2) for 4 vectored + 2 vertical, else 7 (custom)."""
    vertical = sum(1 for t in vf.thrusters if abs(t.direction[2]) > 0.99)
    vectored = sum(
        1 for t in vf.thrusters if abs(t.direction[2]) < 0.01 and min(abs(t.direction[0]), abs(t.direction[1])) > 0.3
    )
    if vectored == 4 and vertical == 4 and len(vf.thrusters) == 8:
        return 2
    if vectored == 4 and vertical == 2 and len(vf.thrusters) == 6:
        return 1
    return 7


def rov_params(v, sub, block, vehicle: str) -> list[Param]:
    """System 1's ArduSub parameters when it is a ROV: FRAME_CONFIG (read-only, from the vehicle file's
    thrusters) and :func:`sub_params`."""
    from ..models.vehicle import load_vehicle

    fc = float(frame_config(load_vehicle(vehicle)))
    ps = [Param("FRAME_CONFIG", lambda: fc, None, 0, 7, INT8, "",
                "ArduSub frame: " + ", ".join(f"{k} {n}" for k, n in FRAME_CONFIGS.items())),
          Param("FS_GCS_ENABLE", lambda: float(sub.fs_gcs_enable), lambda x: setattr(sub, "fs_gcs_enable", int(x)),
                0, 4, INT8, "", "GCS failsafe: 0 off, 1 warn, 2 disarm, 3 ALT_HOLD, 4 SURFACE")]  # fmt: skip
    return ps + sub_params(v, sub, block)
