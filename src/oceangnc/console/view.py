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
  in ``.valid`` or ``.ok``;
* ``waves``: the wave components of a scenario at sea (``environment.waves``, kind not none):
  ``{"a", "omega", "k", "theta", "eps"}`` lists, from the call its plant is built with
  (:meth:`oceangnc.environment.SeaEnvironmentConfig.plant_kwargs` of ``sim.seed``); the 3D panel draws
  the sea surface from them (docs/view.md).
"""

from __future__ import annotations

import math
import re

from ..units import KGF


def _scalar_keys(bus: dict) -> list[str]:
    return sorted(
        k for k, v in bus.items() if not k.startswith("_") and isinstance(v, (int, float)) and not isinstance(v, bool)
    )


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
                    shape = (
                        "sub"
                        if f"{p}.z" in keyset and p.startswith("uuv")
                        else ("ship" if p.startswith("ship") else "boat")
                    )
                    length = 2.0 if shape != "ship" else 100.0
                    bodies.append({"name": p, "label": p.upper(), "length": length, "beam": length / 3, "shape": shape})
        for b in bodies:  # dimensions from the body's config section when it has them
            bc = getattr(cfg, b["name"], None)
            length = getattr(bc, "length_oa", None) or getattr(bc, "length", None)
            beam = getattr(bc, "beam", None) or getattr(bc, "diameter", None)
            if length:
                b["length"] = float(length)
                b["beam"] = float(beam) if beam else float(length) / 3
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
            polys.extend(_geometry_polylines(geo, view))
    view["polylines"] = polys
    if "cable" not in view:
        xs = sorted((k for k in keys if re.fullmatch(r"cable\.x\d+", k)), key=lambda s: int(s[7:]))
        if xs:
            idx = [k[7:] for k in xs]
            view["cable"] = {"x": xs, "y": [f"cable.y{i}" for i in idx], "z": [f"cable.z{i}" for i in idx]}
    if "gauges" not in view:
        view["gauges"] = [g for g in (_gauge(k, cfg) for k in keys) if g is not None]
    if "readouts" not in view:
        ro = []
        for b in view["bodies"]:
            p = b["name"]
            if f"{p}.speed" in keyset:
                ro.append({"key": f"{p}.speed", "label": f"{p} speed", "unit": "m/s", "scale": 1.0})
            elif f"{p}.u" in keyset:
                ro.append({"key": f"{p}.u", "label": f"{p} surge", "unit": "m/s", "scale": 1.0})
            if f"{p}.psi" in keyset:
                ro.append(
                    {"key": f"{p}.psi", "label": f"{p} heading", "unit": "deg", "scale": 180 / math.pi, "wrap360": True}
                )
            if f"{p}.z" in keyset:
                ro.append({"key": f"{p}.z", "label": f"{p} depth", "unit": "m", "scale": 1.0})
        view["readouts"] = ro
    if "waves" not in view:
        from ..environment import SeaEnvironmentConfig

        env = getattr(cfg, "environment", None)
        if isinstance(env, SeaEnvironmentConfig) and env.waves.kind != "none":
            w = env.plant_kwargs(cfg.sim.seed)["waves"]
            view["waves"] = {k: getattr(w, k).tolist() for k in ("a", "omega", "k", "theta", "eps")}
    if "sensors" not in view:
        view["sensors"] = [
            {"key": k, "label": k.rsplit(".", 1)[0]} for k in keys if k.endswith(".valid") or k.endswith(".ok")
        ]
    return view


def _pts(p) -> list[list[float]] | None:
    try:
        out = [[float(q[0]), float(q[1])] for q in p]
    except (TypeError, ValueError, IndexError):
        return None
    return out if len(out) >= 2 else None


def _geometry_polylines(geo: dict, view: dict) -> list[dict]:
    """Polylines from a scenario's ``geometry(cfg)`` (berthing: route, banks, quay, berth, ship)."""
    polys = []
    for name, val in geo.items():
        if name == "route":
            pts = _pts(val)
            if pts and not view.get("route"):
                view["route"] = pts
            continue
        if name == "banks":
            for i, bank in enumerate(val or []):
                pts = _pts(bank)
                if pts:
                    polys.append({"name": f"bank {i}", "points": pts, "style": "channel"})
            continue
        if name == "quay":
            pts = _pts(val)
            if pts:
                polys.append({"name": "quay", "points": pts, "style": "shore"})
            continue
        pts = _pts(val)
        if pts:
            style = "berth" if "berth" in name else ("channel" if "channel" in name or "bank" in name else "shore")
            polys.append({"name": name, "points": pts, "style": style})
    ship = geo.get("ship") if isinstance(geo.get("ship"), dict) else None
    berth = geo.get("berth")
    if ship:
        for b in view.get("bodies", []):
            if b["name"] == "ship":
                b["length"], b["beam"] = float(ship["length"]), float(ship["beam"])
    if ship and isinstance(berth, (list, tuple)) and len(berth) == 2:
        # the berth: the ship's outline where it should end up, at the berth heading
        L, B = float(ship["length"]), float(ship["beam"])
        h = math.radians(float(geo.get("berth_heading_deg", 0.0)))
        c, s = math.cos(h), math.sin(h)
        n0, e0 = float(berth[0]), float(berth[1])
        box = [(L / 2, -B / 2), (L / 2, B / 2), (-L / 2, B / 2), (-L / 2, -B / 2), (L / 2, -B / 2)]
        polys.append(
            {"name": "berth", "style": "berth", "points": [[n0 + x * c - y * s, e0 + x * s + y * c] for x, y in box]}
        )
    return polys


def _gauge(key: str, cfg) -> dict | None:
    """An actuator gauge for a bus key naming thrust, rudder or shaft speed; ranges from the body's
    config section (``max_thrust_kgf``, ``max_reverse_kgf``, ``rudder_max_deg``, ``n_max_rpm``,
    ``thruster_rpm_max``) when it has them."""
    if "." not in key:
        return None
    body, leaf = key.split(".", 1)
    if leaf.endswith("_cmd") or leaf.endswith("_d") or "." in leaf:
        return None
    bc = getattr(cfg, body, None)
    label = f"{body} {leaf.replace('_', ' ')}"
    if leaf.startswith("thrust"):
        hi = getattr(bc, "max_thrust_kgf", 40.0)
        lo = -getattr(bc, "max_reverse_kgf", hi)
        return {"key": key, "label": label, "unit": "kgf", "scale": 1 / KGF, "min": lo, "max": hi}
    if leaf in ("rudder", "delta"):
        m = getattr(bc, "rudder_max_deg", 35.0)
        return {"key": key, "label": label, "unit": "deg", "scale": 180 / math.pi, "min": -m, "max": m}
    if leaf.startswith("rpm"):
        m = getattr(bc, "n_max_rpm", 200.0) if "prop" in leaf else getattr(bc, "thruster_rpm_max", 200.0)
        return {"key": key, "label": label, "unit": "rpm", "scale": 1.0, "min": -m, "max": m}
    return None
