"""Sanity of the low-speed S-175 ship model (001 eq. 1-25, Son & Nomoto 1981 coefficients)."""

import math

import numpy as np
import pytest
from scipy.integrate import quad

from oceangnc.models.ship_lowspeed import P, ShipConfig, crossflow_integrals, propeller_thrust, ship_rhs, simulate_open
from oceangnc.scenarios.berthing import speed_per_rps

L = 175.0


def test_published_mass_matches_displacement():
    """Son & Nomoto's m' = 0.00792 (on rho/2 L^3) is the displacement 21 222 m^3 of sea water (0.1 %)."""
    cfg = ShipConfig()
    assert 0.00792 * 0.5 * cfg.rho * L**3 == pytest.approx(cfg.mass, rel=1e-3)


@pytest.mark.parametrize("a,b", [(0.3, 0.0), (0.3, 0.002), (-0.2, 0.01), (0.0, -0.004), (1.0, 1e-9), (0.05, 0.03)])
def test_crossflow_closed_form_equals_quadrature(a, b):
    """The closed-form cross-flow integrals of 001 eq. 8, 9 equal numerical quadrature."""
    i0, i1 = crossflow_integrals(a, b, L)
    f0 = lambda x: (a + b * x) * abs(a + b * x)  # noqa: E731
    q0 = quad(f0, -L / 2, L / 2, points=[-a / b] if b != 0 and abs(a / b) < L / 2 else None, limit=200)[0]
    q1 = quad(
        lambda x: x * f0(x), -L / 2, L / 2, points=[-a / b] if b != 0 and abs(a / b) < L / 2 else None, limit=200
    )[0]
    scale0 = L * max(a * a, (b * L / 2) ** 2, 1e-30)
    assert i0 == pytest.approx(q0, abs=1e-9 * scale0)
    assert i1 == pytest.approx(q1, abs=1e-9 * scale0 * L)


def test_steady_speed_proportional_to_rpm():
    """Straight ahead, resistance ~ u^2 and thrust ~ n^2 K_T(J): the steady speed is k n (k analytic)."""
    cfg = ShipConfig()
    k = speed_per_rps(cfg)
    for rpm in (6.0, 30.0):
        n = rpm / 60
        h = simulate_open(cfg, 8000.0, (0.0, n, 0.0, 0.0), dt=2.0, x0=[0, 0, 0, k * n * 0.97, 0, 0, 0, n, 0, 0])
        assert h[-1, 3] == pytest.approx(k * n, rel=5e-3)
    # 1.3 kn needs only a few rpm: the low-speed regime of the berthing trials
    assert 0.5 < 60 * (1.3 * 0.5144) / k < 10


def test_turning_circle_within_imo_criteria():
    """35 deg rudder from 100 rpm (~20 kn): advance < 4.5 L and tactical diameter < 5 L (IMO MSC.137(76)),
    and a tight but not spinning turn (tactical diameter > 2.5 L, speed loss 50-80 %)."""
    cfg = ShipConfig()
    n = 100 / 60
    u0 = speed_per_rps(cfg) * n
    h = simulate_open(cfg, 1500.0, (math.radians(35), n, 0, 0), dt=0.2, x0=[0, 0, 0, u0, 0, 0, 0, n, 0, 0])
    psi = h[:, 2]
    advance = h[np.argmax(psi > math.pi / 2), 0]
    tactical = h[np.argmax(psi > math.pi), 1]
    assert advance < 4.5 * L
    assert 2.5 * L < tactical < 5 * L
    speed_ratio = math.hypot(h[-1, 3], h[-1, 4]) / u0
    assert 0.2 < speed_ratio < 0.5
    assert h[-1, 5] > 0  # positive rudder turns to starboard


def test_crash_stop_track_reach():
    """Full astern from 10 m/s: the ship stops within 15 L (IMO MSC.137(76) track reach)."""
    cfg = ShipConfig()
    n0 = 10.0 / speed_per_rps(cfg)
    h = simulate_open(cfg, 1500.0, (0.0, -cfg.n_max_rpm / 60, 0, 0), dt=0.5, x0=[0, 0, 0, 10.0, 0, 0, 0, n0, 0, 0])
    k = int(np.argmax(h[:, 3] < 0.0))
    assert k > 0
    reach = np.sum(np.hypot(np.diff(h[: k + 1, 0]), np.diff(h[: k + 1, 1])))
    assert L < reach < 15 * L


def test_pure_sway_with_both_thrusters():
    """Bow and stern thrusters pushing the same way (400 kN): steady sway where thrust balances the
    broadside cross-flow drag rho/2 T C_D L v^2 (001 eq. 8 with r = 0), little heading change."""
    cfg = ShipConfig()
    nt = cfg.thruster_rpm_max / 60
    h = simulate_open(cfg, 400.0, (0.0, 0.0, nt, nt), dt=0.5)
    v_expected = math.sqrt(2 * cfg.thruster_force_kn * 1e3 / (0.5 * cfg.rho * cfg.draft * cfg.c_d * L))
    assert h[-1, 4] == pytest.approx(v_expected, rel=0.02)
    assert abs(h[-1, 3]) < 0.02
    assert abs(math.degrees(h[-1, 2])) < 10.0


def test_opposite_thrusters_turn_on_the_spot():
    """n_S = -n_B: pure yaw moment, the ship turns to starboard on the spot (hardly any sway)."""
    cfg = ShipConfig()
    nt = cfg.thruster_rpm_max / 60
    h = simulate_open(cfg, 600.0, (0.0, 0.0, nt, -nt), dt=0.5)
    assert h[-1, 5] > 0
    assert math.degrees(h[-1, 2]) > 60
    assert math.hypot(h[-1, 0], h[-1, 1]) < 0.1 * L


def test_current_enters_through_relative_velocity():
    """Galilean invariance (Fossen 2011 Prop. 8.1): a ship moving with the water feels no hydrodynamic
    force, and the accelerations depend on the velocity through the water only (no wind)."""
    cfg = ShipConfig(area_front=1e-9, area_side=1e-9)
    p = cfg.params()
    assert propeller_thrust(0.0, 0.5, p) == 0.0
    psi = math.radians(30.0)
    cn, ce = 0.3, 0.2
    uc = math.cos(psi) * cn + math.sin(psi) * ce
    vc = -math.sin(psi) * cn + math.cos(psi) * ce
    out = np.zeros(10)
    ship_rhs(0.0, np.array([0, 0, psi, uc, vc, 0, 0, 0, 0, 0.0]), np.array([0, 0, 0, 0, cn, ce, 0, 0.0]), p, out)
    assert out[0] == pytest.approx(cn) and out[1] == pytest.approx(ce)
    assert np.allclose(out[3:6], [0.0, 0.0, 0.0], atol=1e-12)
    # same relative motion, with and without current: same body accelerations (plus the frame terms)
    rel = np.array([0.8, -0.1, 0.002])
    a_still = np.zeros(10)
    ship_rhs(0.0, np.array([0, 0, psi, *rel, 0.1, 0.5, 1.0, -1.0]), np.zeros(8), p, a_still)
    a_cur = np.zeros(10)
    x = np.array([0, 0, psi, rel[0] + uc, rel[1] + vc, rel[2], 0.1, 0.5, 1.0, -1.0])
    ship_rhs(0.0, x, np.array([0, 0, 0, 0, cn, ce, 0, 0.0]), p, a_cur)
    r = rel[2]
    assert a_cur[3] == pytest.approx(a_still[3] + r * vc, rel=1e-9, abs=1e-12)
    assert a_cur[4] == pytest.approx(a_still[4] - r * uc, rel=1e-9, abs=1e-12)
    assert a_cur[5] == pytest.approx(a_still[5], rel=1e-9, abs=1e-15)


def test_actuator_limits_and_lags():
    """Commands beyond the limits are clipped; the rudder respects its rate limit (2.32 deg/s)."""
    cfg = ShipConfig()
    p = cfg.params()
    out = np.zeros(10)
    x = np.zeros(10)
    ship_rhs(0.0, x, np.array([2.0, 100.0, 100.0, -100.0, 0, 0, 0, 0]), p, out)
    assert out[6] == pytest.approx(p[P["delta_rate"]])
    assert out[7] == pytest.approx(p[P["n_max"]] / p[P["tau_p"]])
    assert out[8] == pytest.approx(p[P["nB_max"]] / p[P["tau_tb"]])
    assert out[9] == pytest.approx(-p[P["nS_max"]] / p[P["tau_ts"]])
