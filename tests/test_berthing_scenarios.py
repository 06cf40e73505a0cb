"""berthing-channel and berthing-dock scenarios (001 sec. 4, figs 6-10)."""

import math

import numpy as np
import pytest

import oceangnc
from oceangnc.api import resolve_config
from oceangnc.errors import ConfigError
from oceangnc.guidance.scripted_pilot import ScriptedPilot

SHORT = {"channel.leg1_m": 400.0, "channel.leg2_m": 300.0, "channel.leg3_m": 400.0}


def test_external_pilot_live_simulation_and_geometry():
    """pilot.kind = external: no scripted pilot; the console's joystick.* keys drive the ship."""
    sc, cfg = resolve_config("berthing-dock", overrides={"pilot.kind": "external", "control.mode": "pid"})
    sim = sc.build(cfg, np.random.default_rng(0))
    assert not any(isinstance(b, ScriptedPilot) for b in sim.blocks)
    sim.inject({"joystick.surge": 0.8, "joystick.yaw": 0.5})
    u0 = sim.bus["ship.u"]
    sim.run(90.0)
    b = sim.bus
    for k in (
        "ship.x",
        "ship.y",
        "ship.psi",
        "ship.u",
        "ship.v",
        "ship.r",
        "ship.rudder",
        "ship.rpm_prop",
        "ship.rpm_bow",
        "ship.rpm_stern",
    ):
        assert k in b and math.isfinite(b[k])
    assert b["ship.u"] > u0 + 0.05  # surge stick ahead speeds the ship up
    assert b["ship.r"] > 0.0  # yaw stick to starboard turns it to starboard
    # emergency stop: every actuator command goes to zero and the shaft/thrusters spin down
    sim.inject({"_estop": True})
    sim.run(30.0)
    b = sim.bus
    assert b["ship.rudder_cmd"] == 0.0 and b["ship.n_prop_cmd"] == 0.0
    assert b["ship.n_bow_cmd"] == 0.0 and b["ship.n_stern_cmd"] == 0.0
    assert abs(b["ship.rpm_bow"]) < 0.01 * 250 and abs(b["ship.rpm_prop"]) < 1.0
    g = sc.geometry(cfg)
    assert g["berth"] == [0.0, 0.0] and len(g["quay"]) == 2 and len(g["route"]) == 3
    _, ccfg = resolve_config("berthing-channel")
    gc = oceangnc.api.get_scenario("berthing-channel").geometry(ccfg)
    banks = np.array(gc["banks"])
    assert banks.shape == (2, 4, 2)
    # banks are half a width from the centre line on the straight legs
    assert abs(banks[0, 0, 1] - banks[1, 0, 1]) == pytest.approx(ccfg.channel.width_m)


def test_bad_config_is_one_line_error():
    with pytest.raises(ConfigError, match="control.mode"):
        resolve_config("berthing-channel", overrides={"control.mode": "fuzzy"})
    with pytest.raises(ConfigError, match="pilot.kind"):
        resolve_config("berthing-dock", overrides={"pilot.kind": "robot"})


@pytest.mark.slow
@pytest.mark.parametrize("mode", ["open", "pid", "nonlinear"])
def test_dock_berths_with_every_controller(mode, tmp_path):
    """The scripted pilot stops the ship within 5 m of the berth at under 0.1 m/s (issue 8)."""
    r = oceangnc.run("berthing-dock", overrides={"control.mode": mode}, out=tmp_path, plots=False)
    s = r.summary
    assert s["final_distance_m"] < 5.0
    assert s["final_speed_mps"] < 0.1
    assert s["final_heading_error_deg"] < 5.0


@pytest.fixture(scope="module")
def channel_runs(tmp_path_factory):
    out = {}
    for mode in ("open", "pid", "nonlinear"):
        d = tmp_path_factory.mktemp(mode)
        out[mode] = oceangnc.run(
            "berthing-channel", overrides={**SHORT, "runs": 2, "control.mode": mode}, out=d, plots=False
        )
    return out


@pytest.mark.slow
def test_closed_loop_beats_open_loop(channel_runs):
    """001 figs 8-10: PID and nonlinear beat the open loop on the error index (44) and on the rudder
    and bow thruster indices (43); without disturbances PID and nonlinear are close (within 30 %)."""
    s = {m: r.summary for m, r in channel_runs.items()}
    for m in ("pid", "nonlinear"):
        assert s[m]["error_index"] < s["open"]["error_index"]
        assert s[m]["rudder_index"] < s["open"]["rudder_index"]
        assert s[m]["bow_thruster_index"] < s["open"]["bow_thruster_index"]
        assert s[m]["min_channel_margin_m"] > 0
    a, b = s["pid"]["error_index"], s["nonlinear"]["error_index"]
    assert abs(a - b) < 0.3 * max(a, b)
    df = channel_runs["pid"].df
    assert sorted(df["run"].unique()) == [0.0, 1.0]
    assert 1.0 < s["pid"]["mean_speed_kn"] < 1.6


STEADY = {
    "environment.current.speed": 0.2,
    "environment.current.direction_deg": 270.0,
    "environment.wind.speed": 10.0,
    "environment.wind.direction_deg": 90.0,
}


@pytest.fixture(scope="module")
def disturbed_runs(tmp_path_factory):
    """PID and nonlinear, 2 runs each on the short channel, steady 0.2 m/s cross current, 10 m/s beam wind."""
    out = {}
    for mode in ("pid", "nonlinear"):
        d = tmp_path_factory.mktemp("dist-" + mode)
        out[mode] = oceangnc.run(
            "berthing-channel", overrides={**STEADY, **SHORT, "runs": 2, "control.mode": mode}, out=d, plots=False
        )
    return out


@pytest.mark.slow
def test_nonlinear_tracks_commands_better_in_current_and_wind(disturbed_runs):
    """With a steady cross current and wind the model-based controller keeps the joystick's yaw-rate
    and speed commands far more closely than the PID (rms errors at least halved; for the nonlinear
    controller the error is to its setpoint-filtered command, see docs/berthing.md)."""
    rms = {}
    for mode, r in disturbed_runs.items():
        df = r.df
        rms[mode] = (float(np.sqrt(np.mean(df["ctrl.e_r"] ** 2))), float(np.sqrt(np.mean(df["ctrl.e_u"] ** 2))))
    assert rms["nonlinear"][0] < 0.5 * rms["pid"][0]
    assert rms["nonlinear"][1] < 0.5 * rms["pid"][1]


GUSTY = {
    "environment.current.speed": 0.2,
    "environment.current.direction_deg": 270.0,
    "environment.wind.speed": 15.0,
    "environment.wind.direction_deg": 45.0,
    "environment.wind.gust_sigma": 4.0,
    "environment.wind.gust_time_constant": 10.0,
}


@pytest.mark.slow
@pytest.mark.parametrize("env", ["steady", "gusty"])
def test_nonlinear_error_index_lower_in_current_and_wind(env, disturbed_runs, tmp_path):
    """001 sec. 4.1 (the paper's expectation, shown here): in current and wind the nonlinear controller's
    error index (44) is lower than the PID's in every run (the runs share their seeds, so the pilot's
    perception errors are the same for both). ``steady``: 0.2 m/s cross current, 10 m/s beam wind;
    ``gusty``: the same current, 15 m/s wind from 045 deg with 4 m/s gusts (10 s), whose yaw moment the
    PID integrators must chase. Measured 2026-11-23 on the full channel, 5 runs x 2 seed sets: 2.0 %
    (steady) and 4.5 % (gusty) lower, in all 10 paired runs each (docs/berthing.md)."""
    if env == "steady":
        runs = disturbed_runs
    else:
        runs = {
            m: oceangnc.run(
                "berthing-channel",
                overrides={**GUSTY, **SHORT, "runs": 2, "control.mode": m},
                out=tmp_path / m,
                plots=False,
            )
            for m in ("pid", "nonlinear")
        }
    pid, nl = runs["pid"].summary, runs["nonlinear"].summary
    assert nl["runs_completed"] == 2 and pid["runs_completed"] == 2
    for a, b in zip(nl["error_index_runs"], pid["error_index_runs"]):
        assert a < b
    assert nl["error_index"] < 0.99 * pid["error_index"]
    assert nl["min_channel_margin_m"] > 0 and pid["min_channel_margin_m"] > 0
