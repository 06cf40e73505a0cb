"""Events and state messages of a console :class:`oceangnc.console.session.Session` (what the page shows)."""

from __future__ import annotations

import json
import math
import time

import numpy as np


def _finite(v):
    """``float(v)``, or None when it is not finite (JSON has no NaN)."""
    v = float(v)
    return v if math.isfinite(v) else None


class SnapshotMixin:
    """The event log, the hello message (scenario, view, gains) and the state message built from the bus."""

    def event(self, level: str, text: str, access: bool = False) -> None:
        """Record an event for the page's log (level info, warning, error, alarm) and append it to the
        run's ``events.jsonl``. ``access`` marks a summary of refused requests
        (:class:`~oceangnc.console.access.AccessLog`): it goes to its own short history
        (``access_events``), so traffic without the token can never push an operator's event out of
        ``events``."""
        with self._lock:
            self._event_id += 1
            t = float(self.sim.t) if self.sim is not None else 0.0
            e = {"id": self._event_id, "t": t, "level": level, "text": text, "wall": time.time()}
            if access:
                e["kind"] = "access"
            (self.access_events if access else self.events).append(e)
            if self._events_file is not None:
                try:
                    self._events_file.write(
                        json.dumps({"run": self.run_id, **e}, separators=(",", ":")),
                        sync=access or level == "alarm",
                    )
                except OSError as err:  # a full disk must not stop the console; say so once
                    self._events_file = None
                    self._event_id += 1
                    text = f"events.jsonl not written any more: {err}"
                    self.events.append(
                        {"id": self._event_id, "t": t, "level": "error", "text": text, "wall": e["wall"]}
                    )

    def events_since(self, last_id: int) -> list[dict]:
        """Events (both histories) with an id above ``last_id``, oldest first."""
        self.access.flush()  # a summary whose interval is over
        with self._lock:
            new = []
            for hist in (self.events, self.access_events):
                for e in reversed(hist):
                    if e["id"] <= last_id:
                        break
                    new.append(e)
        new.sort(key=lambda e: e["id"])
        return new

    def _make_hello(self) -> None:
        gains = {k: {kk: vv for kk, vv in v.items() if kk not in ("setter", "getter")} for k, v in self.gains.items()}
        self.hello = {
            "type": "hello",
            "run": self.run_id,
            "scenario": self.scenario.name,
            "summary": self.scenario.summary,
            "scenarios": self.live_scenarios(),
            "view": self.view,
            "gains": gains,
            "speed": self.speed,
            "stick_timeout": self.stick_timeout,
            "tick_s": self.tick_s,
            "log_dir": str(self.run_dir) if self.run_dir else None,
            "tracks": {k: [list(p) for p in v] for k, v in self.tracks.items()},
            "station_keep": self.station_keep,
            "loop_switch": bool(getattr(self.scenario, "console_loop_switch", False)),
            "route_edit": bool(getattr(self.scenario, "console_route_edit", False)),
        }

    def hello_message(self) -> dict:
        with self._lock:
            self.hello["tracks"] = {k: [list(p) for p in v] for k, v in self.tracks.items()}
            for k, g in self.hello["gains"].items():
                g["value"] = _finite(self.gains[k]["getter"]())
            return dict(self.hello)

    def _publish(self) -> None:
        """Build the state message from the bus (simulation thread, under the lock)."""
        sim = self.sim
        bus = sim.bus
        sig = {}
        for k, v in bus.items():
            if k.startswith("_") or isinstance(v, (str, bytes)):
                continue
            if isinstance(v, (bool, np.bool_)):
                sig[k] = bool(v)
            elif isinstance(v, (int, float, np.floating, np.integer)):
                sig[k] = _finite(v)
            elif isinstance(v, (list, tuple, np.ndarray)) and k.startswith("cable"):
                try:
                    sig[k] = [_finite(x) for x in np.asarray(v, float).ravel()[:400]]
                except (TypeError, ValueError):
                    pass
        if sim.t - self._track_t >= 0.25:
            self._track_t = sim.t
            for b, tr in self.tracks.items():
                x, y = bus.get(f"{b}.x"), bus.get(f"{b}.y")
                if x is not None and y is not None and math.isfinite(x) and math.isfinite(y):
                    tr.append((round(float(x), 3), round(float(y), 3)))
        now = self.clock()
        age = now - self.t_stick
        self.snapshot = {
            "type": "state",
            "run": self.run_id,
            "t": float(sim.t),
            "mode": self.mode,
            "loop": self.loop,
            "estop": self.estop,
            "failsafe": self.failsafe,
            "failsafe_reason": self.failsafe_reason,
            "paused": self.paused,
            "ended": self.ended,
            "error": self.error,
            "speed": self.speed,
            "rtf": self.rtf,
            "clients": self.clients,
            "operator": self.operator,
            "stick": {
                "surge": self.stick[0],
                "yaw": self.stick[1],
                "source": self.stick_source,
                "age": age if math.isfinite(age) else None,
            },
            "waypoints": [list(p) for p in bus.get("console.waypoints", ())] or None,
            "signals": sig,
            "last_event": self._event_id,
            "refused": self.access.total,  # requests refused since the start (token, origin, host, 429)
        }
        self.snapshot_json = json.dumps(self.snapshot, separators=(",", ":"))

    def state(self) -> dict:
        with self._lock:
            return json.loads(self.snapshot_json)
