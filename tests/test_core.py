"""Simulation core: rotations, RK4 order, the multi-rate clock and zero-order hold."""

import math

import numpy as np
import pytest
from numba import njit

from oceangnc.core.blocks import Block, FunctionBlock, Plant
from oceangnc.core.clock import Simulation
from oceangnc.core.integrators import euler_advance, rk4_advance, rk4_workspace
from oceangnc.core.rotations import euler_from_rotation, rot2, rot3, rzyx, skew, tzyx, wrap
from oceangnc.errors import ConfigError, DivergenceError

RNG = np.random.default_rng(1)


@pytest.mark.parametrize("angles", [RNG.uniform(-1.4, 1.4, 3) for _ in range(5)])
def test_rzyx_is_a_rotation_and_inverts(angles):
    R = rzyx(*angles)
    assert np.allclose(R.T @ R, np.eye(3), atol=1e-14)
    assert np.linalg.det(R) == pytest.approx(1.0, abs=1e-14)
    assert np.allclose(euler_from_rotation(R), angles, atol=1e-12)


def test_planar_rotations_agree_with_6dof_at_zero_roll_pitch():
    psi = 0.7
    assert np.allclose(rzyx(0.0, 0.0, psi)[:2, :2], rot2(psi))
    assert np.allclose(rot3(psi)[:2, :2], rot2(psi))
    # a body-forward velocity at heading 90 deg moves east in NED
    assert np.allclose(rot2(math.pi / 2) @ [1.0, 0.0], [0.0, 1.0], atol=1e-15)


@pytest.mark.parametrize("seed", range(4))
def test_euler_rate_transform_matches_rotation_kinematics(seed):
    """R_dot = R S(omega) when Theta_dot = T(Theta) omega (Fossen 2011 eq. 2.28-2.29)."""
    g = np.random.default_rng(seed)
    th = g.uniform(-1.0, 1.0, 3)
    w = g.uniform(-1.0, 1.0, 3)
    h = 1e-6
    th_dot = tzyx(th[0], th[1]) @ w
    r_dot = (rzyx(*(th + h * th_dot)) - rzyx(*(th - h * th_dot))) / (2 * h)
    assert np.allclose(r_dot, rzyx(*th) @ skew(w), atol=1e-8)


def test_wrap_range():
    for a in [-10.0, -math.pi, -1.0, 0.0, math.pi, 3 * math.pi, 7.5]:
        w = wrap(a)
        assert -math.pi < w <= math.pi
        assert math.isclose(math.cos(w), math.cos(a), abs_tol=1e-12)
    assert wrap(-math.pi) == math.pi


@njit(cache=True)
def _oscillator(t, x, u, p, out):
    out[0] = x[1]
    out[1] = -p[0] * p[0] * x[0] + u[0]


def _error(advance, dt):
    x = np.array([1.0, 0.0])
    w = 2.0
    n = int(round(2.0 / dt))
    advance(_oscillator, 0.0, x, np.zeros(1), np.array([w]), dt, n, rk4_workspace(2))
    return abs(x[0] - math.cos(w * 2.0))


def test_rk4_is_fourth_order():
    """Harmonic oscillator, exact x(t) = cos(w t): halving dt divides the error by 2^4."""
    errs = [_error(rk4_advance, dt) for dt in (0.04, 0.02, 0.01)]
    orders = [math.log2(errs[i] / errs[i + 1]) for i in range(2)]
    assert all(3.8 < o < 4.2 for o in orders), orders


def test_euler_is_first_order_by_contrast():
    errs = [_error(euler_advance, dt) for dt in (0.002, 0.001)]
    assert 0.8 < math.log2(errs[0] / errs[1]) < 1.2


@njit(cache=True)
def _integrator_rhs(t, x, u, p, out):
    out[0] = u[0]


class _Counter(Block):
    def __init__(self, name, period):
        self.name = name
        self.period = period
        self.times = []

    def step(self, t, bus):
        self.times.append(t)


def test_clock_fires_each_block_at_its_period():
    blocks = [_Counter("fast", 0.01), _Counter("mid", 0.05), _Counter("slow", 0.1)]
    plant = Plant("p", _integrator_rhs, [0.0], [0.0], ["x"], ["u"], input_defaults={"u": 0.0})
    sim = Simulation([plant], blocks, dt=0.001, log_period=0.02)
    sim.run(1.0)
    for b, n in zip(blocks, (101, 21, 11)):
        assert len(b.times) == n
        assert np.allclose(np.diff(b.times), b.period)
    assert sim.tick == 10  # gcd of 10, 50, 100 and 20 physics steps


def test_clock_chunked_run_fires_each_tick_once():
    b = _Counter("c", 0.1)
    plant = Plant("p", _integrator_rhs, [0.0], [0.0], ["x"], ["u"], input_defaults={"u": 0.0})
    sim = Simulation([plant], [b], dt=0.01, log_period=0.1)
    for _ in range(10):
        sim.run(0.1)
    assert len(b.times) == 11
    assert np.allclose(b.times, np.arange(11) * 0.1)


def test_zero_order_hold_between_firings():
    """x' = u with u set to the firing time every 0.1 s: x(1) = sum of the held steps, 0.45 (not 0.5)."""
    plant = Plant("p", _integrator_rhs, [0.0], [0.0], ["x"], ["u"], input_defaults={"u": 0.0})
    blk = FunctionBlock("ramp", 0.1, lambda t, bus: bus.__setitem__("u", t))
    sim = Simulation([plant], [blk], dt=0.001, log_period=0.1)
    sim.run(1.0)
    assert plant.x[0] == pytest.approx(0.45, abs=1e-12)


def test_period_not_multiple_of_dt_is_refused():
    with pytest.raises(ConfigError, match=r"sim.dt = 0.001: block .odd. runs every 0.0155 s, which must be a whole"):
        Simulation([], [_Counter("odd", 0.0155)], dt=0.001, log_period=0.1)


def test_step_above_plant_limit_is_refused():
    plant = Plant("p", _integrator_rhs, [0.0], [0.0], ["x"], ["u"], max_dt=0.0005)
    with pytest.raises(ConfigError, match="stability limit"):
        Simulation([plant], [], dt=0.001, log_period=0.1)


@njit(cache=True)
def _blowup(t, x, u, p, out):
    out[0] = x[0] * x[0]


def test_divergence_reports_time_block_and_state():
    """x' = x^2, x(0) = 1 blows up at t = 1."""
    plant = Plant("rocket", _blowup, [1.0], [0.0], ["x"], [])
    sim = Simulation([plant], [], dt=0.001, log_period=0.1)
    with pytest.raises(DivergenceError) as ei:
        sim.run(2.0)
    e = ei.value
    assert e.block == "rocket"
    assert 0.95 < e.t < 1.05
    assert "rocket.x" in e.state
    assert "diverged at t=" in str(e)
