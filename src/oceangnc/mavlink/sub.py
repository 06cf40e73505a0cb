"""ArduSub's modes, sticks, GUIDED targets and missions for one MAVLink system: the towed UUV (system 2 of the
combined scenarios) and a ROV of a vehicle file (system 1 of ``rov-station-keeping``), one implementation.

The front end only keeps the ground station's choices and writes them on the bus each loop pass; the
modes themselves are flown by compiled laws (:mod:`oceangnc.control.ardusub`: ``SubROV`` for a ROV,
``SubDepth`` + the winch for the towed UUV):

* **modes** (ArduSub's numbers, :data:`oceangnc.control.ardusub.FLOWN`): MANUAL 19 (ArduSub's boot mode),
  STABILIZE 0, ACRO 1, ALT_HOLD 2, POSHOLD 16, GUIDED 4, AUTO 3, SURFACE 9 by SET_MODE or
  MAV_CMD_DO_SET_MODE; CIRCLE and the others are DENIED with a STATUSTEXT. AUTO needs a mission waypoint.
* **MANUAL_CONTROL** for this system: x forward, y to starboard, r yaw in -1000..1000, z 0..1000 with
  500 neutral (ArduSub's throttle: above 500 up), INT16_MAX an unused axis (neutral); written as
  ``<body>.stick_x/y/z/r`` in [-1, 1] in the pilot's modes, neutral in GUIDED and AUTO. A stick stream that
  stops for FS_PILOT_TIMEOUT (3 s, range 0.1-3 s as ArduSub's) is taken as neutral sticks with a warning
  (ArduSub's pilot-input failsafe with FS_PILOT_INPUT = 1, warn only; disarming is not offered).
* **RC_CHANNELS_OVERRIDE** for this system (MAVProxy's ``rc 5 1700``, pymavlink's ArduSub example) with
  ArduSub's default input map: channel 5 forward, 6 lateral, 3 throttle (up above 1500), 4 yaw, PWM 1100..1900
  about 1500 to [-1, 1] (:data:`RC_STICK`); in the pilot's modes they set the same sticks as MANUAL_CONTROL.
  A channel at UINT16_MAX keeps its value, 0 releases it to the radio, which a simulated vehicle has not:
  neutral (MAVProxy sends 0 on every channel it does not override). Channels 1 (pitch) and 2 (roll) are not
  flown: SubROV holds roll and pitch level in STABILIZE and gives no roll or pitch moment in MANUAL.
* **GUIDED targets**: SET_POSITION_TARGET_GLOBAL_INT (lat/lon and alt; in a relative-altitude frame the
  depth is -alt, in an AMSL frame origin altitude - alt) and SET_POSITION_TARGET_LOCAL_NED (x, y, z about
  the origin, z the depth), each axis unless its type_mask bit says ignored; DO_REPOSITION (lat/lon,
  param7 alt, NaN keeps the depth) enters GUIDED. A towed body (``horizontal = False``) takes the depth
  only: its horizontal place is its station behind the USV.
* **missions**: the USV's mission protocol (:class:`oceangnc.mavlink.mission.MissionMixin`), the same code
  on this system's own store. In AUTO the items' MAV_CMD_NAV_WAYPOINTs are flown in order: the GUIDED
  target is the item's (north, east, depth = -alt); an item is reached when the body is within
  WPNAV_RADIUS of it horizontally or has passed it (along the leg from the previous item), and within
  :data:`DEPTH_ACCEPT_M` of its depth; MISSION_ITEM_REACHED and MISSION_CURRENT are sent by this system.
  After the last item the vehicle holds (POSHOLD). **A towed UUV** cannot leave the cable's reach of the
  USV: its mission is a depth profile over positions along the tow - it holds each item's depth until the
  tow has brought it to (or past) the item, while the USV flies its own route (system 1's mission, GUIDED
  or the stick).
"""

from __future__ import annotations

import math

from ..control.ardusub import ACRO, ALT_HOLD, AUTO, FLOWN, GUIDED, MANUAL, POSHOLD, STABILIZE, SURFACE
from ..io.geo import latlon_to_ned
from .mission import MissionMixin
from .protocol import mavlink

M = mavlink
#: ArduSub's mode names (ArduSub/mode.h)
SUB_MODES = {0: "STABILIZE", 1: "ACRO", 2: "ALT_HOLD", 3: "AUTO", 4: "GUIDED", 7: "CIRCLE", 9: "SURFACE",
             16: "POSHOLD", 19: "MANUAL"}  # fmt: skip
#: modes in which the pilot's sticks reach the vehicle
PILOT_MODES = (MANUAL, STABILIZE, ACRO, ALT_HOLD, POSHOLD, SURFACE)
#: depth tolerance of a mission item, m (ours: ArduSub has no separate one)
DEPTH_ACCEPT_M = 0.5
INT16_MAX = 32767
#: ArduSub's default RC input map (RCMAP_FORWARD 5, RCMAP_LATERAL 6, RCMAP_THROTTLE 3, RCMAP_YAW 4):
#: channel -> index of the stick [x forward, y lateral, z up, r yaw]
RC_STICK = {5: 0, 6: 1, 3: 2, 4: 3}
#: ArduSub's RC range about its trim (RCn_MIN 1100, RCn_TRIM 1500, RCn_MAX 1900), and the PWM accepted
RC_TRIM, RC_HALF_RANGE, RC_ACCEPT = 1500, 400.0, (800, 2200)
_RELATIVE = (M.MAV_FRAME_GLOBAL_RELATIVE_ALT, M.MAV_FRAME_GLOBAL_RELATIVE_ALT_INT)
_GLOBAL = (M.MAV_FRAME_GLOBAL, M.MAV_FRAME_GLOBAL_INT, *_RELATIVE)


def sub_mode_name(num: int) -> str:
    return SUB_MODES.get(num, f"mode {num}")


class SubAutopilot(MissionMixin):
    """ArduSub's state of one system (module docstring); everything else (arming, parameters, the clock,
    counters) is the vehicle's (attributes not found here are read from it)."""

    _AUTO, _GUIDED = AUTO, GUIDED

    def __init__(self, vehicle, sysid: int, body: str, mav, horizontal: bool):
        self.v = vehicle
        self.sysid = sysid
        self.body = body
        self.mav = mav
        self.horizontal = horizontal
        self.mode = MANUAL  # ArduSub boots in MANUAL
        self.stick = [0.0, 0.0, 0.0, 0.0]
        self.t_stick = -math.inf
        self.stick_flowing = False
        self.pilot_timeout_s = 3.0  # FS_PILOT_TIMEOUT
        self.fs_gcs_enable = 2  # FS_GCS_ENABLE (ArduSub's default: disarm)
        self.failsafe = False
        self.wp_radius_m = 2.0  # WPNAV_RADIUS 200 cm
        self.target = [math.nan, math.nan, math.nan]
        self.mission: list[dict] = []
        self.mission_current = 1
        self._upload: dict | None = None
        self._route_seqs: list[int] = []
        self._legs: list[tuple[float, float, float]] = []
        self._progress = 0
        self.reached: list[int] = []
        self.mission = [self._item(0, 0.0, 0.0, alt=vehicle.cfg_mav.origin_alt_m)]

    def __getattr__(self, name):
        if name == "v":
            raise AttributeError(name)
        return getattr(self.v, name)

    # -- the vehicle's services on this system -----------------------------------------------------------
    @property
    def route(self):
        return self  # MissionMixin asks route.available: a sub flies its missions itself

    #: whether the scenario has this system's laws (False: it answers, but refuses modes and missions)
    available = True

    def _send(self, msg, uuv: bool = False) -> None:
        self.mav.send(msg)

    def event(self, text: str, severity: int = M.MAV_SEVERITY_INFO) -> None:
        name = "ROV" if self.horizontal else "UUV"
        self.v.events.append((float(self.v.sim.t), f"{name} {text}"))
        if self.v.verbose:
            print(f"[t={self.v.sim.t:8.2f}] {name} {text}", flush=True)
        self.mav.send(self.mav.statustext_encode(severity, text[:50].encode()))

    def _ack(self, command: int, result: int) -> None:
        self.v._acked = (command, result)
        self.mav.send(self.mav.command_ack_encode(command, result))

    def position(self) -> tuple[float, float, float]:
        b = self.v.sim.bus
        return tuple(float(b.get(f"{self.body}.{k}", 0.0)) for k in "xyz")  # type: ignore[return-value]

    # -- modes -------------------------------------------------------------------------------------------
    def set_mode(self, num: int, via: str) -> int:
        if not self.available and num != self.mode:
            self.event(f"{sub_mode_name(num)} refused: {self.v.scenario.name} has no depth law for it",
                       M.MAV_SEVERITY_WARNING)  # fmt: skip
            return M.MAV_RESULT_DENIED
        if num not in FLOWN:
            self.event(f"{sub_mode_name(num)} refused: not flown", M.MAV_SEVERITY_WARNING)
            self.v._oor(f"{via} sub mode {num}")
            return M.MAV_RESULT_DENIED
        if num == AUTO and num != self.mode:
            start = self.mission_current if self.mission_current < len(self.mission) else 1
            if not self._nav_points(start)[0]:
                self.event("AUTO refused: no waypoint in the mission", M.MAV_SEVERITY_WARNING)
                return M.MAV_RESULT_DENIED
        if num != self.mode:
            self._switch_mode(num)
            if num == AUTO:
                if self.mission_current >= len(self.mission):
                    self.mission_current = 1
                self._start_mission()
            self.event(f"Mode {sub_mode_name(num)}")
        return M.MAV_RESULT_ACCEPTED

    def _switch_mode(self, num: int) -> None:
        self.mode = num
        self.stick = [0.0, 0.0, 0.0, 0.0]
        self.stick_flowing = False
        self.target = [math.nan, math.nan, math.nan]
        self._route_seqs = []

    # -- sticks -----------------------------------------------------------------------------------------
    def manual_control(self, m) -> None:
        axes = [0 if a == INT16_MAX else a for a in (m.x, m.y, m.r)]
        z = 500 if m.z == INT16_MAX else m.z
        if any(abs(a) > 1000 for a in axes) or not (0 <= z <= 1000):
            self.v._oor(f"MANUAL_CONTROL to {self.sysid}: x={m.x} y={m.y} z={m.z} r={m.r}")
            return
        if self.mode in PILOT_MODES:
            x, y, r = (a / 1000.0 for a in axes)
            self.stick = [x, y, (z - 500) / 500.0, r]
            self.t_stick = self.v.clock()
            self.stick_flowing = True

    def rc_override(self, m) -> None:
        """RC_CHANNELS_OVERRIDE to this system: channels 5, 6, 3, 4 (ArduSub's map, :data:`RC_STICK`) set the
        sticks in the pilot's modes; UINT16_MAX keeps a channel, 0 (released, no radio) is neutral."""
        pwm = {ch: getattr(m, f"chan{ch}_raw") for ch in RC_STICK}
        if any(v not in (0, 65535) and not (RC_ACCEPT[0] <= v <= RC_ACCEPT[1]) for v in pwm.values()):
            self.v._oor(f"RC_CHANNELS_OVERRIDE to {self.sysid}: " + " ".join(f"ch{c}={v}" for c, v in pwm.items()))
            return
        if self.mode not in PILOT_MODES:
            return
        for ch, v in pwm.items():
            if v != 65535:
                self.stick[RC_STICK[ch]] = 0.0 if v == 0 else max(-1.0, min(1.0, (v - RC_TRIM) / RC_HALF_RANGE))
        self.t_stick = self.v.clock()
        self.stick_flowing = True

    def watchdog(self, now: float, gcs: bool = False) -> None:
        """ArduSub's pilot-input failsafe: a stick stream that stopped for FS_PILOT_TIMEOUT: sticks neutral.
        With ``gcs`` (a ROV as system 1) also ArduSub's GCS failsafe: armed, the controlling ground station
        heard and then silent for FS_GCS_TIMEOUT: FS_GCS_ENABLE 1 warns, 2 disarms, 3 ALT_HOLD, 4 SURFACE,
        once, until the link is back."""
        if self.stick_flowing and now - self.t_stick > self.pilot_timeout_s:
            self.stick_flowing = False
            self.stick = [0.0, 0.0, 0.0, 0.0]
            self.event("Failsafe: pilot input lost, sticks neutral", M.MAV_SEVERITY_CRITICAL)
        if not gcs:
            return
        v = self.v
        silent = math.isfinite(v.t_gcs) and now - v.t_gcs > v.cfg_mav.gcs_timeout_s
        if not silent:
            self.failsafe = False
            return
        if self.failsafe or not v.armed or self.fs_gcs_enable == 0:
            return
        self.failsafe = True
        action = {1: "warning only", 2: "disarming", 3: "ALT_HOLD", 4: "SURFACE"}[int(self.fs_gcs_enable)]
        self.event(f"Failsafe: GCS link lost, {action}", M.MAV_SEVERITY_CRITICAL)
        if self.fs_gcs_enable == 2:
            v._arm(False)
        elif self.fs_gcs_enable in (3, 4):
            self.set_mode(ALT_HOLD if self.fs_gcs_enable == 3 else SURFACE, "GCS failsafe")

    # -- GUIDED targets ---------------------------------------------------------------------------------
    def _set_target(self, n: float | None, e: float | None, depth: float | None, via: str) -> int:
        vals = [v for v in (n, e, depth) if v is not None]
        if not all(math.isfinite(v) for v in vals) or (depth is not None and depth < -1.0):
            self.v._oor(f"{via} target {n} {e} {depth}")
            return M.MAV_RESULT_DENIED
        if self.horizontal and n is not None and e is not None:
            self.target[0], self.target[1] = float(n), float(e)
        if depth is not None:
            self.target[2] = max(0.0, float(depth))
        where = f"{n:.1f} m N, {e:.1f} m E, " if self.horizontal and n is not None and e is not None else ""
        self.event(f"Guided to {where}depth {self.target[2]:.2f} m ({via})")
        return M.MAV_RESULT_ACCEPTED

    def _depth_of_alt(self, alt: float, frame: int) -> float:
        return -alt if frame in _RELATIVE else self.v.cfg_mav.origin_alt_m - alt

    def set_position_target_global_int(self, m) -> None:
        if self.mode != GUIDED or m.coordinate_frame not in _GLOBAL:
            self.v.counts["rx_ignored"] += 1
            return
        c = self.v.cfg_mav
        mask = m.type_mask
        n = e = depth = None
        if not mask & (M.POSITION_TARGET_TYPEMASK_X_IGNORE | M.POSITION_TARGET_TYPEMASK_Y_IGNORE):
            n, e = latlon_to_ned(m.lat_int * 1e-7, m.lon_int * 1e-7, c.origin_lat_deg, c.origin_lon_deg)
        if not mask & M.POSITION_TARGET_TYPEMASK_Z_IGNORE:
            depth = self._depth_of_alt(float(m.alt), m.coordinate_frame)
        if n is None and depth is None:
            self.v.counts["rx_ignored"] += 1
            return
        if self._same_target(n, e, depth):
            return
        self._set_target(n, e, depth, "SET_POSITION_TARGET_GLOBAL_INT")

    def set_position_target_local_ned(self, m) -> None:
        if self.mode != GUIDED or m.coordinate_frame != M.MAV_FRAME_LOCAL_NED:
            self.v.counts["rx_ignored"] += 1
            return
        mask = m.type_mask
        n = e = depth = None
        if not mask & (M.POSITION_TARGET_TYPEMASK_X_IGNORE | M.POSITION_TARGET_TYPEMASK_Y_IGNORE):
            n, e = float(m.x), float(m.y)
        if not mask & M.POSITION_TARGET_TYPEMASK_Z_IGNORE:
            depth = float(m.z)
        if n is None and depth is None:
            self.v.counts["rx_ignored"] += 1
            return
        if self._same_target(n, e, depth):
            return
        self._set_target(n, e, depth, "SET_POSITION_TARGET_LOCAL_NED")

    def _same_target(self, n, e, depth) -> bool:
        """The same target streamed again (offboard-style clients send it at a rate): no event."""
        t = self.target
        same_z = depth is None or (math.isfinite(t[2]) and abs(t[2] - depth) < 1e-3)
        same_xy = n is None or not self.horizontal or (math.isfinite(t[0]) and abs(t[0] - n) + abs(t[1] - e) < 1e-3)
        return same_z and same_xy

    def reposition(self, lat: float, lon: float, alt: float) -> int:
        """MAV_CMD_DO_REPOSITION: GUIDED to lat/lon (param5/6) at alt (param7, relative; NaN keeps the depth)."""
        if not (-90 <= lat <= 90 and -180 <= lon <= 180):
            self.v._oor(f"DO_REPOSITION {lat} {lon}")
            return M.MAV_RESULT_DENIED
        res = self.set_mode(GUIDED, "DO_REPOSITION")
        if res != M.MAV_RESULT_ACCEPTED:
            return res
        c = self.v.cfg_mav
        n, e = latlon_to_ned(lat, lon, c.origin_lat_deg, c.origin_lon_deg)
        return self._set_target(n, e, None if math.isnan(alt) else -alt, "DO_REPOSITION")

    def _guided_goto(self, lat: float, lon: float, via: str, change_mode: bool = True) -> int:
        """A MISSION_ITEM with current = 2 (Mission Planner's Fly-to-here) in GUIDED."""
        c = self.v.cfg_mav
        n, e = latlon_to_ned(lat, lon, c.origin_lat_deg, c.origin_lon_deg)
        return self._set_target(n, e, None, via)

    # -- missions: the USV's protocol code on this store; following is the sub's own ---------------------
    def _start_mission(self) -> None:
        c = self.v.cfg_mav
        self._route_seqs, self._legs = [], []
        for it in self.mission[max(1, self.mission_current) :]:
            if it["command"] == M.MAV_CMD_NAV_WAYPOINT:
                n, e = latlon_to_ned(it["lat"], it["lon"], c.origin_lat_deg, c.origin_lon_deg)
                self._legs.append((n, e, max(0.0, self._depth_of_alt(it["alt"], it["frame"]))))
                self._route_seqs.append(it["seq"])
        self._progress = 0
        p = self.position()
        self._leg_start = (p[0], p[1])
        self._aim()

    def _aim(self) -> None:
        if self._progress < len(self._legs):
            n, e, d = self._legs[self._progress]
            self.target = [n if self.horizontal else math.nan, e if self.horizontal else math.nan, d]

    def _follow_mission(self) -> None:
        if self.mode != AUTO or not self._route_seqs:
            return
        x, y, z = self.position()
        while self._progress < len(self._legs):
            n, e, d = self._legs[self._progress]
            a = self._leg_start
            tn, te = n - a[0], e - a[1]
            past = (x - n) * tn + (y - e) * te > 0.0 and (tn or te)
            near = math.hypot(x - n, y - e) <= self.wp_radius_m
            if not ((near or past) and abs(z - d) <= DEPTH_ACCEPT_M):
                break
            seq = self._route_seqs[self._progress]
            self._progress += 1
            self._leg_start = (n, e)
            self.reached.append(seq)
            self.mav.send(self.mav.mission_item_reached_encode(seq))
            self.event(f"Reached waypoint #{seq}")
            last = self._progress >= len(self._legs)
            self.mission_current = seq if last else self._route_seqs[self._progress]
            self.send_mission_current()
            self._aim()
        if self._progress >= len(self._legs):
            self._switch_mode(POSHOLD)
            self.mission_current = len(self.mission)
            self.event("Mission complete, changing mode to POSHOLD")

    def send_mission_current(self) -> None:
        n = len(self.mission)
        seq = min(self.mission_current, max(0, n - 1))
        if n <= 1:
            total, state = 65535, M.MISSION_STATE_NO_MISSION
        elif self.mode == AUTO:
            total, state = n - 1, M.MISSION_STATE_ACTIVE
        elif self.mission_current >= n:
            total, state = n - 1, M.MISSION_STATE_COMPLETE
        else:
            total, state = n - 1, M.MISSION_STATE_PAUSED if self.reached else M.MISSION_STATE_NOT_STARTED
        self.mav.send(self.mav.mission_current_encode(seq, total, state, 1 if self.mode == AUTO else 2))

    _send_mission_current = send_mission_current  # (the name MissionMixin calls)

    # -- the bus and the heartbeat -----------------------------------------------------------------------
    def bus_values(self) -> dict:
        b = self.body
        stick = self.stick if self.mode in PILOT_MODES else [0.0, 0.0, 0.0, 0.0]
        t = self.target
        valid = (1 if math.isfinite(t[0]) else 0) | (2 if math.isfinite(t[2]) else 0)
        vals = {f"{b}.sub_mode": float(self.mode), f"{b}.sub_pilot": 1.0, f"{b}.stick_z": float(stick[2]),
                f"{b}.target_z": t[2] if valid & 2 else 0.0, f"{b}.target_valid": float(valid)}  # fmt: skip
        if self.horizontal:
            vals.update({f"{b}.stick_x": float(stick[0]), f"{b}.stick_y": float(stick[1]),
                         f"{b}.stick_r": float(stick[3]), f"{b}.target_n": t[0] if valid & 1 else 0.0,
                         f"{b}.target_e": t[1] if valid & 1 else 0.0})  # fmt: skip
        return vals

    def base_mode(self, armed: bool) -> int:
        base = M.MAV_MODE_FLAG_CUSTOM_MODE_ENABLED
        if armed:
            base |= M.MAV_MODE_FLAG_SAFETY_ARMED
        if self.mode in PILOT_MODES:
            base |= M.MAV_MODE_FLAG_MANUAL_INPUT_ENABLED
        if self.mode != MANUAL:
            base |= M.MAV_MODE_FLAG_STABILIZE_ENABLED
        if self.mode in (GUIDED, AUTO, POSHOLD):
            base |= M.MAV_MODE_FLAG_GUIDED_ENABLED
        if self.mode == AUTO:
            base |= M.MAV_MODE_FLAG_AUTO_ENABLED
        return base


__all__ = ["PILOT_MODES", "SUB_MODES", "SubAutopilot", "STABILIZE", "sub_mode_name"]
