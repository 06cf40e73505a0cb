"""What the console draws for a scenario: bodies, route, static geometry, gauges, read-outs, sensors.

A scenario may describe itself with ``console_view(cfg) -> dict`` (keys below, all optional); what it
leaves out is inferred from the live bus:

* ``bodies``: ``[{"name": "usv", "label": "USV", "length": 3.0, "beam": 1.8, "shape": "boat"}]``
  (a body is any prefix ``p`` with ``p.x``, ``p.y`` on the bus; ``shape`` boat, ship or sub);
* ``route``: ``[[north, east], ...]`` (m); inferred from ``cfg.guidance.waypoints`` when present;
* ``polylines``: static geometry, ``[{"name": "berth", "points": [[n, e], ...], "style": "berth"}]``
  (styles: berth, channel, route, shore); a scenario method ``console_geometry(cfg)`` or
  ``geometry(cfg)`` returning ``{name: [[n, e], ...]}`` is used too (berth and channel polylines);
* ``cable``: ``{"x": [keys...], "y": [keys...], "z": [keys...]}`` bus keys of the cable's nodes, or
  ``{"prefix": "cable"}`` to read ``cable.node_x`` style arrays; inferred from ``cable.x<i>``;
* ``gauges``: ``[{"key", "label", "unit", "scale", "min", "max"}]`` actuator bars; inferred from
  bus keys naming thrust, rudder, propeller rpm;
* ``readouts``: ``[{"key", "label", "unit", "scale"}]``; inferred: speed, heading, depth;
* ``sensors``: ``[{"key", "label"}]`` health flags (1 valid, 0 failed); inferred from keys ending
  in ``.valid`` or ``.ok``.
"""

from __future__ import annotations

import math
import re

from ..units import KGF


def _scalar_keys(bus: dict) -> list[str]:
    return sorted(k for k, v in bus.items() if not k.startswith("_") and isinstance(v, (int, float))
                  and not isinstance(v, bool))


def infer_view(scenario, cfg, bus: dict) -> dict:
    """The console view of a built scenario: its own ``console_view`` completed from the bus."""
    view: dict = {}
    if hasattr(scenario, "console_view"):
        try:
            view = dict(scenario.console_view(cfg) or {})
        except Exception as e:  # a broken view must not stop the console
            view = {"warning": f"console_view failed: {e}"}
    keys = _scalar_keys(bus)
    keyset = set(keys)
    if "bodies" not in view:
        bodies = []
        for k in keys:
            if k.endswith(".x"):
                p = k[:-2]
                if f"{p}.y" in keyset and (f"{p}.psi" in keyset or f"{p}.z" in keyset) and not p.startswith("gps"):
                    shape = "sub" if f"{p}.z" in keyset and p.startswith("uuv") else (
                        "ship" if p.startswith("ship") else "boat")
                    length = 2.0 if shape != "ship" else 100.0
                    bodies.append({"name": p, "label": p.upper(), "length": length, "beam": length / 3,
                                   "shape": shape})
        view["bodies"] = bodies
    if "route" not in view:
        wps = getattr(getattr(cfg, "guidance", None), "waypoints", None)
        view["route"] = [[float(a), float(b)] for a, b in wps] if wps else []
    polys = list(view.get("polylines", []))
    for meth in ("console_geometry", "geometry"):
        fn = getattr(scenario, meth, None)
        if callable(fn) and not polys:
            try:
                geo = fn(cfg) or {}
            except Exception:
                geo = {}
            for name, pts in geo.items():
                try:
                    pts = [[float(p[0]), float(p[1])] for p in pts]
                except (TypeError, ValueError, IndexError):
                    continue
                style = "berth" if "berth" in name else ("channel" if "channel" in name or "bank" in name
                                                         else "shore")
                polys.append({"name": name, "points": pts, "style": style})
    view["polylines"] = polys
    if "cable" not in view:
        xs = sorted((k for k in keys if re.fullmatch(r"cable\.x\d+", k)), key=lambda s: int(s[7:]))
        if xs:
            idx = [k[7:] for k in xs]
            view["cable"] = {"x": xs, "y": [f"cable.y{i}" for i in idx], "z": [f"cable.z{i}" for i in idx]}
    if "gauges" not in view:
        gauges = []
        for k in keys:
            leaf = k.split(".", 1)[-1]
            if leaf.endswith("_cmd") or leaf.endswith("_d"):
                continue
            if "thrust" in leaf:
                gauges.append({"key": k, "label": k, "unit": "kgf", "scale": 1 / KGF, "min": -40, "max": 40})
            elif "rudder" in leaf or leaf == "delta":
                gauges.append({"key": k, "label": k, "unit": "deg", "scale": 180 / math.pi, "min": -35, "max": 35})
            elif leaf in ("n", "rpm", "n_prop", "prop_rpm") or "rpm" in leaf:
                gauges.append({"key": k, "label": k, "unit": "rpm" if "rpm" in leaf else "rps", "scale": 1.0,
                               "min": -200, "max": 200})
        view["gauges"] = gauges
    if "readouts" not in view:
        ro = []
        for b in view["bodies"]:
            p = b["name"]
            if f"{p}.speed" in keyset:
                ro.append({"key": f"{p}.speed", "label": f"{p} speed", "unit": "m/s", "scale": 1.0})
            elif f"{p}.u" in keyset:
                ro.append({"key": f"{p}.u", "label": f"{p} surge", "unit": "m/s", "scale": 1.0})
            if f"{p}.psi" in keyset:
                ro.append({"key": f"{p}.psi", "label": f"{p} heading", "unit": "deg", "scale": 180 / math.pi,
                           "wrap360": True})
            if f"{p}.z" in keyset:
                ro.append({"key": f"{p}.z", "label": f"{p} depth", "unit": "m", "scale": 1.0})
        view["readouts"] = ro
    if "sensors" not in view:
        view["sensors"] = [{"key": k, "label": k.rsplit(".", 1)[0]} for k in keys
                           if k.endswith(".valid") or k.endswith(".ok")]
    return view
