"""What the console does to a scenario's simulation: its adjustable gains, holding the controllers' PIDs
during an e-stop or failsafe, and gating the scenario's own pilot while the operator's stick drives."""

from __future__ import annotations

import math


def collect_gains(sim) -> dict[str, dict]:
    """Adjustable gains of a simulation's blocks: ``"<block>.<gain>" -> spec`` with a setter.

    A block offering ``gain_specs()`` / ``set_gain(name, value)`` is asked; otherwise every
    :class:`oceangnc.control.pid.PID` attribute of a block exposes its kp, ki, kd with the range
    [0, max(10 |value|, 1)].
    """
    from ..control.pid import PID

    out: dict[str, dict] = {}
    for b in sim.blocks:
        if hasattr(b, "gain_specs") and hasattr(b, "set_gain"):
            for s in b.gain_specs():
                name = f"{b.name}.{s['name']}"
                spec = {k: s[k] for k in ("value", "min", "max") if k in s}
                spec.update(
                    {
                        "unit": s.get("unit", ""),
                        "description": s.get("description", ""),
                        "setter": (lambda v, b=b, n=s["name"]: b.set_gain(n, v)),
                        "getter": (
                            lambda b=b, n=s["name"]: next(
                                (x["value"] for x in b.gain_specs() if x["name"] == n), math.nan
                            )
                        ),
                    }
                )
                out[name] = spec
            continue
        for attr, obj in vars(b).items():
            if isinstance(obj, PID):
                for g in ("kp", "ki", "kd"):
                    v = getattr(obj, g)
                    out[f"{b.name}.{attr}.{g}"] = {
                        "value": v,
                        "min": 0.0,
                        "max": max(10 * abs(v), 1.0),
                        "unit": "",
                        "description": f"{attr} PID {g}",
                        "setter": (lambda val, o=obj, g=g: setattr(o, g, float(val))),
                        "getter": (lambda o=obj, g=g: getattr(o, g)),
                    }
    return out


def _pids(obj, depth=0, seen=None):
    """PID objects inside a block (attributes, one level of nesting, gated pilots)."""
    from ..control.pid import PID

    seen = set() if seen is None else seen
    if id(obj) in seen or depth > 2:
        return
    seen.add(id(obj))
    for v in list(vars(obj).values()) if hasattr(obj, "__dict__") else []:
        if isinstance(v, PID):
            if id(v) not in seen:
                seen.add(id(v))
                yield v
        elif hasattr(v, "__dict__") and not isinstance(v, type) and type(v).__module__.startswith("oceangnc."):
            yield from _pids(v, depth + 1, seen)


def hold_controllers(sim, on: bool, ramp_s: float = 2.0) -> int:
    """Hold (``on``) or release every PID of the simulation's blocks (see
    :meth:`oceangnc.control.pid.PID.hold`): integrators frozen while stopped, outputs ramped from zero
    over ``ramp_s`` s on release (no thrust step at Reset). Returns how many PIDs."""
    n = 0
    seen: set = set()
    for b in sim.blocks:
        for pid in _pids(b, 0, seen):
            pid.hold(on, ramp_s=ramp_s)
            n += 1
    return n
