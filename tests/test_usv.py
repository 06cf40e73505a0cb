"""USV of 003 ch. 2.1: published open-loop figures 2-7 to 2-10, thrust curve 2.5, wind and current."""

import math

import numpy as np
import pyarrow.parquet as pq
import pytest

import oceangnc
from oceangnc.models.actuators import (
    USV_T_FWD_KGF,
    USV_T_REV_KGF,
    USV_V_REV_FULL,
    usv_thrust_from_voltage,
    usv_voltage_from_thrust,
)
from oceangnc.models.usv import USVConfig, calibrate, steady_turn
from oceangnc.units import KGF


def _run(name, tmp_path, **over):
    return oceangnc.run(name, overrides=over, out=tmp_path / name, plots=False).summary


def test_turning_circle_fig_2_8(tmp_path):
    """003 fig 2-8: 30 kgf port / 15 kgf starboard: radius about 1.75 m (+-0.2) at about 16 deg/s (+-2)."""
    s = _run("usv-turn", tmp_path)
    assert s["usv.turn_radius_m"] == pytest.approx(1.75, abs=0.2)
    assert s["usv.yaw_rate_degps"] == pytest.approx(16.0, abs=2.0)
    assert s["usv.drift_speed_mps"] < 1e-3  # calm water: the circle stays put


@pytest.mark.parametrize("wind_from", [0.0, 90.0])
def test_turning_circle_drifts_downwind_fig_2_9(tmp_path, wind_from):
    """003 fig 2-9: 1 m/s wind from 0 and 90 deg: the circle drifts downwind (within 45 deg) and
    faster in stronger wind."""
    s1 = _run("usv-turn-wind", tmp_path, **{"environment.wind.direction_deg": wind_from})
    s5 = _run(
        "usv-turn-wind", tmp_path / "5", **{"environment.wind.direction_deg": wind_from, "environment.wind.speed": 5.0}
    )
    downwind = (wind_from + 180.0) % 360.0
    for s in (s1, s5):
        diff = (s["usv.drift_direction_deg"] - downwind + 180.0) % 360.0 - 180.0
        assert abs(diff) < 45.0
    assert s5["usv.drift_speed_mps"] > 5 * s1["usv.drift_speed_mps"]


def test_calibration_defaults_match_calibrate():
    """The defaults in USVConfig are the rounded output of calibrate() (docs/parameters.md)."""
    c = calibrate()
    d = USVConfig()
    for k, v in c.items():
        assert getattr(d, k) == pytest.approx(v, rel=2e-3), k


def test_steady_state_is_an_equilibrium():
    u, v, r = steady_turn(USVConfig(), 30 * KGF, 15 * KGF)
    assert math.hypot(u, v) / r == pytest.approx(1.75, abs=0.01)
    assert v < 0  # drift angle outward of the turn (bow inside), as for ships


def test_thrust_curve_dead_zone_and_end_values():
    """003 eq. 2.5 with the dead zone 1.6-3.2 V and the printed end values imposed."""
    assert usv_thrust_from_voltage(2.4) == 0.0
    assert usv_thrust_from_voltage(1.6) == 0.0 and usv_thrust_from_voltage(3.2) == 0.0
    assert usv_thrust_from_voltage(4.68) == pytest.approx(USV_T_FWD_KGF * KGF)
    assert usv_thrust_from_voltage(0.05) == pytest.approx(USV_T_REV_KGF * KGF)
    assert usv_thrust_from_voltage(5.0) == usv_thrust_from_voltage(4.68)  # saturation
    v = np.linspace(3.2, 4.68, 200)
    assert np.all(np.diff([usv_thrust_from_voltage(x) for x in v]) > 0)
    v = np.linspace(USV_V_REV_FULL, 1.6, 200)
    assert np.all(np.diff([usv_thrust_from_voltage(x) for x in v]) > 0)
    # below the polynomial's minimum (0.0629 V) the reverse thrust is held at full reverse
    assert usv_thrust_from_voltage(0.055) == pytest.approx(USV_T_REV_KGF * KGF)
    assert 0.06 < USV_V_REV_FULL < 0.066


@pytest.mark.parametrize("t_kgf", [-10.0, -1.0, 0.5, 12.0, 25.0])
def test_thrust_curve_inverse(t_kgf):
    assert usv_thrust_from_voltage(usv_voltage_from_thrust(t_kgf * KGF)) == pytest.approx(t_kgf * KGF, abs=1e-6)


def test_voltage_mode_drives_the_boat(tmp_path):
    s = _run(
        "usv-straight", tmp_path, **{"command.mode": "voltage", "command.volt_port": 4.68, "command.volt_stbd": 4.68}
    )
    # 29.12 kgf each instead of 30: speed scales linearly with thrust in this linear-damping model
    assert s["usv.steady_speed_mps"] == pytest.approx(0.8 * 29.12 / 30.0, rel=0.01)


def test_same_seed_identical_log_different_seed_differs(tmp_path):
    over = {
        "environment.current.model": "gauss-markov",
        "environment.current.speed": 0.2,
        "environment.current.sigma_speed": 0.05,
        "environment.wind.speed": 3.0,
        "environment.wind.gust_sigma": 1.0,
        "sim.duration": 20.0,
    }
    a = oceangnc.run("usv-turn", overrides=over, out=tmp_path / "a", plots=False)
    b = oceangnc.run("usv-turn", overrides=over, out=tmp_path / "b", plots=False)
    c = oceangnc.run("usv-turn", overrides={**over, "sim.seed": 7}, out=tmp_path / "c", plots=False)
    assert a.log.equals(b.log)
    assert not a.log.equals(c.log)


def test_diverging_run_keeps_log_and_reports(tmp_path):
    """A surge mass of 0.1 kg makes the surge mode too stiff for RK4 at 1 ms: the run must stop."""
    with pytest.raises(oceangnc.DivergenceError) as ei:
        oceangnc.run("usv-straight", overrides={"usv.m11": 0.1}, out=tmp_path / "d", plots=False)
    assert ei.value.block == "usv"
    log = pq.read_table(tmp_path / "d" / "log.parquet")
    assert log.num_rows >= 1 and "usv.u" in log.column_names
    import json

    s = json.loads((tmp_path / "d" / "summary.json").read_text())
    assert s["status"] == "diverged" and "usv" in s["error"]
