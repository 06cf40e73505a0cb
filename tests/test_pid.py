"""Anti-windup PID (003 eq. 3.10)."""

import math

import pytest

from oceangnc.control.pid import PID


def _run_plant(pid, t_end, sat_phase=None, dt=0.01):
    """First-order plant y' = -y + u, setpoint 1; returns (history of integral, y)."""
    y = 0.0
    integ = []
    t = 0.0
    while t < t_end:
        u = pid.step(1.0 - y, dt)
        y += dt * (-y + u)
        integ.append(pid.integral)
        t += dt
    return integ, y


def test_integral_action_removes_steady_error():
    pid = PID(kp=2.0, ki=1.0)
    _, y = _run_plant(pid, 30.0)
    assert y == pytest.approx(1.0, abs=1e-3)


def test_back_calculation_stops_windup_under_saturation():
    """With the output saturated at 0.5 (< setpoint 1) a plain PI integrator grows without bound;
    with back-calculation (003 eq. 3.10) it settles where e + K_w (u - v) = 0."""
    plain = PID(kp=2.0, ki=1.0, u_min=-0.5, u_max=0.5, kw=0.0)
    aw = PID(kp=2.0, ki=1.0, u_min=-0.5, u_max=0.5)
    i_plain, _ = _run_plant(plain, 60.0)
    i_aw, y = _run_plant(aw, 60.0)
    assert i_plain[-1] > 25.0  # winds up: ~ K_i * e * t
    # equilibrium of the integrator: e + kw*(u - v) = 0 with u = 0.5, v = kp*e + I
    e = 1.0 - y
    i_expected = (e / aw.kw) + aw.u_max - aw.kp * e
    assert i_aw[-1] == pytest.approx(i_expected, rel=1e-3)
    assert aw.kw == pytest.approx(1.0 / aw.kp)


def test_recovery_after_saturation_is_faster_with_anti_windup():
    """After a long saturated phase the setpoint drops; the wound-up PI overshoots far longer."""

    def settle_time(kw):
        pid = PID(kp=2.0, ki=1.0, u_min=-0.5, u_max=0.5, kw=kw)
        y, dt = 0.0, 0.01
        for _ in range(6000):
            u = pid.step(1.0 - y, dt)
            y += dt * (-y + u)
        t = 0.0
        while abs(0.2 - y) > 0.02 or t < 0.5:
            u = pid.step(0.2 - y, dt)
            y += dt * (-y + u)
            t += dt
            if t > 200:
                return math.inf
        return t

    assert settle_time(None) < 0.2 * settle_time(0.0)


def test_output_limits_validated():
    with pytest.raises(ValueError, match="u_min"):
        PID(1.0, u_min=1.0, u_max=0.0)
