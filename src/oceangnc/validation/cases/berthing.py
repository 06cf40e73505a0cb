"""Validation cases of 001: joystick berthing in the Z channel, open loop vs PID vs nonlinear (figs 8-10,
indices (43)-(44))."""

from __future__ import annotations

from functools import partial

from .. import Case, Measured
from ._common import D001, in_group

CHANNEL_SHORT = {"channel.leg1_m": 400.0, "channel.leg2_m": 300.0, "channel.leg3_m": 400.0, "runs": 2}
MODES = ("open", "pid", "nonlinear")


def berth(kind, r):
    """``kind`` "error": relative error-index gain of the worse closed loop over open loop; "bow": the
    bow thruster index saved by the worse closed loop; else |PID - nonlinear| / max of the error indices."""
    s = {mode: r.run("berthing-channel", **{**CHANNEL_SHORT, "control.mode": mode})[0] for mode in MODES}
    ser = [
        ("error index (44) [m²/1000]", [0, 1, 2], [s[k]["error_index"] / 1000 for k in MODES]),
        ("bow thruster index (43)", [0, 1, 2], [s[k]["bow_thruster_index"] for k in MODES]),
    ]
    note = ", ".join(
        f"{k}: error {s[k]['error_index']:.0f} m², rudder {s[k]['rudder_index']:.3f}, "
        f"bow {s[k]['bow_thruster_index']:.3f}"
        for k in MODES
    )
    if kind == "error":
        v = min(s["open"]["error_index"] - s[k]["error_index"] for k in MODES[1:]) / s["open"]["error_index"]
    elif kind == "bow":
        v = min(s["open"]["bow_thruster_index"] - s[k]["bow_thruster_index"] for k in MODES[1:])
    else:
        a, b = s["pid"]["error_index"], s["nonlinear"]["error_index"]
        v = abs(a - b) / max(a, b)
    return Measured(v, ser, xlabel="0 open, 1 PID, 2 nonlinear", ylabel="index", band=False, note=note)


_RUNS = "Z channel, 2 runs per controller"
_ORDERING = ("min", 0.0), "sign of the published ordering"

CASES: list[Case] = in_group(
    "001",
    Case(
        "001-figs8-10-error-index",
        _RUNS,
        f"{D001} figs 8-10, index (44)",
        "error index gain of the closed loops over open loop (worst of PID / nonlinear)",
        "-",
        None,
        "closed loop beats open loop",
        *_ORDERING,
        partial(berth, "error"),
    ),
    Case(
        "001-figs8-10-bow-index",
        _RUNS,
        f"{D001} figs 8-10, index (43)",
        "bow thruster index, open minus closed (worst)",
        "-",
        None,
        "closed loop uses less bow thruster",
        *_ORDERING,
        partial(berth, "bow"),
    ),
    Case(
        "001-calm-pid-equals-nonlinear",
        "Z channel, calm",
        f"{D001} ch. 5 text",
        "|PID - nonlinear| / max of the error indices",
        "-",
        0.0,
        "equal without disturbances",
        ("max", 0.3),
        "'equal' over 2 scripted runs",
        partial(berth, "equal"),
    ),
)
