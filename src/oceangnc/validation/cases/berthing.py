"""Validation cases of 001: joystick berthing in the Z channel, open loop vs PID vs nonlinear (figs 8-10,
indices (43)-(44))."""

from __future__ import annotations

import math
from functools import partial

from .. import Case, Measured
from ._common import D001, in_group

CHANNEL_SHORT = {"channel.leg1_m": 400.0, "channel.leg2_m": 300.0, "channel.leg3_m": 400.0, "runs": 2}
MODES = ("open", "pid", "nonlinear")


def berth(kind, r):
    """``kind`` "error_index", "rudder_index" or "bow_thruster_index": open loop over the worse closed loop
    (the smaller of open / PID and open / nonlinear; a closed loop that never uses the actuator counts as
    infinitely better); "equal": |PID - nonlinear| / max of the error indices."""
    s = {mode: r.run("berthing-channel", **{**CHANNEL_SHORT, "control.mode": mode})[0] for mode in MODES}
    ser = [
        ("error index (44) [m²/1000]", [0, 1, 2], [s[k]["error_index"] / 1000 for k in MODES]),
        ("rudder index (43) [rad]", [0, 1, 2], [s[k]["rudder_index"] for k in MODES]),
        ("bow thruster index (43) [rev/s]", [0, 1, 2], [s[k]["bow_thruster_index"] for k in MODES]),
    ]
    note = ", ".join(
        f"{k}: error {s[k]['error_index']:.0f} m², rudder {s[k]['rudder_index']:.3f}, "
        f"bow {s[k]['bow_thruster_index']:.3f}"
        for k in MODES
    )
    if kind == "equal":
        a, b = s["pid"]["error_index"], s["nonlinear"]["error_index"]
        v = abs(a - b) / max(a, b)
    else:
        o = s["open"][kind]
        v = min(o / s[k][kind] if s[k][kind] > 0 else math.inf for k in MODES[1:])
        note += f"; open / PID {o / s['pid'][kind]:.3g}" + (
            f", open / nonlinear {o / s['nonlinear'][kind]:.3g}" if s["nonlinear"][kind] > 0 else ", nonlinear 0"
        )
    return Measured(v, ser, xlabel="0 open, 1 PID, 2 nonlinear", ylabel="index", band=False, note=note)


_RUNS = "Z channel, 2 runs per controller"
_LARGER = (
    ("min", 1.5),
    "001 prints no numbers for figs 8-10 (bar charts): 'considerably / markedly larger' read as at least "
    "1.5 times the worse closed loop, the smallest ratio a reader of a bar chart would call considerable "
    "(our reading; a 5 % gain would read as 'about equal')",
)
_DEV_ERROR = (
    "Our open loop crosses the channel with an error index only 5-12 % above the closed loops (docs/berthing.md: "
    "21.2 against 19.0 / 18.7 thousand m² over 5 full runs): most of the area comes from the scripted pilot "
    "cutting the corners of the bends, which all three modes do, and the pilot model (how late and how well he "
    "perceives the yaw rate) decides the rest; with a perfect rate perception the open loop flies the channel "
    "as well as the closed loops. 001 does not describe its pilots."
)

CASES: list[Case] = in_group(
    "001",
    Case(
        "001-fig8-error-index",
        _RUNS,
        f"{D001} fig 8, index (44) (text: open-loop error 'considerably larger', 상당히 크다)",
        "error index, open loop / worse closed loop",
        "-",
        None,
        "open loop considerably larger than PID and nonlinear (no number printed)",
        *_LARGER,
        partial(berth, "error_index"),
        deviation=_DEV_ERROR,
        kind="prediction",
        qualitative=True,
    ),
    Case(
        "001-fig9-rudder-index",
        _RUNS,
        f"{D001} fig 9, index (43) (text under figs 9-10: open-loop index 'markedly larger', 현격히 더 크다)",
        "rudder index, open loop / worse closed loop",
        "-",
        None,
        "open loop markedly larger than PID and nonlinear (no number printed)",
        *_LARGER,
        partial(berth, "rudder_index"),
        kind="calibration",
        basis="re-classed from prediction (issue 38): the ratio is set by the open loop's stick-to-rudder map (35 deg "
        "at half stick), our choice, 001 prints none, against PID's rudder use; the nonlinear controller flies on "
        "thrusters (rudder index 0). It tests our pilot's map, not 001's result",
    ),
    Case(
        "001-fig10-bow-index",
        _RUNS,
        f"{D001} fig 10, index (43) (text under figs 9-10: 'markedly larger')",
        "bow thruster index, open loop / worse closed loop",
        "-",
        None,
        "open loop markedly larger than PID and nonlinear (no number printed)",
        *_LARGER,
        partial(berth, "bow_thruster_index"),
        kind="prediction",
        qualitative=True,
    ),
    Case(
        "001-calm-pid-equals-nonlinear",
        "Z channel, calm",
        f"{D001} ch. 4.1 and 5 text",
        "|PID - nonlinear| / max of the error indices",
        "-",
        0.0,
        "no difference without disturbances",
        ("max", 0.3),
        "'no difference' over 2 scripted runs with the same pilot",
        partial(berth, "equal"),
        kind="prediction",
        qualitative=True,
    ),
)
