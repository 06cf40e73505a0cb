"""What the console does to a scenario's simulation: its adjustable gains (an e-stop or failsafe reaches
the controllers' laws through the ``_estop`` signal: they hold their integrators and give zero thrust,
and the thrusters ramp back when it clears)."""

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
