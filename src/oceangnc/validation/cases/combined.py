"""Validation cases of the combined USV-cable-UUV vehicle: 003 ch. 4 (combined-survey, waypoints-square)
and ch. 6.2 (field-test). One ``combined-survey`` run per controller feeds seven cases (shared by the Runner)."""

from __future__ import annotations

import math
from functools import partial

import numpy as np

from ...core.rotations import wrap_array
from .. import Case, Measured
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
        note=f"max {s['uuv.rel_distance_max_m']:.3f} m; formation target l^d = 0.5 m (unprinted, ours). PID: mean "
        f"{sp['uuv.rel_distance_mean_m']:.3f} m, max {sp['uuv.rel_distance_max_m']:.3f} m, which "
        + ("passes" if abs(sp["uuv.rel_distance_mean_m"] - 0.4) <= 0.1 else "would fail")
        + " the same band: the distance is where the chosen target and the cable put the UUV",
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


def turn_window(df) -> tuple[int, int]:
    """Row indices (start, end) of the USV's turn onto the second leg, read from the log: from the switch of
    ``guidance.leg`` until the USV's yaw rate falls back below 20 % of its peak in the turn."""
    leg = df["guidance.leg"].to_numpy()
    if not (leg >= 1).any():
        raise ValueError("the USV never reaches the second leg: no turn in the log")
    i0 = int(np.argmax(leg >= 1))
    r = np.abs(df["usv.r"].to_numpy()[i0:])
    k = int(np.argmax(r))
    below = np.nonzero(r[k:] < 0.2 * r[k])[0]
    i1 = i0 + k + (int(below[0]) if below.size else r.size - 1 - k)
    return i0, i1


def largest_rise(y: np.ndarray) -> tuple[float, int, int]:
    """(rise, i, j): the largest y[j] - y[i] with i <= j."""
    lo = np.minimum.accumulate(y)
    j = int(np.argmax(y - lo))
    i = int(np.argmin(y[: j + 1]))
    return float(y[j] - y[i]), i, j


def growth(r):
    """Largest rise of the backstepping distance inside the USV's own turn window (read from the log)."""
    _, df, _, dfp, series = _both_surveys(r)
    t = df["t"].to_numpy()
    i0, i1 = turn_window(df)
    d = rel_distance(df)
    rise, a, b = largest_rise(d[i0 : i1 + 1])
    pre = (t >= t[i0] - 10.0) & (t < t[i0])
    swing = float(np.ptp(d[pre])) if pre.any() else float("nan")
    j0, j1 = turn_window(dfp)
    rise_pid = largest_rise(rel_distance(dfp)[j0 : j1 + 1])[0]
    return history(
        rise,
        series,
        _DISTANCE,
        [("turn window (from the log)", [t[i0], t[i1]], [d[i0], d[i1]])],
        band=False,
        note=f"USV turn {t[i0]:.1f}-{t[i1]:.1f} s (003: about 25-30 s); backstepping distance {d[i0 + a]:.3f} m at "
        f"{t[i0 + a]:.1f} s -> {d[i0 + b]:.3f} m at {t[i0 + b]:.1f} s (+{rise:.3f} m); swing over the 10 s before the "
        f"turn {swing:.3f} m; PID's largest rise in its turn +{rise_pid:.3f} m",
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


def uuv_heading_switch(r):
    """When the UUV's desired heading changes after the USV switches to the second leg: the first time its rate
    reaches half its peak (backstepping run)."""
    s, df = survey(r, "backstepping")
    t = df["t"].to_numpy()
    leg = df["guidance.leg"].to_numpy()
    if not (leg >= 1).any():
        raise ValueError("the USV never reaches the second leg")
    i_leg = int(np.argmax(leg >= 1))
    t_leg = float(t[i_leg])
    psi_d = np.unwrap(df["uuv_ctrl.psi_d"].to_numpy())
    dpsi = np.gradient(psi_d, t)
    k = i_leg + int(np.argmax(np.abs(dpsi[i_leg:])))
    i_on = i_leg + int(np.argmax(np.abs(dpsi[i_leg:]) >= 0.5 * abs(dpsi[k])))
    onset = float(t[i_on])
    # half way from the value at the onset to the extremum the change runs to
    sgn = np.sign(dpsi[k])
    end = k + int(np.argmax(sgn * psi_d[k:]))
    half = psi_d[i_on] + 0.5 * (psi_d[end] - psi_d[i_on])
    t_half = float(t[i_on + int(np.argmax(sgn * (psi_d[i_on:] - half) >= 0))])
    outside = int((df["lf.outside"].to_numpy() > 0).sum())
    return history(
        onset,
        [
            ("UUV desired heading", t, np.degrees(psi_d)),
            ("UUV heading", t, np.degrees(np.unwrap(df["uuv.psi"].to_numpy()))),
            ("USV target heading", t, np.degrees(np.unwrap(df["guidance.psi_d"].to_numpy()))),
        ],
        "heading [deg]",
        [("003 fig 4-13 text: changes at about 25 s", [25.0], [float(np.degrees(half))])],
        band=False,
        note=f"the UUV's desired heading starts to change at {onset:.1f} s and is half way at {t_half:.1f} s; the USV "
        f"switched legs at {t_leg:.1f} s (acceptance radius 2 m). The heading-to-USV loop (outside R) engaged in "
        f"{outside} rows: the change is the USV's turn passed on by the relative-angle loop",
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


def survey_tension(r) -> tuple[float, float]:
    """(median bottom tension (N), median lean of the last cable segment forward of the vertical (deg)) of the
    backstepping combined-survey run (single point)."""
    _, df = survey(r, "backstepping")
    n = max(int(c[7:]) for c in df.columns if c.startswith("cable.z") and c[7:].isdigit())
    dn = df[f"cable.x{n - 1}"] - df[f"cable.x{n}"]
    de = df[f"cable.y{n - 1}"] - df[f"cable.y{n}"]
    up = df[f"cable.z{n}"] - df[f"cable.z{n - 1}"]
    fwd = np.cos(df["uuv.psi"]) * dn + np.sin(df["uuv.psi"]) * de
    return float(np.median(df["cable.bottom_tension"])), float(np.degrees(np.median(np.arctan2(fwd, up))))


def bridle_stiffness(r):
    """Pitch stiffness of the bridle about the CB at the survey tension, through the model, against the rigid
    apex's r_A . F_b; the single point's in the note and the plot."""
    from ...models._combined_bridle import pitch_stiffness
    from ...models.cable import CableConfig
    from ...models.uuv import UUVConfig

    T, lean = survey_tension(r)
    uc = UUVConfig(**r.section("uuv"))
    base = {k: v for k, v in r.section("cable").items() if k != "attachment"}
    bri = CableConfig(**{**base, "attachment": "bridle"})
    one = CableConfig(**{**base, "attachment": "single"})
    leans = np.linspace(-20.0, 20.0, 9)
    kb = [pitch_stiffness(bri, uc, T, a)[0] for a in leans]
    ks = [pitch_stiffness(one, uc, T, a)[0] for a in leans]
    k, _ = pitch_stiffness(bri, uc, T, lean)
    k1, rc = pitch_stiffness(one, uc, T, lean)
    b = bri.bridle
    a = math.radians(lean)
    fb = np.array([math.sin(a), 0.0, -math.cos(a)]) * T
    rigid = float(np.array([b.apex_x, b.apex_y, b.apex_z]) @ fb)
    return Measured(
        k,
        [("bridle (model)", leans, np.array(kb)), ("single point (model)", leans, np.array(ks))],
        [("rigid apex r_A . F_b", [lean], [rigid])],
        xlabel="lean of the cable's force from vertical [deg]",
        ylabel="pitch stiffness -dM/dtheta [N m/rad]",
        published=rigid,
        note=f"survey tension {T:.1f} N leaning {lean:.1f} deg (combined-survey, backstepping); bridle {k:.1f}, single "
        f"point {k1:.1f} N m/rad (rigid r_c . F_b = {float(rc @ fb):.1f}); W z_G = {uc.weight * uc.zg:.1f} N m/rad; "
        "Munk + lift M_uw u^2 destabilises by " + ", ".join(
            f"{uc.coefficients()['M_uw'] * u * u:.0f}" for u in (0.6, 0.96)) + " N m/rad at 0.6, 0.96 m/s",
    )  # fmt: skip


def field_waypoints(r):
    s, df = r.run("field-test")
    return plan(
        s["usv.waypoints_reached"],
        [track(df, "usv"), track(df, "uuv")],
        [("waypoints (003 ch. 6.2)", [0, 0, -50, -50, 0], [0, 50, 50, 0, 0])],
    )


def field_leg_time(r):
    """Mean time between the USV's waypoint switches onto legs 2, 3 and 4 of the field test (two 50 m legs): a
    difference of switch times, so the unprinted acceptance radius and the start from rest cancel."""
    from ...models.usv import USVConfig
    from ...units import KGF

    s, df = r.run("field-test")
    t = df["t"].to_numpy()
    leg = df["guidance.leg"].to_numpy()
    if not (leg >= 3).any():
        raise ValueError("the USV never reaches the fourth leg")
    sw = [float(t[int(np.argmax(leg >= k))]) for k in (1, 2, 3)]
    on = (leg >= 1) & (leg <= 2)
    u = float(np.median(df["usv.speed"].to_numpy()[on]))
    uc = USVConfig(**r.section("usv"))
    u_max = 2.0 * uc.max_thrust_kgf * KGF / uc.d11
    return history(
        0.5 * (sw[2] - sw[0]),
        [("USV leg (pure pursuit)", t, leg)],
        "active leg",
        [("003 ch. 6.2: UUV roll changes at about 40, 78, 117 s", [40.0, 78.0, 117.0], [1.0, 2.0, 3.0])],
        band=False,
        note=f"switches at {sw[0]:.1f}, {sw[1]:.1f}, {sw[2]:.1f} s; USV speed on legs 2-3 (median) {u:.3f} m/s, "
        f"target 1.3 m/s; straight-line speed at the thrusters' limit 2 x {uc.max_thrust_kgf:g} kgf / d11 = "
        f"{u_max:.3f} m/s (d11 = {uc.d11:g} N s/m); 50 m in 38.5 s is 1.30 m/s",
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
_DEV_FIELD_DEPTH = (
    "The fit of the bridle's apex height and l^d to 003's pitch, depth and distance at once (docs/validation/"
    "bridle_fit.csv: the cable paid out to hang the UUV at 003's initial 3 m, apex 1.25 m, l^d = 0.4 m) leaves the "
    "depth at 2.80 m, 1.05 tolerances deep: along the fit's valley (apex 0.75-1.25 m at l^d 0.4 m) it stays "
    "2.78-2.83 m. On the 3 m cable of ch. 4 the bridle hangs the UUV its height deeper: 3.43-4.43 m on the grid."
)
_DEV_FIELD_LEGS = (
    "Our USV runs the 50 m legs at 0.96 m/s, not the 1.3 m/s that 003's turn times imply (50 m in 38.5 s): its "
    "thrusters saturate. Its surge damping d11 = 735.5 N s/m is fitted to 003 fig 2-7 (0.8 m/s at 2 x 30 kgf), "
    "and at the thrusters' limit (2 x 36.2 kgf, table C-8) the legs are straight, so u = T / d11 = 0.965 m/s "
    "whatever the unfitted coefficients. 1.3 m/s needs d11 <= 546 N s/m (26 % less, fig 2-7 would give 1.08 m/s) "
    "or 2 x 48.7 kgf: 003's simulated USV (fig 2-7) and its boat at sea (ch. 6.2) disagree. With d11 = 546 N s/m "
    "the field test turns at 37.7, 80.2 and 121.7 s (42.0 s a leg at 1.28 m/s): the rest is the time our pure "
    "pursuit (look-ahead unprinted) spends in the turns."
)
_DEV_GROWTH = (
    "In our survey the backstepping distance does grow in the USV's turn, but by under 2 cm: the cable carries "
    "the UUV (stern thrust 1-2 N each of 75 N) and the formation target sits where the towed UUV trails anyway, "
    "so the turn barely moves it; see docs/combined-vehicle.md 'The flagship result'."
)
_FIELD = "field-test, sensors on"
_COUNT = ("waypoints reached", "-")
_ALL = (("abs", 0.0), "count")
_PRED = {"kind": "prediction"}

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
        **_PRED,
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
        **_PRED,
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
        "'about 0.4 m' read to ±0.1. Not a prediction: the mean distance is the formation target we chose "
        "(l^d = 0.5 m, unprinted), where the towed UUV trails anyway; it passes at 0.496 m, and PID (0.506 m) "
        "would fail the same band",
        bs_distance,
        kind="calibration",
        basis="formation target l^d = 0.5 m, chosen (unprinted; docs/combined-vehicle.md)",
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
        kind="prediction",
        qualitative=True,
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
        **_PRED,
    ),
    Case(
        "003-fig4-13-uuv-heading-switch",
        "combined-survey, backstepping: the UUV's desired heading",
        f"{D003} fig 4-13 (text: 'At about 25 seconds, the desired heading angle changed')",
        "time the UUV's desired heading starts to change (rate at half its peak)",
        "s",
        25.0,
        "the UUV's desired heading changes at about 25 s",
        ("abs", 4.0),
        "the waypoint acceptance radius is unprinted: ours (2 m at 0.6 m/s) moves the USV's turn, and so the "
        "UUV's desired heading, by 3.3 s; plus the figure reading",
        uuv_heading_switch,
        kind="calibration",
        basis="re-classed from prediction (issue 38): what passes is the time of the USV's own leg switch (first "
        "leg length over the USV's surge speed, d11 fitted to 003 fig 2-7, and our 2 m acceptance radius) passed "
        "on to the UUV by the relative-angle loop; the mechanism 003 describes, the UUV switching its heading to "
        "the USV's centre, never engages (the UUV stays inside R)",
    ),
    Case(
        "003-fig4-15-distance-growth",
        "combined-survey, backstepping, in the USV's turn (window read from the log)",
        f"{D003} fig 4-15 (text: with backstepping 'the relative distance increased while turning (about 25 ~ 30 "
        "seconds)')",
        "largest rise of the backstepping distance in the turn",
        "m",
        None,
        "the backstepping distance grows while turning",
        ("min", 0.02),
        "'increased', no magnitude printed: at least 0.02 m, 4 % of the 0.5 m formation distance and about three "
        "times its swing on the straight leg before the turn (note). The window is our USV's own turn (leg switch "
        "until the yaw rate is back under 20 % of its peak), not 003's 25-30 s",
        growth,
        deviation=_DEV_GROWTH,
        kind="prediction",
        qualitative=True,
    ),
    Case("003-fig4-6-square", "waypoints-square", f"{D003} fig 4-6", *_COUNT, 4.0, "all four", *_ALL, square, **_PRED),
    Case(
        "003-ch6.2-field-waypoints",
        _FIELD,
        f"{D003} ch. 6.2, fig 6-13",
        *_COUNT,
        5.0,
        "the route was completed",
        *_ALL,
        field_waypoints,
        **_PRED,
    ),
    Case(
        "003-ch6.2-field-leg-time",
        _FIELD,
        f"{D003} ch. 6.2, fig 6-15 (text: the UUV's roll 'changed instantaneously at about 40 seconds, 78 seconds, "
        "and 117 seconds in the section where the way-point changed')",
        "mean time between the USV's waypoint switches (legs 2 and 3, 50 m each)",
        "s",
        38.5,
        "(117 - 40) / 2 = 38.5 s",
        ("abs", 2.0),
        "each printed time is 'about' a whole second (±1 s on the mean of the two intervals), plus 1 s for reading "
        "003's roll change against our leg switch; a difference of switch times cancels the unprinted acceptance "
        "radius and the start from rest. Nothing is fitted to it",
        field_leg_time,
        deviation=_DEV_FIELD_LEGS,
        **_PRED,
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
        deviation=_DEV_FIELD_DEPTH,
        kind="calibration",
        basis="one of the three numbers the bridle's apex height (cable.bridle.apex_z = -1.25 m) and formation target "
        "(formation.l_d = 0.4 m) are fitted to by least squares (docs/validation/bridle_fit.py); the cable's length "
        "(1.692 m) hangs the UUV at 003's initial 3 m",
    ),
    Case(
        "003-ch6.2-field-pitch",
        _FIELD,
        f"{D003} ch. 6.2",
        "UUV pitch while moving",
        "deg",
        None,
        "-2 to -4 deg",
        ("range", -6.0, 0.0),
        "the printed range widened by 2 deg (issue 27): a median over four legs and three turns of a pitch that "
        "swings by 2-4 deg",
        field_pitch,
        kind="calibration",
        basis="the bridle's apex height cable.bridle.apex_z = -1.25 m and the formation target formation.l_d = 0.4 m, "
        "fitted by least squares to this range, 003's depth (fig 6-17) and its 0.8 m distance (ch. 6.1.2) at once "
        "(docs/validation/bridle_fit.py; 003 prints neither); the single point gives -36 deg",
    ),
    Case(
        "physics-bridle-pitch-stiffness",
        "the three-point bridle (003 fig 5-6) at the combined-survey tension",
        f"{D003} fig 5-6 (the bridle), eq. 2.33 (M = r x F): for a junction fixed in the body -dM/dtheta = r_A . F_b",
        "pitch stiffness of the attachment about the CB",
        "N m/rad",
        None,
        "r_A . F_b (rigid apex)",
        ("rel", 0.02),
        "the wires stretch (EA 0.7 MN on 1 m: the junction moves ~0.1 mm under 140 N), which softens the bridle by "
        "under 0.1 %; 2 % would catch a wrong moment arm or sign",
        bridle_stiffness,
        kind="analytic",
        basis="the rigid-apex formula, against the model's moment (uuv_deriv) with the junction solved",
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
        kind="calibration",
        basis="the AHRS lag tau = 1 s and magnetic disturbance sigma_m = 2 deg, T_m = 30 s, chosen against these "
        "statistics (sensors/ahrs.py)",
    ),
)
