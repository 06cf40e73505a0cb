"""Commands, modes, sticks and parameters of :class:`oceangnc.mavlink.vehicle.MavlinkVehicle` (the message dispatch)."""

from __future__ import annotations

import math

from .gcs_control import ControlMixin
from .protocol import AUTO, NAV_MODES, ROVER_MODES, ROVER_OTHER, RTL, STICK_MODES, mavlink, mode_name

M = mavlink
INT16_MAX = 32767
#: commands of the navigation modes (oceangnc.mavlink.nav)
_NAV_COMMANDS = {
    M.MAV_CMD_DO_REPOSITION,
    M.MAV_CMD_DO_CHANGE_SPEED,
    M.MAV_CMD_DO_SET_HOME,
    M.MAV_CMD_NAV_RETURN_TO_LAUNCH,
    M.MAV_CMD_NAV_LOITER_UNLIM,
}
_GLOBAL_FRAMES = (
    M.MAV_FRAME_GLOBAL,
    M.MAV_FRAME_GLOBAL_INT,
    M.MAV_FRAME_GLOBAL_RELATIVE_ALT,
    M.MAV_FRAME_GLOBAL_RELATIVE_ALT_INT,
    M.MAV_FRAME_GLOBAL_TERRAIN_ALT,
    M.MAV_FRAME_GLOBAL_TERRAIN_ALT_INT,
)


def _finite(*values) -> bool:
    return all(math.isfinite(v) for v in values)


def _whole(v: float, lo: float, hi: float) -> bool:
    """``v`` a whole number in [lo, hi] (command parameters that name an item, a mode, a message)."""
    return math.isfinite(v) and v == round(v) and lo <= v <= hi


class CommandsMixin(ControlMixin):
    """Message dispatch (``_handle`` -> ``_on_<message>``), arming, modes, the e-stop, the stick and the parameters."""

    def _for_us(self, m) -> bool:
        ts = getattr(m, "target_system", 0)
        return ts in (0, self.cfg_mav.system_id)

    def _oor(self, what: str) -> None:
        self.counts["rx_out_of_range"] += 1
        if self.counts["rx_out_of_range"] in (1, 10, 100, 1000):
            self.event(f"ignored out-of-range {what}", M.MAV_SEVERITY_WARNING)

    def _ack(self, command: int, result: int) -> None:
        self._acked = (command, result)
        self._send(self.mav.command_ack_encode(command, result))

    def _param_error(self, cmd: int, params, nan_ok=()) -> str | None:
        """Why a command's parameters are refused (non-finite, or out of the command's range), or None.
        ``nan_ok``: indices of ``params`` where NaN means "unchanged" (MAVLink's convention for the yaw and
        the altitude of DO_REPOSITION / DO_SET_HOME, which QGroundControl sends)."""
        if not _finite(*(v for i, v in enumerate(params) if not (i in nan_ok and math.isnan(v)))):
            return "a non-finite parameter"
        p1, p2 = params[0], params[1]
        n = len(self.mission)
        if cmd == M.MAV_CMD_COMPONENT_ARM_DISARM and p1 not in (0.0, 1.0):
            return f"param1 {p1} (0 disarm, 1 arm)"
        if cmd == M.MAV_CMD_DO_FLIGHTTERMINATION and p1 not in (0.0, 1.0):
            return f"param1 {p1} (0 reset, 1 terminate)"
        if cmd == M.MAV_CMD_DO_SET_MODE and not (_whole(p1, 0, 255) and _whole(p2, 0, 2**31 - 1)):
            return f"mode {p1}/{p2}"
        if cmd == M.MAV_CMD_MISSION_START and not (_whole(p1, 0, max(n - 1, 0)) and _whole(p2, 0, max(n - 1, 0))):
            return f"mission items {p1}..{p2} of {n}"
        if cmd == M.MAV_CMD_DO_SET_MISSION_CURRENT and not _whole(p1, 0, max(n - 1, 0)):
            return f"mission item {p1} of {n}"
        if cmd in (M.MAV_CMD_REQUEST_MESSAGE, M.MAV_CMD_SET_MESSAGE_INTERVAL, M.MAV_CMD_GET_MESSAGE_INTERVAL) and not (
            _whole(p1, 0, 16777215)
        ):
            return f"message id {p1}"
        return None

    def _on_command_long(self, m) -> None:
        cmd = m.command
        nan_ok = (2, 3, 6) if cmd in (M.MAV_CMD_DO_REPOSITION, M.MAV_CMD_DO_SET_HOME) else ()
        why = self._param_error(cmd, (m.param1, m.param2, m.param3, m.param4, m.param5, m.param6, m.param7), nan_ok)
        if why is not None:  # refused with an answer, and nothing changes
            self._oor(f"COMMAND_LONG {cmd}: {why}")
            self._ack(cmd, M.MAV_RESULT_DENIED)
            return
        res = None
        if self.sub1 is not None:
            p = (m.param1, m.param2, m.param3, m.param4)
            res = self._sub_command(self.sub1, m, cmd, p, m.param5, m.param6, m.param7)
        if res is not None:
            self._ack(cmd, res)
        elif cmd == M.MAV_CMD_COMPONENT_ARM_DISARM:
            self._ack(cmd, self._arm(m.param1 > 0.5))
        elif cmd == M.MAV_CMD_DO_SET_MODE:
            self._ack(cmd, self._set_mode(round(m.param2), "DO_SET_MODE"))
        elif cmd == M.MAV_CMD_DO_FLIGHTTERMINATION:
            self._ack(cmd, self._estop(m.param1 > 0.5))
        elif cmd == M.MAV_CMD_MISSION_START:  # ArduPilot: start the mission in AUTO from param1 (0: current)
            first = round(m.param1)
            if first >= 1:
                self._set_current(first)
            self._ack(cmd, self._set_mode(AUTO, "MISSION_START"))
        elif cmd == M.MAV_CMD_DO_SET_MISSION_CURRENT:
            self._ack(cmd, self._set_current(round(m.param1)))
        elif cmd in _NAV_COMMANDS:
            self._ack(cmd, self._nav_command(cmd, m.param1, m.param2, m.param5, m.param6))
        elif cmd in (M.MAV_CMD_REQUEST_MESSAGE, M.MAV_CMD_REQUEST_AUTOPILOT_CAPABILITIES, M.MAV_CMD_GET_HOME_POSITION):
            send = self._requested(cmd, m.param1)
            self._ack(cmd, M.MAV_RESULT_UNSUPPORTED if send is None else M.MAV_RESULT_ACCEPTED)
            if send is not None:
                send()
        elif cmd == M.MAV_CMD_SET_MESSAGE_INTERVAL:
            self._ack(cmd, self._set_interval(round(m.param1), m.param2))
        elif cmd == M.MAV_CMD_GET_MESSAGE_INTERVAL:
            name = self._stream_name(round(m.param1))
            self._ack(cmd, M.MAV_RESULT_ACCEPTED if name else M.MAV_RESULT_UNSUPPORTED)
            if name:
                hz = self.rates[name]
                self._send(self.mav.message_interval_encode(round(m.param1), round(1e6 / hz) if hz > 0 else -1))

        else:
            self.counts["rx_ignored"] += 1
            self._ack(cmd, M.MAV_RESULT_UNSUPPORTED)

    def _requested(self, cmd: int, param1: float):
        """The sender of the message a request command asks for (REQUEST_MESSAGE names it in param1; the
        legacy REQUEST_AUTOPILOT_CAPABILITIES and GET_HOME_POSITION imply it), or None if unsupported."""
        mid = round(param1) if cmd == M.MAV_CMD_REQUEST_MESSAGE else None
        if cmd == M.MAV_CMD_REQUEST_AUTOPILOT_CAPABILITIES or mid == M.MAVLINK_MSG_ID_AUTOPILOT_VERSION:
            return self._send_autopilot_version
        if cmd == M.MAV_CMD_GET_HOME_POSITION or mid == M.MAVLINK_MSG_ID_HOME_POSITION:
            return self._send_home if self.home is not None else None
        one_shot = {
            "SYS_STATUS": self._send_sys_status,
            "BATTERY_STATUS": self._send_battery_status,
            "MISSION_CURRENT": self._send_mission_current,
        }
        name = M.mavlink_map[mid].msgname if mid in M.mavlink_map else None
        return one_shot.get(name)

    # -- telemetry rates, time, file transfer ------------------------------------------------------------
    def _stream_name(self, msgid: int) -> str | None:
        cls = M.mavlink_map.get(msgid)
        return cls.msgname if cls is not None and cls.msgname in self.rates else None

    def _set_interval(self, msgid: int, interval_us: float) -> int:
        """MAV_CMD_SET_MESSAGE_INTERVAL: param2 -1 stops the message, 0 restores its default rate, > 0 is the
        interval in us (at most MAX_RATE_HZ); messages the vehicle does not stream are UNSUPPORTED."""
        from .protocol import MAX_RATE_HZ, TELEMETRY

        name = self._stream_name(msgid)
        if name is None:
            return M.MAV_RESULT_UNSUPPORTED
        if interval_us == -1:
            hz = 0.0
        elif interval_us == 0:
            hz = TELEMETRY[name][0]
        elif interval_us > 0:
            hz = min(MAX_RATE_HZ, 1e6 / interval_us)
        else:
            self._oor(f"SET_MESSAGE_INTERVAL {name} {interval_us} us")
            return M.MAV_RESULT_DENIED
        self.set_rate(name, hz)
        return M.MAV_RESULT_ACCEPTED

    def _on_request_data_stream(self, m) -> None:
        """REQUEST_DATA_STREAM (ArduPilot's stream groups, :data:`oceangnc.mavlink.protocol.STREAMS`):
        ``req_message_rate`` Hz for every message of the group (0 or start_stop 0 stops them)."""
        from .protocol import STREAMS

        ids = list(STREAMS) if m.req_stream_id == M.MAV_DATA_STREAM_ALL else [m.req_stream_id]
        hz = float(m.req_message_rate) if m.start_stop else 0.0
        for sid in ids:
            for name in STREAMS.get(sid, ()):
                self.set_rate(name, hz)

    def _on_timesync(self, m) -> None:
        """TIMESYNC request (tc1 = 0): answered with the vehicle's clock in tc1 and the request's ts1."""
        if m.tc1 == 0:
            self._send(self.mav.timesync_encode(int(self.clock() * 1e9), m.ts1))

    def _ftp_nak(self, m) -> None:
        """MAVFTP: no file system here. Every request gets a NAK (opcode 129) with error 10 "file not found" for
        opening, listing and reading (so MAVProxy's and QGroundControl's parameter download falls back to
        PARAM_REQUEST_LIST at once) and 1 "fail" otherwise, seq + 1, to the requester's system and component."""
        import struct

        p = bytes(m.payload)
        if len(p) < 12:
            self.counts["rx_bad"] += 1
            return
        seq, session, opcode = struct.unpack_from("<HBB", p, 0)
        self.counts["ftp_naks"] += 1
        file_ops = (3, 4, 5, 15)  # ListDirectory, OpenFileRO, ReadFile, BurstReadFile
        err = 10 if opcode in file_ops else 1
        hdr = struct.pack("<HBBBBBBI", (seq + 1) % 65536, session, 129, 1, opcode, 0, 0, 0)
        payload = list(hdr + bytes([err])) + [0] * (251 - 13)
        self._send(self.mav.file_transfer_protocol_encode(0, m.get_srcSystem(), m.get_srcComponent(), payload))

    def _on_command_int(self, m) -> None:
        nan_ok = (2, 3, 4) if m.command in (M.MAV_CMD_DO_REPOSITION, M.MAV_CMD_DO_SET_HOME) else ()
        why = self._param_error(m.command, (m.param1, m.param2, m.param3, m.param4, m.z), nan_ok)
        if why is not None:
            self._oor(f"COMMAND_INT {m.command}: {why}")
            self._ack(m.command, M.MAV_RESULT_DENIED)
            return
        res = None
        if self.sub1 is not None:
            p = (m.param1, m.param2, m.param3, m.param4)
            res = self._sub_command(self.sub1, m, m.command, p, m.x * 1e-7, m.y * 1e-7, float(m.z))
        if res is not None:
            self._ack(m.command, res)
        elif m.command == M.MAV_CMD_DO_SET_MODE:
            self._ack(m.command, self._set_mode(round(m.param2), "DO_SET_MODE"))
        elif m.command in _NAV_COMMANDS:
            if m.command in (M.MAV_CMD_DO_REPOSITION, M.MAV_CMD_DO_SET_HOME) and m.frame not in _GLOBAL_FRAMES:
                self._oor(f"COMMAND_INT {m.command}: frame {m.frame}")
                self._ack(m.command, M.MAV_RESULT_DENIED)
                return
            self._ack(m.command, self._nav_command(m.command, m.param1, m.param2, m.x * 1e-7, m.y * 1e-7))
        else:
            self.counts["rx_ignored"] += 1
            self._ack(m.command, M.MAV_RESULT_UNSUPPORTED)

    def _nav_command(self, cmd: int, p1: float, p2: float, lat: float, lon: float) -> int:
        """DO_REPOSITION (go there in GUIDED, param1 speed m/s or -1), DO_CHANGE_SPEED (param2 m/s),
        DO_SET_HOME (param1 1: here, else lat/lon), NAV_RETURN_TO_LAUNCH and NAV_LOITER_UNLIM (the modes)."""
        if cmd == M.MAV_CMD_DO_REPOSITION:
            # ArduPilot: outside GUIDED only with the CHANGE_MODE flag (QGroundControl and MAVSDK set it)
            change = bool(int(p2) & M.MAV_DO_REPOSITION_FLAGS_CHANGE_MODE)
            res = self._guided_goto(lat, lon, "DO_REPOSITION", change_mode=change)
            if res == M.MAV_RESULT_ACCEPTED and p1 > 0:
                self._do_change_speed(p1)
            return res
        if cmd == M.MAV_CMD_DO_CHANGE_SPEED:
            return self._do_change_speed(p2)
        if cmd == M.MAV_CMD_DO_SET_HOME:
            return self._do_set_home(p1 == 1.0, lat, lon)
        if cmd == M.MAV_CMD_NAV_RETURN_TO_LAUNCH:
            return self._set_mode(RTL, "NAV_RETURN_TO_LAUNCH")
        if cmd == M.MAV_CMD_NAV_LOITER_UNLIM:
            from .protocol import LOITER

            return self._set_mode(LOITER, "NAV_LOITER_UNLIM")
        return M.MAV_RESULT_UNSUPPORTED

    def _on_set_position_target_global_int(self, m) -> None:
        """GUIDED only (ArduPilot: ignored in other modes, no answer): a position target (the type mask does
        not ignore x/y) in a global frame is the GUIDED destination; velocity/acceleration-only targets are
        not supported and counted as ignored."""
        from .protocol import GUIDED

        pos_ignored = m.type_mask & (M.POSITION_TARGET_TYPEMASK_X_IGNORE | M.POSITION_TARGET_TYPEMASK_Y_IGNORE)
        if self.mode != GUIDED or pos_ignored or m.coordinate_frame not in _GLOBAL_FRAMES:
            self.counts["rx_ignored"] += 1
            return
        lat, lon = m.lat_int * 1e-7, m.lon_int * 1e-7  # (the same target re-sent: _guided_goto keeps the leg)
        self._guided_goto(lat, lon, "SET_POSITION_TARGET", change_mode=False)

    def _on_set_mode(self, m) -> None:
        res = self._set_mode(int(m.custom_mode), "SET_MODE")
        self._ack(M.MAVLINK_MSG_ID_SET_MODE, res)

    def _arm(self, arm: bool) -> int:
        if arm:
            if self.estop:
                self.event("Arm: refused, e-stop latched", M.MAV_SEVERITY_WARNING)
                return M.MAV_RESULT_DENIED
            if self.ended:
                return M.MAV_RESULT_DENIED
            if not self.armed:
                self.armed = True
                self._on_armed()
                self.event("Throttle armed")
        elif self.armed:
            self.armed = False
            self.event("Throttle disarmed")
        return M.MAV_RESULT_ACCEPTED

    def _set_mode(self, num: int, via: str) -> int:
        if num not in ROVER_MODES:
            self._oor(f"{via} mode {num} ({ROVER_OTHER.get(num, 'unknown')})")
            return M.MAV_RESULT_DENIED
        if num in STICK_MODES and not self.reads_stick:
            self.event(f"{mode_name(num)} refused: {self.scenario.name} takes no stick", M.MAV_SEVERITY_WARNING)
            return M.MAV_RESULT_DENIED
        if num in NAV_MODES and num != self.mode:
            why = self._nav_refusal(num)
            if why is not None:
                self.event(f"{mode_name(num)} refused: {why}", M.MAV_SEVERITY_WARNING)
                return M.MAV_RESULT_DENIED
        if num == AUTO and num != self.mode and self.route.available:
            start = self.mission_current if self.mission_current < len(self.mission) else 1
            if not self._nav_points(start)[0]:
                self.event("AUTO refused: no waypoint in the mission", M.MAV_SEVERITY_WARNING)
                return M.MAV_RESULT_DENIED
        self.stick_failsafe = False  # the operator chose a mode
        if num != self.mode:
            stick_takes_over = num in STICK_MODES and self.mode not in STICK_MODES
            self._switch_mode(num)
            if stick_takes_over:
                self._restart_resume_ramp()
            if num == AUTO and self.route.available:
                if self.mission_current >= len(self.mission):
                    self.mission_current = 1
                self._start_mission()
            self.event(
                f"Mode {mode_name(num)}"
                + ("" if num != AUTO or self.route.available else ": the scenario's own guidance (no mission upload)")
            )
        return M.MAV_RESULT_ACCEPTED

    def _restart_resume_ramp(self) -> None:
        """The stick takes over from a mode where it did not drive (HOLD after a failsafe, AUTO, ...): the
        thrust restarts from zero on the e-stop's resume ramp (:mod:`oceangnc.core.estop`), so a stick
        held over at the switch is not applied as a step (issue 26). The blocks see ``_estop`` for this
        instant only (fired once, as when the e-stop rises); the next pass clears it and they ramp."""
        sim = self.sim
        sim.inject({"_estop": True})
        for b in sim.blocks:
            b.step(sim.t, sim.bus)

    def _estop(self, engage: bool) -> int:
        if engage and not self.estop:
            self.estop = True
            self.armed = False
            self.event("EMERGENCY STOP: thrust zero, disarmed (latched)", M.MAV_SEVERITY_EMERGENCY)
        elif not engage and self.estop:
            self.estop = False
            self.stick = (0.0, 0.0)
            self.event("e-stop reset (still disarmed)")
        return M.MAV_RESULT_ACCEPTED

    def _on_manual_control(self, m) -> None:
        if m.target not in (0, self.cfg_mav.system_id):
            return
        x = 0 if m.x == INT16_MAX else m.x
        r = 0 if m.r == INT16_MAX else m.r
        if abs(x) > 1000 or abs(r) > 1000:
            self._oor(f"MANUAL_CONTROL x={m.x} r={m.r}")
            return
        if self.mode in STICK_MODES:
            self.stick = (x / 1000.0, r / 1000.0)
            self._stick_seen()

    def _on_rc_channels_override(self, m) -> None:
        def axis(pwm):
            if pwm in (0, 65535):
                return None
            if not (800 <= pwm <= 2200):
                raise ValueError(pwm)
            return max(-1.0, min(1.0, (pwm - 1500) / 400.0))

        try:
            yaw = axis(m.chan1_raw)
            surge = axis(m.chan3_raw)
        except ValueError:
            self._oor(f"RC_CHANNELS_OVERRIDE ch1={m.chan1_raw} ch3={m.chan3_raw}")
            return
        if self.mode in STICK_MODES:
            self.stick = (self.stick[0] if surge is None else surge, self.stick[1] if yaw is None else yaw)
            self._stick_seen()

    def _stick_seen(self) -> None:
        """A stick message in a stick mode: the stream is flowing (its loss is the stick failsafe)."""
        self.t_stick = self.clock()
        self.stick_flowing = True
        if self.stick_failsafe:
            self.stick_failsafe = False
            self.event("Stick input back; failsafe cleared")
