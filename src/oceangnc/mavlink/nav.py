"""ArduPilot Rover's navigation modes on :class:`oceangnc.mavlink.vehicle.MavlinkVehicle`: GUIDED, RTL,
SMART_RTL and LOITER, home, DO_CHANGE_SPEED, and the failsafe actions that use them.

Every mode flies with the guidance the scenario already has, through the same route hook as a mission
(:class:`oceangnc.mavlink.live.RouteHook`: the route pilot of ``usv-remote``, the pure pursuit of
``combined-survey``), by giving it a short route:

* **GUIDED** (Rover 15): a target from DO_REPOSITION, SET_POSITION_TARGET_GLOBAL_INT or a MISSION_ITEM_INT
  with ``current = 2`` (Mission Planner's "Fly to here") is a one-point route; entered without a target,
  or once the target is reached, the boat loiters there (ArduPilot: "boats loiter at the destination").
* **RTL** (11): a one-point route to home, then a loiter at home. Home is the first position fix, moved to
  where the vehicle arms, or set by MAV_CMD_DO_SET_HOME (then kept); mission item 0 and HOME_POSITION show it.
* **SMART_RTL** (12): the path flown since arming, kept as breadcrumbs every ``smart_rtl_accuracy_m``
  (ArduPilot's SRTL_ACCURACY, 2 m) with loops cut out (a new breadcrumb within the accuracy of an old one
  drops the points between them) and thinned by half when ``smart_rtl_points`` is reached, flown backwards
  to the arming point; then a loiter there. Refused before the first arming (no path yet).
* **LOITER** (5): station keeping within LOIT_RADIUS of the point where the mode was entered: inside the
  radius the boat holds (the scenario's HOLD: speed and yaw-rate setpoints zero), drifted outside it, a
  one-point route back to the centre with an acceptance radius of min(WP_RADIUS, LOIT_RADIUS / 2) (the
  pilots also take a waypoint passed abeam, so the boat does not circle it).

A leg is reached when the guidance reports its last point (not before it has run once on the new route).
DO_CHANGE_SPEED sets the speed of the current mode (as ArduPilot: until the next mode change, CRUISE_SPEED
unchanged); WP_RADIUS and CRUISE_SPEED stay what the operator set and are written into the pilot with
these temporary values over them.
"""

from __future__ import annotations

import math

from ..io.geo import latlon_to_ned, ned_to_latlon
from .protocol import AUTO, GUIDED, HOLD, LOITER, NAV_MODES, RTL, SMART_RTL, STICK_MODES, mavlink, mode_name

M = mavlink

#: a leg's arrival is read only after the guidance has run on the new route this long (simulated s)
_FRESH_S = 0.1
#: a GUIDED target closer than this to the current one is the same target re-sent, m (2e-7 deg ~ 2 cm)
_SAME_TARGET_M = 0.05


class NavMixin:
    """Home, breadcrumbs, the GUIDED target, loiter and the legs of the navigation modes."""

    # -- state ---------------------------------------------------------------------------------------
    def _nav_init(self) -> None:
        self.home: tuple[float, float] | None = None
        self.home_locked = False  # set by DO_SET_HOME: arming does not move it
        self.crumbs: list[tuple[float, float]] = []
        self.guided_target: tuple[float, float] | None = None
        self.loiter_center: tuple[float, float] | None = None
        self._leg: list[tuple[float, float]] | None = None  # route points of the active leg
        self._leg_t0 = 0.0
        self._leg_loiter = False
        self._overrides: dict[str, float] = {}  # DO_CHANGE_SPEED / loiter radius over the operator's values
        self._update_home_from_fix()

    def _position(self) -> tuple[float, float] | None:
        """Where the guidance thinks the vehicle is (the GPS fix, the truth without a GPS); None in an outage."""
        b = self.sim.bus
        if "gps.x" in b:
            if float(b.get("gps.valid", 1.0)) <= 0.5:
                return None
            return float(b["gps.x"]), float(b["gps.y"])
        return float(b.get(f"{self.body}.x", 0.0)), float(b.get(f"{self.body}.y", 0.0))

    # -- home ----------------------------------------------------------------------------------------
    def _update_home_from_fix(self) -> None:
        if self.home is None:
            p = self._position()
            if p is not None:
                self._set_home(p, locked=False)

    def _set_home(self, p: tuple[float, float], locked: bool) -> None:
        self.home = (float(p[0]), float(p[1]))
        self.home_locked = self.home_locked or locked
        if self.mission:
            c = self.cfg_mav
            self.mission[0]["lat"], self.mission[0]["lon"] = ned_to_latlon(
                *self.home, c.origin_lat_deg, c.origin_lon_deg
            )
        if hasattr(self, "mav"):
            self._send_home()

    def _home_latlon(self) -> tuple[float, float]:
        c = self.cfg_mav
        n, e = self.home if self.home is not None else (0.0, 0.0)
        return ned_to_latlon(n, e, c.origin_lat_deg, c.origin_lon_deg)

    def _do_set_home(self, current: bool, lat: float, lon: float) -> int:
        if current:
            p = self._position()
            if p is None:
                return M.MAV_RESULT_FAILED
        else:
            if not (-90 <= lat <= 90 and -180 <= lon <= 180) or (lat == 0 and lon == 0):
                self._oor(f"DO_SET_HOME {lat} {lon}")
                return M.MAV_RESULT_DENIED
            c = self.cfg_mav
            p = latlon_to_ned(lat, lon, c.origin_lat_deg, c.origin_lon_deg)
        self._set_home(p, locked=True)
        self.event(f"Home set: {p[0]:.1f} m N, {p[1]:.1f} m E")
        return M.MAV_RESULT_ACCEPTED

    def _on_armed(self) -> None:
        """Arming: home moves to here (unless DO_SET_HOME set it) and the SMART_RTL path starts here."""
        p = self._position()
        if p is None:
            return
        if not self.home_locked:
            self._set_home(p, locked=False)
        self.crumbs = [p]

    # -- breadcrumbs (SMART_RTL) ------------------------------------------------------------------------
    def _breadcrumb(self, p: tuple[float, float]) -> None:
        c = self.cfg_mav
        acc = c.smart_rtl_accuracy_m
        cr = self.crumbs
        if not cr:
            cr.append(p)
            return
        if math.hypot(p[0] - cr[-1][0], p[1] - cr[-1][1]) < acc:
            return
        for j in range(len(cr) - 2):  # back within the accuracy of an older point: cut the loop out
            if math.hypot(p[0] - cr[j][0], p[1] - cr[j][1]) < acc:
                del cr[j + 1 :]
                return
        cr.append(p)
        if len(cr) > c.smart_rtl_points:
            self.crumbs = [cr[0], *cr[1:-1][1::2], cr[-1]]

    def _smart_rtl_route(self) -> list[tuple[float, float]]:
        return list(reversed(self.crumbs))

    # -- overrides of the operator's parameters ----------------------------------------------------------
    def _apply_overrides(self) -> None:
        """Write CRUISE_SPEED and WP_RADIUS into the guidance: the operator's values, or the temporary ones
        (DO_CHANGE_SPEED in this mode, the loiter leg's acceptance radius) over them."""
        for name, raw in self._raw.items():
            raw[1](self._overrides.get(name, self._user[name]))

    def _set_override(self, name: str, value: float | None) -> None:
        if name not in self._raw:
            return
        if value is None:
            self._overrides.pop(name, None)
        else:
            self._overrides[name] = float(value)
        self._apply_overrides()

    def _do_change_speed(self, speed: float) -> int:
        if speed == -1.0 or speed == -2.0:  # "no change" (MAVLink: -1; -2 "return to default" since 2023)
            if speed == -2.0:
                self._set_override("CRUISE_SPEED", None)
            return M.MAV_RESULT_ACCEPTED
        p = self.params.get("CRUISE_SPEED")
        if p is None:
            return M.MAV_RESULT_UNSUPPORTED
        if not (0.0 < speed <= p.hi):
            self._oor(f"DO_CHANGE_SPEED {speed} m/s (0..{p.hi:g})")
            return M.MAV_RESULT_DENIED
        self._set_override("CRUISE_SPEED", speed)
        self.event(f"Speed {speed:.2f} m/s ({mode_name(self.mode)})")
        return M.MAV_RESULT_ACCEPTED

    # -- legs -----------------------------------------------------------------------------------------
    def _start_leg(self, points, loiter: bool = False) -> None:
        pts = [(float(a), float(b)) for a, b in points]
        self._leg = pts
        self._leg_t0 = float(self.sim.t)
        self._leg_loiter = loiter
        r = self._user.get("WP_RADIUS")
        if loiter and r is not None:
            self._set_override("WP_RADIUS", min(r, 0.5 * self.cfg_mav.loiter_radius_m))
        else:
            self._set_override("WP_RADIUS", None)
        self.route.set_route(pts)

    def _leg_reached(self) -> bool:
        if self._leg is None or self.sim.t < self._leg_t0 + _FRESH_S:
            return False
        return self.route.progress(self.sim.bus) >= len(self._leg)

    def _loiter_at(self, p: tuple[float, float] | None) -> None:
        """Station keeping at ``p`` (here when None or unknown)."""
        self._leg = None
        self._set_override("WP_RADIUS", None)
        self.loiter_center = p if p is not None else self._position()

    def route_active(self) -> bool:
        """Whether the scenario's guidance is flying a route now (``console.mode`` = "auto")."""
        if self.mode == AUTO:
            return True
        return self.mode in NAV_MODES and self._leg is not None

    # -- entering a mode ---------------------------------------------------------------------------------
    def _nav_refusal(self, num: int) -> str | None:
        """Why mode ``num`` (a navigation mode) cannot be entered now, or None."""
        if not self.route.available:
            return f"{self.scenario.name} flies its own route"
        if num == RTL and self.home is None:
            return "no home yet"
        if num == SMART_RTL and len(self.crumbs) < 1:
            return "no path recorded (arm first)"
        if num in (GUIDED, LOITER) and self._position() is None:
            return "no position fix"
        return None

    def _enter_nav(self, num: int) -> None:
        self.guided_target = None
        if num == GUIDED or num == LOITER:
            self._loiter_at(None)
        elif num == RTL:
            self.loiter_center = self.home
            self._start_leg([self.home])
        elif num == SMART_RTL:
            self.loiter_center = self.crumbs[0]
            self._start_leg(self._smart_rtl_route())

    def _leave_nav(self) -> None:
        self._leg = None
        self.loiter_center = None
        self.guided_target = None

    # -- GUIDED targets -----------------------------------------------------------------------------------
    def _guided_goto(self, lat: float, lon: float, via: str, change_mode: bool = True) -> int:
        if not (-90 <= lat <= 90 and -180 <= lon <= 180) or (lat == 0 and lon == 0):
            self._oor(f"{via} target {lat} {lon}")
            return M.MAV_RESULT_DENIED
        if self.mode != GUIDED:
            if not change_mode:
                return M.MAV_RESULT_DENIED
            res = self._set_mode(GUIDED, via)
            if res != M.MAV_RESULT_ACCEPTED:
                return res
        c = self.cfg_mav
        p = latlon_to_ned(lat, lon, c.origin_lat_deg, c.origin_lon_deg)
        t = self.guided_target
        if t is not None and math.hypot(p[0] - t[0], p[1] - t[1]) < _SAME_TARGET_M:
            return M.MAV_RESULT_ACCEPTED  # the same target again (streamed by offboard clients): the leg goes on
        self.guided_target = p
        self.loiter_center = p
        self._start_leg([p])
        self.event(f"Guided to {p[0]:.1f} m N, {p[1]:.1f} m E ({via})")
        return M.MAV_RESULT_ACCEPTED

    # -- every loop pass -----------------------------------------------------------------------------------
    def _nav_step(self) -> None:
        self._update_home_from_fix()
        p = self._position()
        if self.armed and p is not None and self.mode not in (RTL, SMART_RTL):  # ArduPilot: not while returning
            self._breadcrumb(p)
        if self.mode not in NAV_MODES:
            return
        if self._leg is not None:
            if self._leg_reached():
                if not self._leg_loiter:
                    what = {GUIDED: "Reached destination", RTL: "Reached home", SMART_RTL: "Reached home"}
                    self.event(f"{what.get(self.mode, 'Reached')} ({mode_name(self.mode)}), loitering")
                self._loiter_at(self.loiter_center)
            return
        c = self.loiter_center
        if c is None or p is None:
            return
        if math.hypot(p[0] - c[0], p[1] - c[1]) > self.cfg_mav.loiter_radius_m:
            self._start_leg([c], loiter=True)

    # -- failsafe actions ------------------------------------------------------------------------------------
    def _failsafe_action(self, why: str) -> None:
        """FS_ACTION: 1 RTL, 2 HOLD, 3 SMART_RTL else RTL, 4 SMART_RTL else HOLD (ArduPilot Rover); a mode that
        cannot be entered falls back as ArduPilot does (to RTL, then HOLD)."""
        a = self.cfg_mav.fs_action
        chain = {1: (RTL, HOLD), 2: (HOLD,), 3: (SMART_RTL, RTL, HOLD), 4: (SMART_RTL, HOLD)}[int(a)]
        for num in chain:
            if num == HOLD or (self.armed and self._nav_refusal(num) is None):
                self._switch_mode(num)
                self.event(f"Failsafe: {why}, {mode_name(num)}", M.MAV_SEVERITY_CRITICAL)
                return

    def _switch_mode(self, num: int) -> None:
        """Change mode with no checks beyond the navigation state (the failsafe's path)."""
        was = self.mode
        if num != was:
            if was in NAV_MODES:
                self._leave_nav()
            self._overrides.clear()  # DO_CHANGE_SPEED lasts until the mode changes (ArduPilot)
            self._apply_overrides()
        self.mode = num
        self.stick = (0.0, 0.0)
        self.stick_flowing = False
        if num in NAV_MODES and num != was:
            self._enter_nav(num)
        if num in STICK_MODES:
            self.t_gcs = max(self.t_gcs, self.clock())
