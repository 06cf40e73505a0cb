"""The fused loop on the remaining scenarios of ``oceangnc list`` (issue 19): the first-order USV
(autopilots, waypoints, towed trailer), the console USV, berthing in every mode and the inner runs
of the multi-run scenarios give the same log on the fused and the Python path."""

from __future__ import annotations

import warnings

import numpy as np
import pytest

from fused_paths import run_both, run_path, same_log
from oceangnc.api import resolve_config
from oceangnc.io.logs import LogWriter, read_log

#: (scenario, overrides, horizon s) that must run fused with the Python path's log
FUSED_MORE = [
    ("autopilot-heading", {}, 6.0),
    ("autopilot-speed", {}, 6.0),
    ("usv-waypoints-7", {}, 20.0),
    ("usv-waypoints-7", {"guidance.mode": "los"}, 20.0),
    ("uuv-profile-plan", {}, 70.0),  # through several leg switches
    ("uuv-profile-plan", {"guidance.mode": "los"}, 10.0),
    # the console's USV offline: GPS white noise, pure-pursuit route pilot, speed / yaw-rate PIDs
    ("usv-remote", {}, 30.0),
    ("usv-remote", {"guidance.waypoints": [[8.0, 0.0], [8.0, 6.0]], "gps.outages": [[2.0, 4.0]]}, 30.0),
    ("usv-remote", {"pilot.mode": "remote"}, 4.0),
    ("usv-remote", {"pilot.mode": "remote", "pilot.loop": "open"}, 4.0),
]


@pytest.mark.parametrize(
    "name,over,dur", FUSED_MORE, ids=[f"{n}-{'-'.join(map(str, o.values()))}" for n, o, _ in FUSED_MORE]
)
def test_fused_log_equals_python_log(name, over, dur, tmp_path):
    sp, sf, a, b, tp, cfg = run_both(name, over, dur, tmp_path)
    assert len(a) == int(round(tp * cfg.sim.log_rate)) + 1


def test_fused_waypoint_guidance_switches_legs_and_stops_like_python(tmp_path):
    over = {"waypoints": [[0.0, 40.0], [0.0, 120.0], [60.0, 170.0]]}
    sp, tp, a, _ = run_path("usv-waypoints-7", over, 120.0, False, tmp_path)
    sf, tf, b, _ = run_path("usv-waypoints-7", over, 120.0, True, tmp_path)
    assert sf.path == "fused"
    assert tp < 120.0 and tf == tp  # the last waypoint stops both runs at the same tick
    assert set(b["guidance.leg"]) == {1.0, 2.0}
    same_log(a, b)


def _console_session(fused, tmp_path, absent=False):
    """usv-remote driven from outside the loop between runs: stick, mode, loop and e-stop changes
    (``absent``: no console mode or loop on the bus until the console sends one)."""
    sc, cfg = resolve_config("usv-remote", overrides={"pilot.mode": "remote"}, duration=9.0)
    sim = sc.build(cfg, np.random.default_rng(cfg.sim.seed))
    if absent:
        del sim.bus["console.mode"], sim.bus["console.loop"]
    sim.use_fused = fused
    path = tmp_path / f"session-{int(fused)}-{int(absent)}.parquet"
    script = [
        {"joystick.surge": 0.8, "joystick.yaw": 0.0},
        {"joystick.surge": 0.5, "joystick.yaw": -0.6},
        {"console.loop": "open", "joystick.surge": 0.7, "joystick.yaw": 0.4},
        {"_estop": True},
        {"_estop": False, "console.loop": "closed", "console.mode": "auto"},
        {"joystick.surge": -0.5},
    ]
    with LogWriter(path) as log:
        for cmd in script:
            sim.inject(cmd)
            sim.run(1.5, log=log)
    return sim, read_log(path)


@pytest.mark.parametrize("absent", [False, True], ids=["injected", "absent-at-start"])
def test_fused_reads_the_console_signals_between_runs(absent, tmp_path):
    sp, a = _console_session(False, tmp_path, absent)
    sf, b = _console_session(True, tmp_path, absent)
    assert sf.path == "fused"
    same_log(a, b)
    assert sf.bus["console.mode"] == "auto" and sf.bus["console.loop"] == "closed"  # strings stay strings
    # the stick moved the boat, the e-stop zeroed the thrust, the route pilot took over
    t = b["t"].to_numpy()
    assert b["usv.u"].max() > 0.3
    stop = (t > 4.6) & (t < 6.0)
    assert np.all(b["usv.thrust_port"].to_numpy()[stop] == 0.0)
    assert b["usv.u_d"].to_numpy()[(t > 6.1) & (t < 7.5)].max() > 0.0


def test_a_console_route_keeps_the_python_path(tmp_path):
    from oceangnc.core.fused import build_fused

    sc, cfg = resolve_config("usv-remote", duration=1.0)
    sim = sc.build(cfg, np.random.default_rng(0))
    sim.inject({"console.waypoints": ((5.0, 5.0), (10.0, 0.0))})
    sim.run(0.1)
    loop, why = build_fused(sim)
    assert loop is None and why.startswith("signal 'console.waypoints'") and "block 'usv_route'" in why


@pytest.mark.parametrize(
    "name,mode", [("berthing-dock", "open"), ("berthing-dock", "pid"), ("berthing-channel", "pid")]
)
def test_fused_berthing_modes(name, mode, tmp_path):
    over = {"control.mode": mode}
    sp, sf, a, b, tp, cfg = run_both(name, over, 60.0, tmp_path)
    # the controller acted: a propeller command, and the rudder or the thrusters moved
    assert np.abs(b["ship.n_prop_cmd"]).max() > 0.0


@pytest.mark.parametrize("vehicle", ["usv-first-order", "usv-3dof"])
def test_fused_trials_inner_runs(vehicle, tmp_path):
    """Each straight / turning / zig-zag run of ``trials`` (several simulations, one log) fuses, with
    the Python path's log, noise included (the sensors draw from the same generators)."""
    over = {"vehicle": vehicle, "noise.speed_mps": 0.05, "noise.heading_deg": 0.5, "noise.yaw_rate_degps": 0.2}
    sc, cfg = resolve_config("trials", overrides=over)
    kinds = set()
    for i, (kind, val) in enumerate(sc._trial_list(cfg)):
        logs, sims = [], []
        for fused in (False, True):
            with warnings.catch_warnings():
                warnings.simplefilter("ignore", RuntimeWarning)
                sim, dur, _ = sc._build_one(cfg, kind, val, np.random.default_rng(100 + i))
                sim.use_fused = fused
                path = tmp_path / f"{i}-{int(fused)}.parquet"
                with LogWriter(path) as log:
                    sim.run(min(dur, 12.0), log=log)
            logs.append(read_log(path))
            sims.append(sim)
        assert sims[1].path == "fused", (kind, val)
        same_log(*logs)
        kinds.add(kind)
    assert kinds == {"straight", "turn", "zigzag"}
    # the zig-zag's command switched sign within the horizon (the manoeuvre ran, not just the step)
    steer = logs[1]["trial.steer"].to_numpy()
    assert steer.max() > 0.0 and steer.min() < 0.0


def test_a_console_route_sent_to_a_running_fused_loop_is_refused(tmp_path):
    from oceangnc.errors import ConfigError

    sc, cfg = resolve_config("usv-remote", duration=1.0)
    sim = sc.build(cfg, np.random.default_rng(0))
    sim.use_fused = True
    sim.run(0.5)
    assert sim.path == "fused"
    sim.inject({"console.waypoints": ((5.0, 5.0), (10.0, 0.0))})
    with pytest.raises(ConfigError, match="console.waypoints.*use_fused = False"):
        sim.run(0.5)


@pytest.mark.parametrize("fused", [False, True], ids=["python", "fused"])
def test_first_order_range_warning_on_both_paths(fused):
    """Leaving the trial ranges of 000 table 2 during the run warns once, fused or not."""
    over = {"usv.u0": 6.0, "speed_mps": 10.0}  # starts inside, accelerates past the turning range (8.74 m/s)
    sc, cfg = resolve_config("usv-waypoints-7", overrides=over, duration=30.0)
    with warnings.catch_warnings(record=True) as rec:
        warnings.simplefilter("always")
        sim = sc.build(cfg, np.random.default_rng(0))
        assert not rec  # in range at the start
        sim.use_fused = fused
        sim.run(30.0)
    hits = [w for w in rec if "outside the trial ranges" in str(w.message)]
    assert sim.path == ("fused" if fused else "python")
    assert len(hits) == 1 and "speed 8.7" in str(hits[0].message)
