"""Who holds control of the MAVLink vehicle, and the message dispatch that enforces it (issue 41).

ArduPilot feeds its GCS failsafe with the heartbeats of one ground station only (GCS_MAVLINK::handle_heartbeat:
the sender must be SYSID_MYGCS, MAV_GCS_SYSID on master) and takes sticks (MANUAL_CONTROL,
RC_CHANNELS_OVERRIDE) only from it, counting them as its heartbeat. Here the controlling ground station is
``mavlink.gcs_sysid`` (SYSID_MYGCS) when set, else the one whose control act (:data:`_CONTROL_ACTS`: arming or
disarming, a mode change, a mission start) was last accepted; a read never passes control.
"""

from __future__ import annotations

from .protocol import mavlink

M = mavlink
_GCS_TYPES = (M.MAV_TYPE_GCS,)
#: the operator's explicit acts (ArduPilot has no implicit hand-over: its controlling ground station is SYSID_MYGCS,
#: a parameter; with ``mavlink.gcs_sysid`` unset the ground station whose act is accepted holds control from then on):
#: arming or disarming, a mode change (DO_SET_MODE, the modes' own commands), a mission start. Reads, rates,
#: parameters, uploads, home and speed changes never pass control (issue 41).
_CONTROL_ACTS = {
    M.MAV_CMD_COMPONENT_ARM_DISARM,
    M.MAV_CMD_DO_SET_MODE,
    M.MAV_CMD_MISSION_START,
    M.MAV_CMD_NAV_RETURN_TO_LAUNCH,
    M.MAV_CMD_NAV_LOITER_UNLIM,
}
#: messages whose answer may be a control act (a COMMAND_ACK with ACCEPTED)
_ACTING = ("COMMAND_LONG", "COMMAND_INT", "SET_MODE")
#: stick messages: only the controlling ground station's reach the vehicle, and they feed its link (ArduPilot's
#: GCS_MAVLINK_Rover::handle_manual_control / handle_rc_channels_override: "Only accept control from our gcs",
#: "considered to be a 'heartbeat' from the ground station for failsafe purposes")
_STICKS = ("MANUAL_CONTROL", "RC_CHANNELS_OVERRIDE")


class ControlMixin:
    """The controller, its link, and the dispatch of every received message (``_handle`` -> ``_on_<message>``)."""

    def _controller(self) -> int | None:
        """System id of the ground station that holds control: the configured ``mavlink.gcs_sysid`` (SYSID_MYGCS),
        else the one whose control act (:data:`_CONTROL_ACTS`) was last accepted (None before any)."""
        c = self.cfg_mav.gcs_sysid
        return c if c is not None else self.gcs_sysid

    def _control_state(self) -> tuple:
        return (self.armed, self.mode, *(s.mode for s in (self.sub1, self.sub2) if s is not None))

    def _control_act(self, m, kind: str, before: tuple) -> None:
        """After a command or SET_MODE from ``m``'s system: an accepted control act (arming or disarming, a mode
        change, a mission start; DO_REPOSITION when it changed the mode) makes its sender the controller (unless
        SYSID_MYGCS is set), and is traffic from the controller; anything else (a read above all) passes nothing."""
        acked = self._acked
        if acked is None or acked[1] != M.MAV_RESULT_ACCEPTED:
            return
        cmd = acked[0]
        changed = self._control_state() != before
        if kind == "SET_MODE" or cmd in _CONTROL_ACTS or (cmd == M.MAV_CMD_DO_REPOSITION and changed):
            if self.cfg_mav.gcs_sysid is None:
                self.gcs_sysid = m.get_srcSystem()
            self._link_alive(m)

    def _link_alive(self, m) -> None:
        """Only the controlling ground station keeps the link alive (ArduPilot's GCS_MAVLINK::handle_heartbeat:
        heartbeats of SYSID_MYGCS): heartbeats of any other system (a second GCS, a companion computer, an
        attacker) do not hold off the failsafe."""
        if m.get_srcSystem() != self._controller():
            return
        self.t_gcs = self.clock()
        if self.failsafe:
            self.failsafe = False
            self.event("GCS link restored; failsafe cleared (mode stays HOLD)")

    def _handle(self, m) -> None:
        kind = m.get_type()
        self._src_sysid = m.get_srcSystem()  # answers of the mission protocol go to their asker
        if kind == "HEARTBEAT":
            if m.type in _GCS_TYPES or m.get_srcSystem() not in (self.cfg_mav.system_id, self.cfg_mav.uuv_system_id):
                self._link_alive(m)
            return
        if kind in ("RADIO_STATUS", "TIMESYNC", "SYSTEM_TIME", "REQUEST_DATA_STREAM", "MISSION_ACK", "GCS_HEARTBEAT"):
            if kind == "TIMESYNC":
                self._on_timesync(m)
            elif kind == "REQUEST_DATA_STREAM" and self._for_us(m):
                self._on_request_data_stream(m)
            return
        if kind in _STICKS:
            ctl = self._controller()
            if ctl is not None and m.get_srcSystem() != ctl:
                self.counts["rx_ignored"] += 1  # ArduPilot: "Only accept control from our gcs"
                return
            self._link_alive(m)
        if kind in _ACTING:
            before = self._control_state()
            self._acked = None
            self._dispatch(m, kind)
            self._control_act(m, kind, before)
        else:
            self._dispatch(m, kind)

    def _dispatch(self, m, kind: str) -> None:
        if kind == "FILE_TRANSFER_PROTOCOL":
            if m.target_system in (0, self.cfg_mav.system_id):
                self._ftp_nak(m)
            return
        target = m.target if kind == "MANUAL_CONTROL" else getattr(m, "target_system", 0)
        if self.has_uuv and target == self.cfg_mav.uuv_system_id:
            self._handle_uuv(m, kind)  # system 2 (oceangnc.mavlink.uuv)
            return
        if not self._for_us(m):
            self.counts["rx_ignored"] += 1
            return
        if self.sub1 is not None and self._handle_sub(self.sub1, m, kind):
            return  # system 1 is a ROV: ArduSub's modes, sticks, targets and missions (oceangnc.mavlink.sub)
        h = getattr(self, "_on_" + kind.lower(), None)
        if h is None:
            self.counts["rx_ignored"] += 1
            return
        h(m)
