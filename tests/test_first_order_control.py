"""Pole-placed autopilots (000 eq. 22-31), LOS / hybrid guidance (000 table 1) and their scenarios."""

import math
import warnings

import numpy as np
import pytest

import oceangnc
from oceangnc.control.pole_placement import heading_gains, predicted_overshoot, speed_gain
from oceangnc.errors import ConfigError
from oceangnc.guidance.los import (
    BAND_LOS,
    BAND_PERPENDICULAR,
    BAND_R1,
    BAND_R2,
    conventional_los,
    distance_to_polyline,
    hybrid_los,
)


def _run(name, tmp_path, **over):
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        return oceangnc.run(name, overrides=over, plots=False, out=tmp_path / name)


@pytest.mark.parametrize("K, T, zeta, wn", [(0.65, 1.71, 0.7, 0.6), (0.62, 1.3, 0.5, 1.0), (0.003, 3.6, 1.0, 2.0)])
def test_heading_gains_place_the_poles(K, T, zeta, wn):
    """T s^2 + (1 + K K1) s + K K1 K2 has the roots of s^2 + 2 zeta wn s + wn^2 (000 eq. 24-27)."""
    k1, k2 = heading_gains(K, T, zeta, wn)
    got = np.sort_complex(np.roots([T, 1 + K * k1, K * k1 * k2]))
    want = np.sort_complex(np.roots([1, 2 * zeta * wn, wn * wn]))
    assert np.allclose(got, want)
    # speed loop (30)-(31): pole at -(1 + K K1)/T = -2 zeta wn
    assert (1 + K * speed_gain(K, T, zeta, wn)) / T == pytest.approx(2 * zeta * wn)


def test_gains_refused_when_2_zeta_wn_T_not_above_1(tmp_path):
    with pytest.raises(ConfigError, match="2 zeta w_n T"):
        heading_gains(0.65, 1.71, 0.7, 0.3)
    with pytest.raises(ConfigError, match=r"heading.wn = 0.3 .*2 zeta w_n T = 0.8"):
        oceangnc.run("autopilot-heading", overrides={"heading.wn": 0.3}, plots=False, out=tmp_path)


@pytest.mark.parametrize("zeta", [0.7, 0.5])
def test_heading_overshoot_is_what_zeta_predicts(tmp_path, zeta):
    """Issue 6: the pole-placed heading loop on the first-order model overshoots exp(-pi zeta/sqrt(1-zeta^2))
    within 2 percentage points (10 deg step, rudder not saturated, 20 Hz discrete controller)."""
    r = _run("autopilot-heading", tmp_path, **{"command.heading_deg": 10.0, "heading.zeta": zeta, "heading.wn": 0.8})
    s = r.summary
    assert s["heading.rudder_saturated_frac"] == 0.0
    assert s["heading.overshoot_pct"] == pytest.approx(100 * predicted_overshoot(zeta), abs=2.0)


def test_heading_100_deg_converges(tmp_path):
    """000 fig. 17: 0 -> 100 deg converges (the rudder saturates at first)."""
    s = _run("autopilot-heading", tmp_path).summary
    assert abs(s["heading.final_error_deg"]) < 0.1
    assert s["heading.settling_time_s"] < 20.0
    assert s["heading.rudder_saturated_frac"] > 0.0


def test_speed_p_loop_leaves_the_predicted_steady_error(tmp_path):
    """000 fig. 18 / eq. 30: 0 -> 5 m/s approaches the command with steady error ~ v_c / (2 zeta wn T_v)."""
    s = _run("autopilot-speed", tmp_path).summary
    assert 0.0 < s["speed.steady_error_mps"] < 0.5
    assert s["speed.steady_error_mps"] == pytest.approx(s["speed.predicted_steady_error_mps"], rel=0.1)
    assert 0.5 < s["speed.rise_time_s"] < 10.0


def test_los_geometry_and_bands():
    """Leg north from (0,0) to (100,0); vessel at east offset e (starboard +)."""
    R, R1, R2 = 20.0, 25.0, 50.0
    # on the line: steer along it
    assert conventional_los(10, 0, 0, 0, 100, 0, R) == pytest.approx(0.0)
    # 10 m to starboard: circle meets the line sqrt(400 - 100) ahead
    assert conventional_los(10, 10, 0, 0, 100, 0, R) == pytest.approx(math.atan2(-10, math.sqrt(300)))
    # circle misses the line: conventional LOS steers at the waypoint
    assert conventional_los(10, 30, 0, 0, 100, 0, R) == pytest.approx(math.atan2(-30, 90))
    psi, band = hybrid_los(10, 50, 0, 0, 100, 0, R, R1, R2)
    assert band == BAND_PERPENDICULAR and psi == pytest.approx(-math.pi / 2)  # straight at the foot
    psi, band = hybrid_los(10, 30, 0, 0, 100, 0, R, R1, R2)
    assert band == BAND_R2 and psi == pytest.approx(math.atan2(-30, math.sqrt(R2**2 - 900)))
    psi, band = hybrid_los(10, -15, 0, 0, 100, 0, R, R1, R2)
    assert band == BAND_R1 and psi == pytest.approx(math.atan2(15, math.sqrt(R1**2 - 225)))
    assert hybrid_los(10, 5, 0, 0, 100, 0, R, R1, R2)[1] == BAND_LOS


def test_distance_to_polyline():
    d = distance_to_polyline([5, 15, -3], [3, 4, 0], [0, 10, 10], [0, 0, 10])
    assert d == pytest.approx([3.0, 5.0, 3.0])


def test_waypoints_7_joins_the_first_leg_at_a_right_angle(tmp_path):
    """000 fig. 21: from heading 90 deg at rest, far from leg 1-2, the USV heads straight at the leg
    (perpendicular) and is on it, aligned, before waypoint 1; then passes all waypoints."""
    r = _run("usv-waypoints-7", tmp_path)
    df = r.df
    s = r.summary
    wp = np.array(r.config.waypoints)
    assert s["usv.final_leg"] == len(wp) - 1
    far = df[df["guidance.d"] > 2 * r.config.guidance.R]
    assert np.degrees(far["usv.psi_cmd"]).to_numpy() == pytest.approx(90.0, abs=1e-6)
    on = df[(df["guidance.leg"] == 1) & (df["guidance.d"] < 1.0)]
    assert on["usv.x"].iloc[0] < wp[0, 0]  # aligned on the leg before reaching waypoint 1
    assert s["usv.path_error_rms_m"] < 3.0


def test_hybrid_guidance_beats_conventional_los_on_the_uuv_plan(tmp_path):
    """Issue 6 / 000 figs. 25-26: the towed UUV's path error (rms and max) is smaller with the hybrid guidance."""
    los = _run("uuv-profile-plan", tmp_path / "los", **{"guidance.mode": "los"}).summary
    hyb = _run("uuv-profile-plan", tmp_path / "hyb", **{"guidance.mode": "hybrid"}).summary
    assert hyb["uuv.path_error_rms_m"] < los["uuv.path_error_rms_m"]
    assert hyb["uuv.path_error_max_m"] < los["uuv.path_error_max_m"]
    # and the UUV does follow its plan with the hybrid law (a few metres in the half turns)
    assert hyb["uuv.path_error_max_m"] < 5.0
