"""Scenarios of 003 ch. 4 and 6.2 on the compiled USV-cable-UUV plant: waypoints, PID vs backstepping,
sensors, USBL dropout, estop, remote mode, config errors."""

import math

import numpy as np
import pandas as pd
import pytest

import oceangnc
from oceangnc.api import resolve_config
from oceangnc.errors import ConfigError
from oceangnc.scenarios.combined import build_simulation


class _Log:
    def __init__(self):
        self.rows = []

    def append(self, t, row):
        self.rows.append(dict(t=t, **row))


def _run(name, **over):
    sc, cfg = resolve_config(name, overrides=over)
    sim = build_simulation(cfg, np.random.default_rng(cfg.sim.seed))
    log = _Log()
    sim.run(cfg.sim.duration, log=log)
    df = pd.DataFrame(log.rows)
    return sc.summarize(df, cfg), df, sim


@pytest.fixture(scope="module")
def survey():
    return {c: _run("combined-survey", **{"control.uuv": c}) for c in ("pid", "backstepping")}


def test_combined_survey_reaches_all_waypoints_with_both_controllers(survey):
    for c, (s, df, sim) in survey.items():
        assert s["usv.waypoints_reached"] == 3, c
        assert sim.bus["_stop"] and s["t_end_s"] < 60.0
        assert s["usv.cross_track_rms_m"] < 1.5
        assert 2.5 < s["uuv.depth_final_m"] < 3.5  # hangs on its 3 m cable (003: 3 -> ~2.77 m)


def test_backstepping_and_pid_hold_the_same_distance_because_the_cable_tows_the_uuv(survey):
    """003 fig 4-15 says backstepping keeps the relative distance (~0.4 m) and PID does not. The validation
    report documents the deviation (003-fig4-15-bs-beats-pid): in our survey the two are within 1-2 cm,
    because the cable tows the UUV (its stern thrusters give 1-2 N each of 75 N) and the formation target is
    where the towed UUV trails anyway. Both stay inside R (1 m), so neither needs the heading-to-USV loop."""
    pid, bs = survey["pid"][0], survey["backstepping"][0]
    assert abs(pid["uuv.rel_distance_mean_m"] - bs["uuv.rel_distance_mean_m"]) < 0.02
    assert abs(pid["uuv.rel_distance_max_m"] - bs["uuv.rel_distance_max_m"]) < 0.02
    for c, (s, df, _) in survey.items():
        assert s["uuv.rel_distance_max_m"] < 1.0, c
        moving = df["t"] > 5.0
        stern = np.abs(df.loc[moving, ["uuv.thrust_port", "uuv.thrust_stbd"]].to_numpy())
        assert stern.max() < 2.0, c  # N, of 75 N: the cable, not the thrusters, carries the UUV
        assert (df.loc[moving, "lf.outside"] == 0).all(), c
    V = survey["backstepping"][1]["uuv_bs.V"].to_numpy()
    assert np.isfinite(V).all()


def test_waypoints_square_reaches_all_waypoints():
    """003 fig 4-6 (b): relative angle plus heading to the USV; the UUV stays near the USV."""
    s, df, _ = _run("waypoints-square")
    assert s["usv.waypoints_reached"] == 4
    assert s["uuv.rel_distance_max_m"] < 1.5


def test_relative_angle_only_mode_reaches_all_waypoints():
    """003 fig 4-6 (a) mode on the survey route: the bow thruster never switches to the LOS loop."""
    s, df, _ = _run("combined-survey", **{"control.uuv": "pid", "formation.mode": "relative-angle"})
    assert s["usv.waypoints_reached"] == 3
    assert (df["uuv_ctrl.loop"] == 2).all()


@pytest.mark.slow
def test_field_test_with_sensors_reaches_all_waypoints():
    """003 ch. 6.2: (50,0) (50,-50) (0,-50) (0,0) at a 1.3 m/s target with measured signals."""
    s, df, _ = _run("field-test")
    assert s["usv.waypoints_reached"] == 5
    # within the formation target l^d = 1 m plus R = 1 m of the USV, far from the 3 m cable's reach
    assert s["uuv.rel_distance_max_m"] < 2.0
    # the USV cannot make 1.3 m/s (top speed ~0.97 m/s): the speed loop saturates without winding up
    assert df["usv.u"].max() < 1.0
    # AHRS vs GPS-track heading while moving (003: mean 3.53 deg, sd 3.88 deg)
    assert 1.0 < s["ahrs.gps_heading_diff_mean_deg"] < 8.0


def test_usbl_forced_dropout_for_10_s_continues_and_recovers():
    s, df, _ = _run(
        "combined-survey",
        **{
            "control.uuv": "pid",
            "sensors.enabled": True,
            "sensors.usbl.dropout_start": 10.0,
            "sensors.usbl.dropout_duration": 10.0,
        },
    )
    assert s["usv.waypoints_reached"] == 3
    t = df["t"]
    inside = (t >= 10.6) & (t < 20.0)
    assert (df.loc[inside, "nav.usbl.ok"] == 0).all()
    assert df.loc[inside, "nav.usbl.age"].max() > 9.0
    after = t >= 22.0
    assert (df.loc[after, "nav.usbl.ok"] == 1).all()
    err = np.hypot(df["nav.uuv_x"] - df["uuv.x"], df["nav.uuv_y"] - df["uuv.y"])
    assert err[after].max() < 0.5  # estimate back to USBL + GPS accuracy
    assert s["uuv.rel_distance_max_m"] < 1.5


def test_estop_zeroes_every_thruster_and_remote_mode_drives_the_usv():
    sc, cfg = resolve_config("combined-survey")
    sim = build_simulation(cfg, np.random.default_rng(0))
    sim.run(5.0)
    assert sim.bus["usv.thrust_port"] != 0.0
    sim.inject({"_estop": True})
    sim.run(0.1)
    for k in ("usv.thrust_port", "usv.thrust_stbd", "uuv.thrust_port", "uuv.thrust_stbd", "uuv.thrust_bow"):
        assert sim.bus[k] == 0.0
    sim.inject({"_estop": False, "console.mode": "remote", "joystick.surge": 0.0, "joystick.yaw": 0.0})
    sim.run(20.0)
    assert abs(sim.bus["usv.u"]) < 0.1  # stick centred: the USV stops instead of following guidance
    assert sim.bus["usv_ctrl.u_d"] == 0.0


def test_bad_controller_name_is_a_config_error():
    with pytest.raises(ConfigError, match="control.uuv"):
        resolve_config("combined-survey", overrides={"control.uuv": "lqr"})
    with pytest.raises(ConfigError, match="formation.R"):
        resolve_config("combined-survey", overrides={"formation.R": -1.0})
    with pytest.raises(ConfigError, match="guidance.waypoints.*coincide"):
        resolve_config("combined-survey", overrides={"guidance.waypoints": [[0, 0], [0, 0], [5, 5]]})


def test_default_run_is_the_flagship_with_summary_and_plots(tmp_path):
    res = oceangnc.run(out=tmp_path / "run", overrides={"control.uuv": "backstepping"})
    assert res.summary["scenario"] == "combined-survey"
    for k in (
        "usv.waypoints_reached",
        "usv.cross_track_rms_m",
        "uuv.rel_distance_mean_m",
        "uuv.rel_distance_max_m",
        "uuv.depth_final_m",
        "uuv.heading_error_rms_deg",
        "usv.heading_error_rms_deg",
    ):
        assert math.isfinite(res.summary[k]), k
    names = {p.name for p in res.plots}
    assert {"trajectory3d.png", "track.png", "headings.png", "depth_distance.png"} <= names
    assert all(p.stat().st_size > 5000 for p in res.plots)
