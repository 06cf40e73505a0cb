"""First-order USV (000 table 2, eq. 8/15), towed trailer (000 eq. 2-7) and planning from the UUV (eq. 32-34)."""

import math

import numpy as np
import pytest

from oceangnc.api import resolve_config
from oceangnc.core.blocks import FunctionBlock
from oceangnc.core.clock import Simulation
from oceangnc.errors import ConfigError
from oceangnc.guidance.towed_planning import (
    plan_usv,
    segments_profile,
    table3_profile,
    usv_path_closed_form,
    waypoints_from_plan,
)
from oceangnc.models.first_order import FirstOrderConfig, FirstOrderUSV
from oceangnc.models.towed_trailer import TowedTrailer, simulate_trailer, uuv_position


def test_table2_coefficients_and_clamped_schedule():
    """000 table 2 at 6 m/s; below 4.87 m/s (where T_v would go negative below 1.915 m/s) the laws are held."""
    c = FirstOrderConfig()
    k = c.coefficients(6.0)
    assert k["K_v"] == pytest.approx(0.0004 * 6 + 0.0014)
    assert k["T_v"] == pytest.approx(1.1737 * 6 - 2.2474)
    assert k["K_r"] == pytest.approx(-0.0113 * 6 + 0.7176)
    assert k["T_r"] == pytest.approx(-0.1534 * 6 + 2.6341)
    # the raw law is negative (unstable) at 1 m/s: the model refuses a trial range reaching down there ...
    with pytest.raises(ValueError, match=r"T_v\(1 m/s\) = -1.07"):
        FirstOrderConfig(straight_lo_mps=1.0)
    assert c.coefficients(1.0)["T_v"] == pytest.approx(1.1737 * 4.87 - 2.2474)  # ... and holds the law at 4.87
    assert c.coefficients(30.0)["T_r"] == pytest.approx(-0.1534 * 8.74 + 2.6341)


def test_negative_time_constant_in_range_is_a_config_error():
    with pytest.raises(ConfigError, match="T_v"):
        resolve_config("autopilot-heading", overrides={"usv.tv_intercept": -10.0})


def _run(cfg, rpm, delta, duration, dt=0.01):
    pl = FirstOrderUSV(cfg)

    def cmd(t, bus):
        bus["usv.rpm"] = rpm
        bus["usv.delta_s"] = delta
        bus["usv.u_op"] = 6.0

    sim = Simulation([pl], [FunctionBlock("cmd", 0.05, cmd)], dt, 0.05)
    sim.run(duration)
    return pl


def test_step_response_is_the_first_order_lag():
    """With the operating-speed schedule the plant is exactly T r' + r = K delta: r(t) = K d (1 - exp(-t/T))."""
    cfg = FirstOrderConfig(schedule="operating", u0=6.0)
    k = cfg.coefficients(6.0)
    d = math.radians(10)
    pl = _run(cfg, cfg.trim_rpm(6.0), d, 3.0)
    r_exact = k["K_r"] * d * (1 - math.exp(-3.0 / k["T_r"]))
    assert pl.x[4] == pytest.approx(r_exact, rel=1e-6)
    assert pl.x[3] == pytest.approx(6.0, rel=1e-9)  # trim rpm holds the speed


def test_steady_speed_and_warning_outside_trial_range():
    """Steady u = K_v(u) n; starting from rest (outside 4.87-16.02 m/s) warns once."""
    cfg = FirstOrderConfig(u0=0.0)
    n = cfg.trim_rpm(8.0)
    with pytest.warns(RuntimeWarning, match="outside the trial ranges"):
        pl = _run(cfg, n, 0.0, 400.0, dt=0.05)
    assert pl.x[3] == pytest.approx(8.0, rel=2e-3)


def test_trailer_aligns_on_straight_tow_and_holds_phi_in_a_steady_turn():
    """000 eq. 4/7: straight -> phi -> 0; USV circling at (u, r) -> sin(phi) = -L r / u."""
    L, u, r = 30.0, 5.0, 0.1
    cfg = FirstOrderConfig(schedule="operating", u0=u, r0_degps=math.degrees(r))
    k = cfg.coefficients(u)
    pl = FirstOrderUSV(cfg)
    tr = TowedTrailer(L, psi0=0.5)

    def cmd(t, bus):
        bus["usv.rpm"] = cfg.trim_rpm(u)
        bus["usv.delta_s"] = r / k["K_r"]
        bus["usv.u_op"] = u

    sim = Simulation([pl, tr], [FunctionBlock("cmd", 0.05, cmd)], 0.01, 0.05)
    sim.run(120.0)
    assert sim.bus["uuv.phi"] == pytest.approx(math.asin(-L * r / u), abs=1e-3)
    # distance USV-UUV is the cable length
    assert math.hypot(sim.bus["usv.x"] - sim.bus["uuv.x"], sim.bus["usv.y"] - sim.bus["uuv.y"]) == pytest.approx(L)
    # UUV speed and yaw rate of eq. 3-4
    assert sim.bus["uuv.u"] == pytest.approx(u * math.cos(sim.bus["uuv.phi"]), rel=1e-9)
    assert sim.bus["uuv.r"] == pytest.approx(r, rel=1e-3)


def test_plan_offset_angle_and_speed_match_eq_32_34():
    """Clockwise turn R = 40 m at 4 m/s, L = 30 m: tan(phi_d) = -0.75 -> phi_d = -36.87 deg, u_USV = 5 m/s."""
    plan = plan_usv(table3_profile(), 30.0)
    turn = (plan.t > 55) & (plan.t < 75)
    assert np.degrees(plan.phi[turn]) == pytest.approx(-36.8699, abs=1e-3)
    assert plan.u[turn] == pytest.approx(5.0, abs=1e-9)
    assert np.max(plan.u) == pytest.approx(5.0)


def test_table3_profile_geometry():
    """000 table 3: legs of 200 m at 45 / 225 / 45 deg joined by half turns of radius 40 m, 212.8 s in all."""
    p = table3_profile()
    assert p.t[-1] == pytest.approx(150 + 2 * math.pi * 10, abs=1e-9)
    assert math.degrees(p.psi[-1]) == pytest.approx(45.0)
    # after the first leg and half turn the track is offset 80 m to starboard of the first leg
    i = np.searchsorted(p.t, 50 + math.pi * 10) - 1
    e = -math.sin(math.pi / 4) * p.x[i] + math.cos(math.pi / 4) * p.y[i]
    assert e == pytest.approx(80.0, abs=0.05)


def test_integrated_usv_path_equals_trailer_geometry():
    """Eq. 1 integrated with the planned speed/heading = p_UUV + L e(psi_UUV) (consistency of 32-34)."""
    prof = table3_profile(dt=0.02)
    plan = plan_usv(prof, 30.0)
    xc, yc = usv_path_closed_form(prof, 30.0)
    assert np.max(np.hypot(plan.x - xc, plan.y - yc)) < 0.01


def test_planned_usv_motion_through_trailer_reproduces_uuv_profile():
    """The issue's consistency test: the trailer model driven by the planned USV motion follows the UUV plan."""
    prof = table3_profile(dt=0.02)
    plan = plan_usv(prof, 30.0)
    psi_uuv = simulate_trailer(plan.t, plan.u, plan.psi, 30.0, float(prof.psi[0]), 4)
    ux, uy = uuv_position(plan.x, plan.y, psi_uuv, 30.0)
    assert np.max(np.abs(psi_uuv - prof.psi)) < 1e-3
    assert np.max(np.hypot(ux - prof.x, uy - prof.y)) < 0.02
    # a wrong sign in (32) (the printed asin form without the minus) does not reproduce it
    bad = plan.psi + 2 * plan.phi
    psi_bad = simulate_trailer(plan.t, plan.u, bad, 30.0, float(prof.psi[0]), 4)
    assert np.max(np.abs(psi_bad - prof.psi)) > 0.3


def test_waypoints_keep_corners_and_speeds():
    prof = segments_profile([(10.0, 0.0), (10.0, 0.1)], 4.0, 0.0)
    plan = plan_usv(prof, 20.0)
    wp, sp = waypoints_from_plan(plan, 5.0)
    assert wp.shape[1] == 2 and len(wp) >= 4
    assert sp[0] == pytest.approx(4.0) and sp[-1] == pytest.approx(4.0 / math.cos(math.atan(0.5)))
