"""Commands of a console :class:`oceangnc.console.session.Session`: queued by the web server's threads,
applied in the simulation thread; the failsafe watchdog and the console's bus keys."""

from __future__ import annotations

from ..guidance.route_pilot import send_route
from .messages import Rejected, check_gains

NEUTRAL = 0.05  #: stick deflection below which the stick counts as centred (failsafe reset)


class CommandsMixin:
    """``submit`` (semantic checks, queue), ``_apply`` (in the simulation thread), failsafe and bus keys."""

    def submit(self, msg) -> None:
        """Queue a validated message for the simulation thread; semantic checks raise Rejected."""
        kind = msg.type
        if kind == "gains":
            with self._lock:
                check_gains(msg.gains, self.gains)
        elif kind == "waypoints" and not getattr(self.scenario, "console_route_edit", False):
            raise Rejected(
                f"waypoints: scenario {self.scenario.name} flies a fixed route; "
                f"start a scenario that takes a route from the console (usv-remote)"
            )
        elif kind == "new_run" and msg.scenario is not None and msg.scenario not in self.live_scenarios():
            raise Rejected(
                f"new_run: unknown or non-live scenario {msg.scenario!r}; live scenarios: "
                f"{', '.join(self.live_scenarios())}"
            )
        if kind == "stick":  # timestamp on arrival, so the watchdog sees the link, not the queue
            with self._lock:
                self.t_stick = self.clock()
        self._cmds.append(msg)

    def _apply(self, msg) -> None:
        kind = msg.type
        if kind == "stick":
            self.stick = (float(msg.surge), float(msg.yaw))
            self.stick_source = msg.source
        elif kind == "mode":
            if msg.mode != self.mode:
                self.mode = msg.mode
                self.event("info", f"mode: {msg.mode}")
                if msg.mode == "remote":
                    self.t_stick = max(self.t_stick, self.clock())  # 1 s grace for the first stick message
                    self.stick = (0.0, 0.0)
                elif self.failsafe:
                    self._clear_failsafe("autonomous mode selected")
        elif kind == "loop":
            if msg.loop != self.loop:
                self.loop = msg.loop
                self.event(
                    "info",
                    f"stick drives the {'actuators (open loop)' if msg.loop == 'open' else 'speed and yaw-rate loops (closed loop)'}",
                )
        elif kind == "estop":
            if msg.engaged and not self.estop:
                self.estop = True
                self.event("alarm", "EMERGENCY STOP: all thrust zero (latched until reset)")
            elif not msg.engaged and self.estop:
                self.estop = False
                self.stick = (0.0, 0.0)
                self.event("info", "emergency stop reset")
        elif kind == "gains":
            for name, v in msg.gains.items():
                self.gains[name]["setter"](v)
                self.gains[name]["value"] = v
                self.event("info", f"gain {name} = {v:g} {self.gains[name].get('unit', '')}".rstrip())
        elif kind == "pause":
            if msg.paused != self.paused:
                self.paused = msg.paused
                self._anchor = (self.clock(), self.sim.t)
                self._rtf_ref = self._anchor
                self.event("info", "paused" if msg.paused else "resumed")
        elif kind == "waypoints":
            send_route(self.sim, msg.points)
            self.view["route"] = [[float(a), float(b)] for a, b in msg.points]
            self.event("info", f"new route of {len(msg.points)} waypoint(s)")

    def _trip_failsafe(self, reason: str) -> None:
        self.failsafe = True
        self.failsafe_reason = reason
        self.stick = (0.0, 0.0)
        what = "station-keeping" if self.station_keep else "thrust zero"
        self.event("alarm", f"FAILSAFE ({reason}): {what}")

    def _clear_failsafe(self, why: str) -> None:
        self.failsafe = False
        self.failsafe_reason = ""
        self.event("info", f"failsafe cleared: {why}")

    def _watchdog(self, now: float) -> None:
        if self.mode != "remote" or self.paused or self.ended:
            return
        if self.operator is None:
            reason = "operator link lost"
        elif now - self.t_stick > self.stick_timeout:
            reason = f"no stick input for {self.stick_timeout:g} s"
        else:
            reason = ""
        if reason and not self.failsafe:
            self._trip_failsafe(reason)
        elif not reason and self.failsafe:
            if abs(self.stick[0]) <= NEUTRAL and abs(self.stick[1]) <= NEUTRAL:
                self._clear_failsafe("link restored and stick centred")

    def _push_bus(self) -> None:
        """Write the console's keys; the stick only in remote mode (in auto a scenario's own pilot may
        write ``joystick.*``, as the scripted berthing pilot does)."""
        estop_bus = self.estop or (self.failsafe and not self.station_keep)
        vals = {
            "console.mode": self.mode,
            "console.loop": self.loop,
            "_estop": estop_bus,
            "console.failsafe": float(self.failsafe),
            "console.estop": float(self.estop),
        }
        if self.mode == "remote":
            surge, yaw = (0.0, 0.0) if (self.failsafe or self.estop) else self.stick
            vals["joystick.surge"] = surge
            vals["joystick.yaw"] = yaw
        self.sim.inject(vals)
