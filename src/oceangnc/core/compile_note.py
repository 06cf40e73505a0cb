"""What a first run is compiling, said on the progress line instead of a bar standing at 0 %.

A first run on a machine compiles the plants' functions (in a child process, :func:`oceangnc.core.caches.
compile_ahead`) and then the fused driver of the whole closed loop (:mod:`oceangnc.core.fused`): 14-110 s in
which no simulated time passes. The progress line then reads ``compiling <what> (first run, cached
afterwards) [elapsed]`` - only when numba's disk cache has no index for the function yet, so a cached run,
which loads in a second, never says it - and turns into the usual bar at the first simulated step.
"""

from __future__ import annotations

import os

#: the progress bar's format while compiling: the description and the time spent, no empty bar
FORMAT = "{desc} [{elapsed}]"


def _say(bar, what: str) -> None:
    if bar is None or not str(bar.desc).startswith("compiling"):
        return
    bar.bar_format = FORMAT
    bar.set_description_str(f"compiling {what} (first run, cached afterwards)")


def ahead_note(bar, children) -> None:
    """Name the functions the children compile ahead (``children``: :class:`~oceangnc.core.caches.Ahead`)."""
    names = [n for c in children for n in getattr(c, "names", ())]
    if names:
        shown = ", ".join(names[:3]) + (f" and {len(names) - 3} more" if len(names) > 3 else "")
        _say(bar, f"{shown}")


def driver_note(bar, sim, fused) -> None:
    """Say that the fused driver of ``sim`` is being compiled when numba has no cache index for it yet."""
    from .caches import _index_path

    path = _index_path(getattr(fused, "drive", None))
    if path is not None and not os.path.exists(path):
        _say(bar, f"the closed loop ({len(sim.blocks)} blocks, {len(sim.plants)} plant(s)) into one driver")


def done(bar) -> bool:
    """True once when the bar still shows a compiling note: back to the ordinary bar (the caller resets it)."""
    if bar is None or not str(bar.desc).startswith("compiling"):
        return False
    bar.bar_format = None
    bar.set_description_str("")
    return True
