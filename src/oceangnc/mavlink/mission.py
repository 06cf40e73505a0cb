"""The mission store and the MAVLink mission protocol of :class:`oceangnc.mavlink.vehicle.MavlinkVehicle`."""

from __future__ import annotations

import math

from ..io.geo import latlon_to_ned, ned_to_latlon
from .protocol import AUTO, GUIDED, HOLD, mavlink

M = mavlink


#: parameters (1-4) that ArduPilot lets be NaN, per command (AP_Mission::sanity_check_params: "param 4 can be
#: nan" for NAV_WAYPOINT / NAV_LAND / NAV_TAKEOFF / NAV_VTOL_TAKEOFF, 3 and 4 for NAV_VTOL_LAND; none elsewhere)
NAN_PARAMS = {
    M.MAV_CMD_NAV_WAYPOINT: (4,),
    M.MAV_CMD_NAV_LAND: (4,),
    M.MAV_CMD_NAV_TAKEOFF: (4,),
    M.MAV_CMD_NAV_VTOL_TAKEOFF: (4,),
    M.MAV_CMD_NAV_VTOL_LAND: (3, 4),
}
#: commands whose x / y / z are a location (AP_Mission::stored_in_location): latitude, longitude and a finite
#: altitude below LOCATION_ALT_MAX_M are checked; other commands do not read them
LOCATION_CMDS = {
    M.MAV_CMD_NAV_WAYPOINT, M.MAV_CMD_NAV_LOITER_UNLIM, M.MAV_CMD_NAV_LOITER_TURNS, M.MAV_CMD_NAV_LOITER_TIME,
    M.MAV_CMD_NAV_LAND, M.MAV_CMD_NAV_TAKEOFF, M.MAV_CMD_NAV_CONTINUE_AND_CHANGE_ALT, M.MAV_CMD_NAV_LOITER_TO_ALT,
    M.MAV_CMD_NAV_SPLINE_WAYPOINT, M.MAV_CMD_NAV_GUIDED_ENABLE, M.MAV_CMD_DO_SET_HOME, M.MAV_CMD_DO_LAND_START,
    M.MAV_CMD_DO_SET_ROI, M.MAV_CMD_NAV_VTOL_TAKEOFF, M.MAV_CMD_NAV_VTOL_LAND, M.MAV_CMD_NAV_PAYLOAD_PLACE,
}  # fmt: skip
LOCATION_ALT_MAX_M = 83000.0  # AP_Common/Location.h


def _item_refusal(m, lat: float, lon: float) -> int | None:
    """The MAV_MISSION_RESULT ArduPilot answers a mission item with (AP_Mission::mavlink_int_to_mission_cmd:
    sanity_check_params, then the location of a command stored in one), or None if accepted. Item 0 (home)
    carries no checked location here."""
    errs = (M.MAV_MISSION_INVALID_PARAM1, M.MAV_MISSION_INVALID_PARAM2, M.MAV_MISSION_INVALID_PARAM3,
            M.MAV_MISSION_INVALID_PARAM4)  # fmt: skip
    nan_ok = NAN_PARAMS.get(m.command, ())
    for i, v in enumerate((m.param1, m.param2, m.param3, m.param4), 1):
        if math.isinf(v) or (math.isnan(v) and i not in nan_ok):
            return errs[i - 1]
    if m.command in LOCATION_CMDS and m.seq > 0:
        if not -90 <= lat <= 90:
            return M.MAV_MISSION_INVALID_PARAM5_X
        if not -180 <= lon <= 180:
            return M.MAV_MISSION_INVALID_PARAM6_Y
        if not abs(float(m.z)) < LOCATION_ALT_MAX_M:  # (NaN included)
            return M.MAV_MISSION_INVALID_PARAM7
    return None


class MissionMixin:
    """Mission items (item 0 is home), upload / download / clear / set-current, and following the mission
    through the scenario's :class:`oceangnc.mavlink.live.RouteHook`. The protocol code serves every system
    (system 1's Rover, and ArduSub's systems through :class:`oceangnc.mavlink.sub.SubAutopilot`, which
    brings its own store, mode numbers ``_AUTO`` / ``_GUIDED`` and mission following)."""

    _AUTO, _GUIDED = AUTO, GUIDED

    def _item(self, seq: int, n: float, e: float, command: int = M.MAV_CMD_NAV_WAYPOINT, alt: float = 0.0) -> dict:
        c = self.cfg_mav
        lat, lon = ned_to_latlon(n, e, c.origin_lat_deg, c.origin_lon_deg)
        return {
            "seq": seq,
            "frame": M.MAV_FRAME_GLOBAL_RELATIVE_ALT_INT if seq else M.MAV_FRAME_GLOBAL_INT,
            "command": command,
            "current": 0,
            "autocontinue": 1,
            "p1": 0.0,
            "p2": 0.0,
            "p3": 0.0,
            "p4": 0.0,
            "lat": lat,
            "lon": lon,
            "alt": alt,
        }

    def _set_initial_mission(self) -> None:
        pts = self.route.initial_route(self.cfg) if self.route.available else []
        self.mission = [self._item(0, 0.0, 0.0, alt=self.cfg_mav.origin_alt_m)]
        self.mission += [self._item(i + 1, n, e) for i, (n, e) in enumerate(pts)]
        self.mission_current = 1

    def _nav_points(self, start: int) -> tuple[list[tuple[float, float]], list[int]]:
        c = self.cfg_mav
        pts, seqs = [], []
        for it in self.mission[max(1, start) :]:
            if it["command"] == M.MAV_CMD_NAV_WAYPOINT:
                pts.append(latlon_to_ned(it["lat"], it["lon"], c.origin_lat_deg, c.origin_lon_deg))
                seqs.append(it["seq"])
        return pts, seqs

    def _start_mission(self) -> None:
        """Hand the mission from ``mission_current`` on to the guidance."""
        pts, seqs = self._nav_points(self.mission_current)
        self._route_seqs = seqs
        self._progress = 0
        if pts:
            self.route.set_route(pts)
            self._progress = self.route.progress(self.sim.bus) if self.route.kind == "pure_pursuit" else 0

    def _mission_ack(self, result: int, mission_type: int = 0, to: int | None = None) -> None:
        sysid = self._src_sysid if to is None else to  # the ground station whose message this answers
        self._send(self.mav.mission_ack_encode(sysid, 0, result, mission_type))

    def _on_mission_count(self, m) -> None:
        mt = getattr(m, "mission_type", 0)
        if mt != M.MAV_MISSION_TYPE_MISSION or not self.route.available:
            if mt == M.MAV_MISSION_TYPE_MISSION:
                self.event(f"Mission refused: {self.scenario.name} flies its own route", M.MAV_SEVERITY_WARNING)
            self._mission_ack(M.MAV_MISSION_UNSUPPORTED, mt)
            return
        if m.count > self.cfg_mav.max_mission_items:
            self._oor(f"MISSION_COUNT {m.count}")
            self._mission_ack(M.MAV_MISSION_NO_SPACE)
            return
        if m.count == 0:
            self.mission = self.mission[:1]
            self._mission_ack(M.MAV_MISSION_ACCEPTED)
            self.event("Mission cleared")
            return
        self._upload = {
            "count": int(m.count),
            "items": [],
            "t": self.clock(),
            "tries": 0,
            "sys": m.get_srcSystem(),
            "comp": m.get_srcComponent(),
        }
        self._request_item()

    def _request_item(self) -> None:
        u = self._upload
        if u is None:
            return
        seq = len(u["items"])
        self._send(self.mav.mission_request_int_encode(u["sys"], u["comp"], seq, 0))

    def _on_mission_item_int(self, m, scale: float = 1e-7) -> None:
        if m.current == 2 and getattr(m, "mission_type", 0) == 0:  # a GUIDED destination, not a mission item
            ok = (
                self.mode == self._GUIDED
                and m.command == M.MAV_CMD_NAV_WAYPOINT
                and m.frame in (M.MAV_FRAME_GLOBAL, M.MAV_FRAME_GLOBAL_INT, M.MAV_FRAME_GLOBAL_RELATIVE_ALT,
                                M.MAV_FRAME_GLOBAL_RELATIVE_ALT_INT)
                and self._guided_goto(m.x * scale, m.y * scale, "MISSION_ITEM current=2", change_mode=False)
                == M.MAV_RESULT_ACCEPTED
            )  # fmt: skip
            self._mission_ack(M.MAV_MISSION_ACCEPTED if ok else M.MAV_MISSION_ERROR)
            return
        u = self._upload
        if u is None or getattr(m, "mission_type", 0) != 0:
            self.counts["rx_ignored"] += 1
            return
        seq = len(u["items"])
        if m.seq != seq:
            self._request_item()  # ask again for the one we need
            return
        lat, lon = m.x * scale, m.y * scale
        err = _item_refusal(m, lat, lon)
        if err is not None:  # refused with its answer (AP_Mission's), and no part of the upload is kept
            self._oor(f"MISSION_ITEM seq {m.seq} command {m.command}: {M.enums['MAV_MISSION_RESULT'][err].name}")
            self._upload = None
            if self.mode != self._AUTO and len(self.mission) > 1:
                self.mission = self.mission[:1]  # AUTO must not fly the previous mission as if it were this one
                self.mission_current = 1
                self.event("Mission upload refused: mission cleared", M.MAV_SEVERITY_WARNING)
            self._mission_ack(err)  # (last: the client that reads it finds the mission cleared)
            return
        u["items"].append(
            {
                "seq": m.seq,
                "frame": m.frame,
                "command": m.command,
                "current": m.current,
                "autocontinue": m.autocontinue,
                "p1": m.param1,
                "p2": m.param2,
                "p3": m.param3,
                "p4": m.param4,
                "lat": lat,
                "lon": lon,
                "alt": float(m.z),
            }
        )
        u["t"] = self.clock()
        u["tries"] = 0
        if len(u["items"]) < u["count"]:
            self._request_item()
            return
        self.mission = u["items"]
        self._upload = None
        self.mission_current = 1
        self._mission_ack(M.MAV_MISSION_ACCEPTED)
        n_nav = len(self._nav_points(1)[0])
        self.event(f"Mission: {len(self.mission)} items, {n_nav} waypoints")
        if self.mode == self._AUTO:
            self._start_mission()

    def _on_mission_item(self, m) -> None:
        self._on_mission_item_int(m, scale=1.0)

    def _on_mission_request_list(self, m) -> None:
        if getattr(m, "mission_type", 0) != 0:
            self._send(self.mav.mission_count_encode(m.get_srcSystem(), m.get_srcComponent(), 0, m.mission_type))
            return
        self._send(self.mav.mission_count_encode(m.get_srcSystem(), m.get_srcComponent(), len(self.mission), 0))

    def _send_item(self, m, as_int: bool) -> None:
        if getattr(m, "mission_type", 0) != 0 or not (0 <= m.seq < len(self.mission)):
            self._oor(f"mission request seq {m.seq}")
            self._mission_ack(M.MAV_MISSION_INVALID_SEQUENCE)
            return
        it = self.mission[m.seq]
        cur = 1 if it["seq"] == self.mission_current else 0
        args = (
            m.get_srcSystem(),
            m.get_srcComponent(),
            it["seq"],
            it["frame"],
            it["command"],
            cur,
            it["autocontinue"],
            it["p1"],
            it["p2"],
            it["p3"],
            it["p4"],
        )
        if as_int:
            self._send(
                self.mav.mission_item_int_encode(*args, round(it["lat"] * 1e7), round(it["lon"] * 1e7), it["alt"], 0)
            )
        else:
            self._send(self.mav.mission_item_encode(*args, it["lat"], it["lon"], it["alt"], 0))

    def _on_mission_request_int(self, m) -> None:
        self._send_item(m, True)

    def _on_mission_request(self, m) -> None:
        self._send_item(m, False)

    def _on_mission_clear_all(self, m) -> None:
        self.mission = self.mission[:1]
        self.mission_current = 1
        self._mission_ack(M.MAV_MISSION_ACCEPTED)
        self.event("Mission cleared")

    def _set_current(self, seq: int) -> int:
        if not (1 <= seq < len(self.mission)):
            self._oor(f"mission current {seq}")
            return M.MAV_RESULT_DENIED
        self.mission_current = seq
        if self.mode == self._AUTO:
            self._start_mission()
        self._send_mission_current()  # with total, mission_state, mission_mode
        return M.MAV_RESULT_ACCEPTED

    def _on_mission_set_current(self, m) -> None:
        self._set_current(int(m.seq))

    def _upload_watchdog(self, now: float) -> None:
        u = self._upload
        if u is None or now - u["t"] < 1.0:
            return
        u["tries"] += 1
        u["t"] = now
        if u["tries"] * 1.0 > self.cfg_mav.mission_timeout_s:
            self._upload = None
            self._mission_ack(M.MAV_MISSION_OPERATION_CANCELLED, to=u["sys"])
            self.event("Mission upload timed out", M.MAV_SEVERITY_WARNING)
        else:
            self._request_item()

    def _follow_mission(self) -> None:
        if self.mode != AUTO or not self._route_seqs:
            return
        k = min(self.route.progress(self.sim.bus), len(self._route_seqs))
        while self._progress < k:
            seq = self._route_seqs[self._progress]
            self._progress += 1
            self.reached.append(seq)
            self._send(self.mav.mission_item_reached_encode(seq))
            self.event(f"Reached waypoint #{seq}")
            self.mission_current = self._route_seqs[self._progress] if self._progress < len(self._route_seqs) else seq
            self._send_mission_current()  # MAVLink 2's extensions in every one (issue 39)
        if self._progress >= len(self._route_seqs):
            self._route_seqs = []
            self._switch_mode(HOLD)
            self.mission_current = len(self.mission)  # past the end: AUTO restarts from item 1
            self.event("Mission complete, changing mode to Hold")
