"""Issue 41: physically meaningless set-ups are refused in one line naming the key, exit 2, nothing run.

Each was accepted and simulated on the code at the issue's filing: a thruster 5 m off a 1 m hull, an ROV
on the surface craft's route, a sea steeper than any sea can be (Hs 1 m at Tp 0.6 s)."""

from __future__ import annotations

import pytest

from oceangnc.cli import main
from oceangnc.core.config import validate
from oceangnc.environment.waves import WaveConfig
from oceangnc.errors import ConfigError
from test_vehicle_thrust import box_rov_text


def _refused(args, capsys) -> str:
    capsys.readouterr()
    assert main(args) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1
    return err


def test_a_thruster_off_the_hull_is_refused(tmp_path, capsys):
    f = tmp_path / "far.toml"
    f.write_text(box_rov_text().replace("position = [-0.4, -0.3, 0.0]", "position = [5.5, -0.3, 0.0]", 1))
    err = _refused(["run", "rov-station-keeping", "--set", f"vehicle={f}", "--out", str(tmp_path / "r")], capsys)
    assert "thrusters[0].position ('left')" in err and "length = 1 m" in err
    assert not (tmp_path / "r").exists()


def test_an_rov_on_the_surface_route_and_a_boat_at_depth_are_refused(tmp_path, capsys):
    err = _refused(["run", "otter-waypoints", "--set", "vehicle=bluerov2-heavy", "--out", str(tmp_path / "a")], capsys)
    assert "vehicle: 'bluerov2-heavy' is a vehicle of kind = 'underwater'" in err and "kind = 'surface'" in err
    err = _refused(["run", "rov-station-keeping", "--set", "vehicle=otter", "--out", str(tmp_path / "b")], capsys)
    assert "vehicle: 'otter'" in err and "kind = 'underwater'" in err


def test_a_sea_steeper_than_the_breaking_limit_is_refused(tmp_path, capsys):
    args = ["run", "tow-sea-state", "--set", "environment.waves.hs=1", "--set", "environment.waves.tp=0.6"]
    err = _refused([*args, "--out", str(tmp_path / "s")], capsys)
    assert "environment.waves" in err and "DNV-RP-C205" in err and "tp >= 3.1 s" in err


@pytest.mark.parametrize("kind", ["jonswap", "pierson-moskowitz"])
def test_the_steepness_limit_is_dnvs_on_both_sides_of_it(kind):
    """S_p = 2 pi Hs/(g Tp^2) <= 1/15 up to Tp 8 s, 1/25 from 15 s (DNV-RP-C205 sec. 3.5.5): the shortest
    Tp of a 1 m sea is 3.10 s; at Tp 11.5 s (1/18.75, linear between) the largest Hs is 11.0 m (10.8 m at
    11.4 s); at Tp 20 s (1/25) 24.97 m, above the 20 m the config allows, so 19.9 m passes there."""
    cases = [(1.0, 3.11, True), (1.0, 3.09, False), (10.9, 11.5, True), (10.9, 11.4, False), (19.9, 20.0, True)]
    cases += [(19.9, 16.0, False), (0.1, 0.9, False), (0.1, 1.0, True)]
    for hs, tp, ok in cases:
        if ok:
            validate(WaveConfig, {"kind": kind, "hs": hs, "tp": tp})
        else:
            with pytest.raises(ConfigError, match="DNV-RP-C205"):
                validate(WaveConfig, {"kind": kind, "hs": hs, "tp": tp})


def test_a_regular_wave_above_miches_limit_is_refused():
    """H / lambda <= 0.142 tanh(k h): a 6 s deep-water wave (lambda 56.2 m) breaks above H = 7.98 m."""
    validate(WaveConfig, {"kind": "regular", "hs": 7.9, "tp": 6.0})
    with pytest.raises(ConfigError, match="Miche"):
        validate(WaveConfig, {"kind": "regular", "hs": 8.1, "tp": 6.0})
    validate(WaveConfig, {"kind": "none", "hs": 1.0, "tp": 0.6})  # no waves: hs and tp unused


def test_a_last_waypoint_narrower_than_the_turning_circle_is_refused(tmp_path, capsys):
    """guidance.acceptance 0.1 m < the USV's 0.36 m minimum turning radius: on the code at the issue's filing
    the USV circled the last waypoint (0,0) (20,0) (19,4) for all 300 s, status ok; now refused."""
    args = ["run", "combined-survey", "--set", "guidance.acceptance=0.1", "--out", str(tmp_path / "c")]
    err = _refused(args, capsys)
    assert "guidance.acceptance: 0.1 m is below the USV's minimum turning radius 0.363 m" in err
    assert not (tmp_path / "c").exists()
