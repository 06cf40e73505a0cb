"""The console's string signals in the fused loop (issue 19; :mod:`oceangnc.core.fused`).

The signal array of a fused loop holds floats. The console protocol's ``console.mode`` and
``console.loop`` are strings; a kernel that lists one of them among its signals reads it as a code,
its index in :data:`ENUMS` (-1 when the signal is absent: the reading block's default). Any other
console string (a route sent by the console, ``console.waypoints``) read by a block keeps the Python
path: :func:`strings_ok` says why, at build time and before each fused call.
"""

from __future__ import annotations

import numpy as np

#: string signals of the console protocol that kernels read as a code, the value's index here
ENUMS = {"console.mode": ("remote", "auto"), "console.loop": ("closed", "open")}


def _numeric(v) -> bool:
    return isinstance(v, (int, float, bool, np.floating, np.integer, np.bool_))


def code(k: str, v) -> float:
    """A bus value as a float of the signal array: numbers as they are (absent or not numeric: 0), an
    :data:`ENUMS` string its index (absent or unknown: -1, the reading block's default)."""
    if k in ENUMS:
        return float(ENUMS[k].index(v)) if isinstance(v, str) and v in ENUMS[k] else -1.0
    return float(v) if _numeric(v) else 0.0


def strings_ok(bus: dict, readers) -> str | None:
    """None when every console string signal on ``bus`` is read only by kernels that take its code,
    else why not; ``readers``: (block, compiled form) pairs."""
    for k, v in bus.items():
        if _numeric(v) or not k.startswith("console."):
            continue
        if k in ENUMS and v not in ENUMS[k]:
            return f"signal '{k}' = {v!r} (no code for it in the fused loop)"
        for b, f in readers:
            reads = {**(getattr(b, "inputs", None) or {}), **(getattr(b, "optional_inputs", None) or {})}
            if k in reads and (k not in ENUMS or not ({k, "?" + k} & set(f.signals))):
                return f"signal '{k}' = {v!r} is read by block '{b.name}' on the Python path only"
    return None
