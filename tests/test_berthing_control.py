"""Joystick filter (001 eq. 26), allocation (36-38) and the feedback-linearised loops (27-35)."""

import math

import numpy as np
import pytest

from oceangnc.control.allocation import allocate, cost_nb2, rudder_term, thruster_gain
from oceangnc.control.berthing import ControlConfig, NonlinearController, rps_for_thrust
from oceangnc.control.joystick import Joystick, JoystickConfig, dead_band, recursive_mean, stick_to_command
from oceangnc.core.blocks import FunctionBlock
from oceangnc.core.clock import Simulation
from oceangnc.environment import CurrentConfig, OceanCurrent, Wind, WindConfig
from oceangnc.models.ship_lowspeed import ShipConfig, ShipPlant, inverse_mass, propeller_thrust
from oceangnc.units import KNOT


@pytest.mark.parametrize("n", [1, 2, 7, 100, 1000])
def test_recursive_mean_equals_running_mean(n):
    """001 eq. 26 x_k = x_{k-1} + (z_k - x_{k-1})/k is the arithmetic mean of the samples."""
    z = np.random.default_rng(n).normal(0.3, 0.2, n)
    assert recursive_mean(z) == pytest.approx(float(np.mean(z)), abs=1e-13)


def test_joystick_block_filters_noise_and_scales():
    """100 noisy samples per 100 ms are averaged (noise / 10); dead band and scaling as documented."""
    cfg = JoystickConfig(noise=0.05)
    j = Joystick(cfg)
    j.reset(np.random.default_rng(1))
    vals = []
    for k in range(400):
        bus = {"joystick.surge": 0.5, "joystick.yaw": -1.0}
        j.step(0.1 * k, bus)
        vals.append(bus["joystick.surge_f"])
    assert np.std(vals) == pytest.approx(0.05 / 10, rel=0.15)
    u_d, r_d = stick_to_command(1.0, -1.0, cfg)
    assert u_d == pytest.approx(3.34 * KNOT)
    assert r_d == pytest.approx(-math.radians(0.4))
    assert stick_to_command(0.04, 0.04, cfg) == (0.0, 0.0)
    assert dead_band(0.05 + 0.95 * 0.5, 0.05) == pytest.approx(0.5)
    assert stick_to_command(-1.0, 0.0, cfg)[0] == pytest.approx(-1.5 * KNOT)


def _states():
    rng = np.random.default_rng(7)
    for _ in range(12):
        ur = rng.uniform(0.45, 2.0)
        vr = rng.uniform(-0.3, 0.3)
        r = rng.uniform(-0.004, 0.004)
        n = rng.uniform(-0.3, 1.0)
        yield ur, vr, r, n, rng.uniform(-4e-4, 4e-4)


def test_allocation_optimum_equals_brute_force():
    """Above 0.4 m/s the allocated rudder angle minimises J = n_B^2 (001 eq. 38): equal to a brute-force
    search over 200 001 angles; n_B then satisfies (37) exactly unless saturated."""
    ship = ShipConfig()
    p = ship.params()
    _, _, c, d = inverse_mass(p)
    dmax = math.radians(ship.rudder_max_deg)
    grid = np.linspace(-dmax, dmax, 200001)
    K = thruster_gain(c, d, p)
    for ur, vr, r, n, u_rd in _states():
        delta, nb = allocate(u_rd, ur, vr, r, n, c, d, p, 0.4, 71, -dmax, dmax)
        J = np.array([cost_nb2(g, u_rd, ur, vr, r, n, c, d, p) for g in grid])
        jmin = J.min()
        jal = cost_nb2(delta, u_rd, ur, vr, r, n, c, d, p)
        assert jal <= jmin + 1e-9 * max(1.0, jmin)
        if jmin > 1e-6:  # unique optimum at a rudder stop or interior: same angle
            assert delta == pytest.approx(grid[np.argmin(J)], abs=2e-4)
        if abs(nb) < ship.thruster_rpm_max / 60:
            assert K * nb * abs(nb) + rudder_term(delta, ur, vr, r, n, c, d, p) == pytest.approx(
                u_rd, rel=1e-9, abs=1e-14
            )


def test_allocation_below_switch_speed_uses_thrusters_only():
    """Below 0.4 m/s J = delta^2: the rudder stays amidships and the thrusters give all of u_rd."""
    ship = ShipConfig()
    p = ship.params()
    _, _, c, d = inverse_mass(p)
    delta, nb = allocate(2e-4, 0.3, 0.05, 0.001, 0.5, c, d, p, 0.4, 71, -1.0, 1.0)
    assert delta == 0.0
    K = thruster_gain(c, d, p)
    assert K * nb * abs(nb) + rudder_term(0.0, 0.3, 0.05, 0.001, 0.5, c, d, p) == pytest.approx(2e-4, rel=1e-9)


def test_propeller_inversion():
    """rps_for_thrust inverts X_P(n) of 001 eq. 16 ahead and astern, and saturates at the limit."""
    p = ShipConfig().params()
    for x_pd, ur in [(3e5, 0.7), (-4e5, 0.7), (1e4, 0.0), (-1e5, -0.3)]:
        n = rps_for_thrust(x_pd, ur, p, 2.0)
        assert propeller_thrust(n, ur, p) == pytest.approx(x_pd, rel=1e-8)
    assert rps_for_thrust(1e9, 0.5, p, 1.5) == 1.5


def _nominal_step(current: float):
    """Nonlinear controller on the nominal model with near-ideal actuators; steps in u_d and r_d."""
    ship = ShipConfig(
        tau_prop=0.02, tau_rudder=0.02, tau_thruster=0.02, rudder_rate_degps=100.0, u0=1.0, n0_rpm=60.0 * 1.0 / 6.28
    )
    cc = ControlConfig(mode="nonlinear", period=0.02, t_ref=0.0, lambda1=0.1, lambda2=0.1, rate_aware_rudder=False)
    u_d, r_d = 1.5, math.radians(0.1)

    def cmd(t, bus):
        bus["cmd.u_d"] = u_d
        bus["cmd.r_d"] = r_d

    blocks = [
        OceanCurrent(CurrentConfig(speed=current, direction_deg=120.0), 0.02),
        Wind(WindConfig(speed=8.0 if current else 0.0, direction_deg=200.0), 0.02),
        FunctionBlock("cmd", 0.02, cmd),
        NonlinearController(cc, ship),
    ]
    sim = Simulation([ShipPlant(ship)], blocks, 0.005, 0.02, np.random.default_rng(0))
    ts, eu, er = [], [], []

    class Rec:
        def append(self, t, row):
            ts.append(t)
            eu.append(row["ship.u"] - u_d)
            er.append(row["ship.r"] - r_d)

    sim.run(30.0, log=Rec())
    return np.array(ts), np.array(eu), np.array(er), cc


@pytest.mark.parametrize("current", [0.0, 0.3])
def test_feedback_linearisation_gives_exponential_decay(current):
    """001 eq. 30, 33: with the model exact (and the measured current and wind) the surge and yaw-rate
    errors decay as e(0) exp(-lambda t), here within 3 % of e(0) over 30 s."""
    t, eu, er, cc = _nominal_step(current)
    k0 = 2  # after the first controller update reached the (fast) actuators
    tt = t[k0:] - t[k0]
    ref_u = eu[k0] * np.exp(-cc.lambda1 * tt)
    ref_r = er[k0] * np.exp(-cc.lambda2 * tt)
    assert np.max(np.abs(eu[k0:] - ref_u)) < 0.03 * abs(eu[k0])
    assert np.max(np.abs(er[k0:] - ref_r)) < 0.03 * abs(er[k0])
    assert abs(eu[-1]) < 0.1 * abs(eu[0])
