"""System 2: the towed UUV of the combined scenarios as an ArduSub-like vehicle that answers ground stations.

In ``combined-survey``, ``waypoints-square`` and ``field-test`` the UUV is towed by the USV: its controller
keeps it on a station behind the USV (leader-follower, 003 eq. 3.8) and its depth is the cable's. It has no
mission or depth loop of its own, so system 2 is a vehicle a ground station can *see and query*, not one it
can fly (docs/mavlink-and-logs.md, "Against ArduPilot Rover and Sub"):

* HEARTBEAT: MAV_TYPE_SUBMARINE, ArduSub's custom mode GUIDED (4: guided by the tow), the shared armed flag;
* AUTOPILOT_VERSION (the package version, MAVLINK2 / PARAM_FLOAT / MISSION_INT / COMMAND_INT), HOME_POSITION;
* the parameter protocol over its own table: SYSID_THISMAV, the station behind the USV as ArduPilot's follow
  offsets (FOLL_OFS_X ahead / FOLL_OFS_Y to starboard in the leader's frame, FOLL_OFS_TYPE 1 = relative to
  the leader's heading, read-only) and the UUV's PID gains where its controller has them (UUV_POS_*,
  UUV_ANG_*, UUV_LOS_*);
* arm / disarm and the e-stop act on the one vehicle (the USV and the UUV share the thrust enable);
* mission lists are empty; an upload gets MAV_MISSION_UNSUPPORTED, a mode other than GUIDED is DENIED,
  other commands UNSUPPORTED, each with its answer.
"""

from __future__ import annotations

from .params import INT8, INT16, REAL32, Param, _attr, _pid
from .protocol import mavlink

M = mavlink

#: ArduSub's mode numbers (ArduSub/mode.h) a ground station may ask for
SUB_MODES = {0: "STABILIZE", 1: "ACRO", 2: "ALT_HOLD", 3: "AUTO", 4: "GUIDED", 7: "CIRCLE", 9: "SURFACE",
             16: "POSHOLD", 19: "MANUAL"}  # fmt: skip
SUB_GUIDED = 4


def build_uuv_params(v) -> dict[str, Param]:
    ps = [Param("SYSID_THISMAV", lambda: float(v.cfg_mav.uuv_system_id), None, 1, 250, INT16, "", "system id")]
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
    """Messages addressed to system 2 (see the module docstring)."""

    def _uuv_ack(self, command: int, result: int) -> None:
        self._send(self.mav_uuv.command_ack_encode(command, result), uuv=True)

    def _uuv_param_value(self, name: str, index: int | None = None) -> None:
        names = list(self.uuv_params)
        p = self.uuv_params[name]
        i = names.index(name) if index is None else index
        self._send(self.mav_uuv.param_value_encode(name.encode(), p.get(), p.kind, len(names), i), uuv=True)

    def _handle_uuv(self, m, kind: str) -> None:
        if kind in ("COMMAND_LONG", "COMMAND_INT"):
            self._take_control(m)
            self._link_alive(m)
            self._uuv_command(m)
        elif kind == "SET_MODE":
            self._take_control(m)
            self._uuv_mode(int(m.custom_mode), M.MAVLINK_MSG_ID_SET_MODE)
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
            self._take_control(m)
            why = p.refusal(float(m.param_value))
            if why is None:
                p.set(float(m.param_value))
                self.event(f"UUV {name} set to {p.get():g}")
            else:
                self._oor(f"UUV PARAM_SET {name} = {m.param_value}: {why}")
            self._uuv_param_value(name)
        elif kind == "MISSION_REQUEST_LIST":
            mt = getattr(m, "mission_type", 0)
            self._send(self.mav_uuv.mission_count_encode(m.get_srcSystem(), m.get_srcComponent(), 0, mt), uuv=True)
        elif kind in ("MISSION_COUNT", "MISSION_CLEAR_ALL"):
            ok = kind == "MISSION_CLEAR_ALL" or m.count == 0
            res = M.MAV_MISSION_ACCEPTED if ok else M.MAV_MISSION_UNSUPPORTED
            if not ok:
                self.event("UUV mission refused: the UUV follows the USV", M.MAV_SEVERITY_WARNING)
            mt = getattr(m, "mission_type", 0)
            self._send(self.mav_uuv.mission_ack_encode(m.get_srcSystem(), m.get_srcComponent(), res, mt), uuv=True)
        else:
            self.counts["rx_ignored"] += 1

    def _uuv_mode(self, num: int, command: int) -> None:
        if num == SUB_GUIDED:
            res = M.MAV_RESULT_ACCEPTED
        else:
            self.event(f"UUV {SUB_MODES.get(num, f'mode {num}')} refused: the UUV follows the USV",
                       M.MAV_SEVERITY_WARNING)  # fmt: skip
            res = M.MAV_RESULT_DENIED
        self._uuv_ack(command, res)

    def _uuv_command(self, m) -> None:
        cmd = m.command
        p = [m.param1, m.param2, m.param3, m.param4]
        why = self._param_error(cmd, p)
        if why is not None:
            self._oor(f"UUV command {cmd}: {why}")
            self._uuv_ack(cmd, M.MAV_RESULT_DENIED)
            return
        if cmd == M.MAV_CMD_COMPONENT_ARM_DISARM:
            self._uuv_ack(cmd, self._arm(m.param1 > 0.5))  # one vehicle: the shared thrust enable
        elif cmd == M.MAV_CMD_DO_FLIGHTTERMINATION:
            self._uuv_ack(cmd, self._estop(m.param1 > 0.5))
        elif cmd == M.MAV_CMD_DO_SET_MODE:
            self._uuv_mode(round(m.param2), cmd)
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
        elif cmd == M.MAV_CMD_SET_MESSAGE_INTERVAL:
            name = self._stream_name(round(m.param1))
            ok = name in ("HEARTBEAT", "GLOBAL_POSITION_INT", "ATTITUDE", "VFR_HUD")
            self._uuv_ack(cmd, self._set_interval(round(m.param1), m.param2) if ok else M.MAV_RESULT_UNSUPPORTED)
        else:
            self.counts["rx_ignored"] += 1
            self._uuv_ack(cmd, M.MAV_RESULT_UNSUPPORTED)
