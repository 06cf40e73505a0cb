"""Validation cases of the combined USV-cable-UUV vehicle: 003 ch. 4 (combined-survey, waypoints-square)
and ch. 6.2 (field-test). One ``combined-survey`` run per controller feeds seven cases (shared by the Runner)."""

from __future__ import annotations

import math
from functools import partial

import numpy as np

from ...core.rotations import wrap_array
from .. import Case
from ._common import D003, history, in_group, plan, track, ts


def survey(r, ctrl):
    return r.run("combined-survey", **{"control.uuv": ctrl})


def rel_distance(df):
    from ...scenarios.combined import rel_distance

    return rel_distance(df)


def rel_series(df, label):
    return (label, df["t"].to_numpy(), rel_distance(df))


def _both_surveys(r):
    """(summary, df) of the backstepping survey, then of the PID one, and the two distance series."""
    s, df = survey(r, "backstepping")
    sp, dfp = survey(r, "pid")
    return s, df, sp, dfp, [rel_series(df, "backstepping"), rel_series(dfp, "PID")]


_DISTANCE = "USV-UUV horizontal distance [m]"


def bs_distance(r):
    s, df, sp, _, series = _both_surveys(r)
    return history(
        s["uuv.rel_distance_mean_m"],
        series,
        _DISTANCE,
        [("003 ch. 4 text: backstepping ≈ 0.4 m", [df["t"].iloc[-1]], [0.4])],
        note=f"max {s['uuv.rel_distance_max_m']:.3f} m (PID: mean {sp['uuv.rel_distance_mean_m']:.3f}, "
        f"max {sp['uuv.rel_distance_max_m']:.3f} m); formation target l^d = 0.5 m (unprinted)",
    )


def bs_vs_pid(r):
    s, _, sp, _, series = _both_surveys(r)
    return history(
        sp["uuv.rel_distance_mean_m"] - s["uuv.rel_distance_mean_m"],
        series,
        _DISTANCE,
        band=False,
        note=f"mean PID {sp['uuv.rel_distance_mean_m']:.3f} m vs backstepping {s['uuv.rel_distance_mean_m']:.3f} m",
    )


def growth(r):
    """PID distance at 30 s minus at 25 s (and the backstepping one in the note)."""
    _, df, _, dfp, series = _both_surveys(r)

    def change(d):
        t, rd = d["t"].to_numpy(), rel_distance(d)
        return float(rd[int(np.argmin(abs(t - 30.0)))] - rd[int(np.argmin(abs(t - 25.0)))])

    bs, pid = change(df), change(dfp)
    return history(
        pid,
        series,
        _DISTANCE,
        band=False,
        note=f"distance change 25 -> 30 s: PID {pid:+.3f} m, backstepping {bs:+.3f} m",
    )


def survey_depth(r):
    s, df = survey(r, "backstepping")
    _, dfp = survey(r, "pid")
    return history(
        s["uuv.depth_final_m"],
        [ts(df, "uuv.z", label="backstepping"), ts(dfp, "uuv.z", label="PID")],
        "UUV depth [m]",
        [("003 ch. 4: start 3 m", [0.0], [3.0]), ("003 ch. 4: converges ≈ 2.77 m", [df["t"].iloc[-1]], [2.77])],
    )


def survey_waypoints(ctrl, r):
    s, df = survey(r, ctrl)
    return plan(
        s["usv.waypoints_reached"],
        [track(df, "usv"), track(df, "uuv")],
        [("waypoints (003 ch. 4)", [0, 10, 5], [0, 10, 20])],
        note=f"cross-track rms {s['usv.cross_track_rms_m']:.2f} m, end {s['t_end_s']:.0f} s",
    )


def leg_switch(r):
    s, df = survey(r, "backstepping")
    t = df["t"].to_numpy()
    leg = df["guidance.leg"].to_numpy()
    t_switch = float(t[np.argmax(leg >= 1)]) if (leg >= 1).any() else float("nan")
    return history(
        t_switch,
        [
            ("USV heading", t, np.degrees(np.unwrap(df["usv.psi"].to_numpy()))),
            ("USV target heading", t, np.degrees(np.unwrap(df["guidance.psi_d"].to_numpy()))),
        ],
        "heading [deg]",
        [("003 ch. 4: switch at about 25 s", [25.0], [0.0])],
        band=False,
        note=f"second leg starts at {t_switch:.1f} s (acceptance radius 2 m)",
    )


def square(r):
    s, df = r.run("waypoints-square")
    return plan(
        s["usv.waypoints_reached"],
        [track(df, "usv"), track(df, "uuv")],
        [("waypoints (003 fig 4-6)", [0, 0, 50, 50], [0, 50, 50, 0])],
        note=f"rel. distance max {s['uuv.rel_distance_max_m']:.2f} m",
    )


def field_depth(r):
    s, df = r.run("field-test")
    return history(
        s["uuv.depth_final_m"],
        [ts(df, "uuv.z", label="UUV depth (true)")],
        "depth [m]",
        [("003 ch. 6.2: 3 m", [0.0], [3.0]), ("003 ch. 6.2: ≈ 2.75 m", [df["t"].iloc[-1]], [2.75])],
    )


def field_pitch(r):
    _, df = r.run("field-test")
    moving = df["usv.speed"].to_numpy() > 0.3
    th = np.degrees(df["uuv.theta"].to_numpy())
    return history(
        float(np.median(th[moving])),
        [ts(df, "uuv.theta", 180 / math.pi, "UUV pitch")],
        "pitch [deg]",
        note="median while the USV moves (> 0.3 m/s)",
    )


def field_waypoints(r):
    s, df = r.run("field-test")
    return plan(
        s["usv.waypoints_reached"],
        [track(df, "usv"), track(df, "uuv")],
        [("waypoints (003 ch. 6.2)", [0, 0, -50, -50, 0], [0, 50, 50, 0, 0])],
    )


def ahrs(r):
    s, df = r.run("field-test")
    d = np.degrees(np.abs(wrap_array(df["usv_ahrs.psi"] - df["gps.cog"])))
    return history(s["ahrs.gps_heading_diff_mean_deg"], [("|AHRS - GPS course|", df["t"].to_numpy(), d)], "deg")


_DEV_DEPTH = (
    "The UUV does not rise toward 2.77 m: on a taut 3 m cable a 0.23 m rise needs the tow point >= 1.15 m "
    "(horizontally) from the attachment, which holding the UUV 0.4-0.5 m from the USV excludes unless the "
    "cable leaves the USV's bow, 1.15 m ahead; that pitches the UUV 34-45 deg (003: -2 to -4). A UUV dragged "
    "with its thrusters off rises to 2.65-2.79 m at -0.2 to -3.3 deg. See docs/combined-vehicle.md 'The "
    "flagship result' and the sweep in docs/validation/flagship_sweep.png."
)
_DEV_BS = (
    "Backstepping and PID are within 1-2 cm: the cable carries the UUV (stern thrust 1-2 N each of 75 N: the cable tows it), and the "
    "formation target sits where the towed UUV trails anyway; see docs/combined-vehicle.md 'The flagship result'."
)
_DEV_PITCH = (
    "Held near the USV at 0.96 m/s, our UUV pitches far more nose-down: the forward cable pull acts "
    "0.125 m above the centre of buoyancy against a pitch stiffness of ~11 N m/rad. A UUV dragged "
    "1.5-1.8 m behind its tow point pitches -0.2 to -3.3 deg, as 003 reports "
    "(docs/combined-vehicle.md, 'The flagship result')."
)
_FIELD = "field-test, sensors on"
_COUNT = ("waypoints reached", "-")
_ALL = (("abs", 0.0), "count")

CASES: list[Case] = in_group(
    "003 combined",
    Case(
        "003-fig4-7-waypoints-bs",
        "combined-survey, backstepping",
        f"{D003} figs 4-7, 4-8",
        *_COUNT,
        3.0,
        "all three",
        *_ALL,
        partial(survey_waypoints, "backstepping"),
    ),
    Case(
        "003-fig4-7-waypoints-pid",
        "combined-survey, PID",
        f"{D003} figs 4-7, 4-8",
        *_COUNT,
        3.0,
        "all three",
        *_ALL,
        partial(survey_waypoints, "pid"),
    ),
    Case(
        "003-fig4-15-bs-distance",
        "combined-survey, backstepping",
        f"{D003} fig 4-15 (ch. 4 text)",
        "mean USV-UUV horizontal distance",
        "m",
        0.4,
        "about 0.4 m",
        ("abs", 0.1),
        "'about 0.4 m' read to ±0.1; the target offset l^d is unprinted (ours 0.5 m)",
        bs_distance,
    ),
    Case(
        "003-fig4-15-bs-beats-pid",
        "combined-survey, PID minus backstepping",
        f"{D003} figs 4-12 to 4-15",
        "mean distance PID - backstepping",
        "m",
        None,
        "backstepping holds the distance, PID does not",
        ("min", 0.05),
        "'clearly better': at least 10 % of the 0.5 m distance",
        bs_vs_pid,
        deviation=_DEV_BS,
    ),
    Case(
        "003-fig4-14-depth",
        "combined-survey, backstepping",
        f"{D003} fig 4-14 (ch. 4 text)",
        "final UUV depth",
        "m",
        2.77,
        "3 m -> near 2.77 m",
        ("abs", 0.05),
        "the printed 2.77 read to ±0.05 m",
        survey_depth,
        deviation=_DEV_DEPTH,
    ),
    Case(
        "003-fig4-12-leg-switch",
        "combined-survey, USV heading",
        f"{D003} figs 4-12, 4-13 (ch. 4 text)",
        "time of the switch to the second leg",
        "s",
        25.0,
        "the desired heading switches at about 25 s",
        ("abs", 4.0),
        "the waypoint acceptance radius is unprinted: ours (2 m at 0.6 m/s) moves the switch by "
        "3.3 s; plus the figure reading",
        leg_switch,
    ),
    Case(
        "003-fig4-15-distance-growth",
        "combined-survey, PID, 25-30 s",
        f"{D003} fig 4-15 (ch. 4 text)",
        "PID distance at 30 s minus at 25 s",
        "m",
        None,
        "the relative distance grows over 25-30 s",
        ("min", 0.02),
        "'grows': by more than the 0.02 m noise of the distance",
        growth,
        deviation=_DEV_BS,
    ),
    Case("003-fig4-6-square", "waypoints-square", f"{D003} fig 4-6", *_COUNT, 4.0, "all four", *_ALL, square),
    Case(
        "003-ch6.2-field-waypoints",
        _FIELD,
        f"{D003} ch. 6.2, fig 6-13",
        *_COUNT,
        5.0,
        "the route was completed",
        *_ALL,
        field_waypoints,
    ),
    Case(
        "003-ch6.2-field-depth",
        _FIELD,
        f"{D003} ch. 6.2, fig 6-17",
        "final UUV depth",
        "m",
        2.75,
        "3 m -> about 2.75 m",
        ("abs", 0.05),
        "'about 2.75' read to ±0.05 m",
        field_depth,
        deviation=_DEV_DEPTH,
    ),
    Case(
        "003-ch6.2-field-pitch",
        _FIELD,
        f"{D003} ch. 6.2",
        "UUV pitch while moving",
        "deg",
        None,
        "-2 to -4 deg",
        ("range", -4.0, -2.0),
        "the printed range",
        field_pitch,
        deviation=_DEV_PITCH,
    ),
    Case(
        "003-ch6.2-ahrs-gps",
        "field-test, AHRS vs GPS course while moving",
        f"{D003} ch. 6.1, fig 6-2",
        "mean |AHRS heading - GPS course|",
        "deg",
        3.53,
        "mean 3.53 deg (sd 3.88)",
        ("abs", 2.0),
        "half the printed standard deviation",
        ahrs,
    ),
)
