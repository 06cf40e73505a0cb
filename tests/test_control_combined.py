"""USV/UUV loops of 003 ch. 3.3 (eq. 3.10-3.13) and the re-derived backstepping controller (3.24-3.39)."""

import math

import numpy as np
import pytest
from scipy.integrate import solve_ivp

from oceangnc.control.backstepping import BacksteppingConfig, model_from_uuv
from oceangnc.control.usv_control import USVControlConfig, USVController
from oceangnc.control.uuv_control import UUVPIDConfig, UUVPIDController
from oceangnc.core.clock import Simulation
from oceangnc.models.usv import USVConfig, USVPlant, USVThrusters
from oceangnc.models.uuv import UUVConfig
from oceangnc.units import KGF
from oceangnc.validation.physics import backstepping_lyapunov


class _Log:
    def __init__(self):
        self.rows = []

    def append(self, t, row):
        self.rows.append((t, row))


def _usv_sim(ctl, cfg):
    return Simulation([USVPlant(cfg)], [ctl, USVThrusters(cfg, ctl.period)], 0.01, 0.5)


def test_usv_mixing_signs_and_heading_priority():
    """Eq. 3.11: T_port = U_speed + U_heading; a target to starboard gives T_port > T_stbd, and with
    a large heading error both thrusters stay inside their limits (heading priority)."""
    cfg = USVConfig()
    ctl = USVController(USVControlConfig(), cfg, u_d=2.0, period=0.05)
    ctl.reset(None)
    bus = {"usv.u": 0.0, "usv.psi": 0.0, "usv.r": 0.0, "guidance.psi_d": math.radians(90)}
    for k in range(40):
        ctl.step(0.05 * k, bus)
    tp, ts = bus["usv.thrust_port_cmd"], bus["usv.thrust_stbd_cmd"]
    hi, lo = cfg.max_thrust_kgf * KGF, -cfg.max_reverse_kgf * KGF
    assert tp > ts
    assert lo - 1e-9 <= ts and tp <= hi + 1e-9
    assert (tp - ts) / 2 == pytest.approx(bus["usv_ctrl.u_heading"])


def test_usv_speed_loop_does_not_wind_up_at_an_unreachable_speed():
    """Target 1.3 m/s (field test) is above the USV's top speed (~0.97 m/s): the thrusters saturate
    for 60 s. The back-calculated integrator stays bounded, so when the target drops to 0.5 m/s the
    speed settles within 15 s without a long saturated overshoot."""
    cfg = USVConfig()
    ctl = USVController(USVControlConfig(), cfg, u_d=1.3, period=0.05)
    sim = _usv_sim(ctl, cfg)
    sim.run(60.0)
    hi = cfg.max_thrust_kgf * KGF
    assert sim.bus["usv.thrust_port"] == pytest.approx(hi)
    assert abs(ctl.speed.integral) < 2.0 * hi  # a plain integrator would hold ki * 0.33 m/s * 60 s ~ 3000 N
    ctl.u_d = 0.5
    log = _Log()
    sim.run(40.0, log=log)
    u = np.array([r["usv.u"] for t, r in log.rows])
    t = np.array([t for t, r in log.rows])
    assert abs(u[t > 75.0] - 0.5).max() < 0.02
    assert u[t > 65.0].min() > 0.4


def test_usv_remote_mode_follows_the_joystick():
    """console.mode = remote: surge 0.5 -> u_d = 0.75 m/s; yaw 0.5 -> r_d = 7.5 deg/s (module mapping)."""
    cfg = USVConfig()
    ctl = USVController(USVControlConfig(), cfg, u_d=0.0, period=0.05)
    sim = _usv_sim(ctl, cfg)
    sim.inject({"console.mode": "remote", "joystick.surge": 0.5, "joystick.yaw": 0.0})
    sim.run(40.0)
    assert sim.bus["usv.u"] == pytest.approx(0.75, abs=0.02)
    sim.inject({"joystick.yaw": 0.5})
    sim.run(30.0)
    assert math.degrees(sim.bus["usv.r"]) == pytest.approx(7.5, rel=0.05)
    sim.inject({"joystick.surge": 5.0, "joystick.yaw": -5.0})  # clipped to +-1
    sim.run(0.05)
    assert sim.bus["usv_ctrl.u_d"] == pytest.approx(1.5)
    assert sim.bus["usv_ctrl.r_d"] == pytest.approx(-math.radians(15.0))


def test_uuv_pid_switches_loops_at_R_and_saturates():
    """Eq. 3.13: equal stern commands; bow on the relative angle inside R, on the LOS outside it;
    outputs limited to the Tecnadyne thrust range."""
    ucfg = UUVConfig()
    ctl = UUVPIDController(UUVPIDConfig(), ucfg, 0.05)
    ctl.reset(None)
    bus = {
        "lf.e_x": 0.2,
        "lf.outside": 0.0,
        "lf.rel_heading_err": 0.1,
        "lf.los_err": -0.5,
        "lf.los": 1.0,
        "usv.psi": 0.3,
        "usv.r": 0.0,
        "uuv.r": 0.0,
    }  # every declared input is on the bus
    ctl.step(0.0, bus)
    assert bus["uuv.thrust_port_cmd"] == bus["uuv.thrust_stbd_cmd"] > 0
    assert bus["uuv.thrust_bow_cmd"] > 0 and bus["uuv_ctrl.loop"] == 2 and bus["uuv_ctrl.psi_d"] == 0.3
    bus["lf.outside"] = 1.0
    ctl.step(0.05, bus)
    assert bus["uuv.thrust_bow_cmd"] < 0 and bus["uuv_ctrl.loop"] == 3 and bus["uuv_ctrl.psi_d"] == 1.0
    bus["lf.e_x"] = 100.0
    for k in range(200):
        ctl.step(0.1 + 0.05 * k, bus)
    hi = ucfg.max_thrust_kgf * KGF
    assert bus["uuv.thrust_port_cmd"] == pytest.approx(hi)
    assert ctl.pos.integral < hi  # back-calculation holds the integrator near the limit
    bus["lf.e_x"] = -100.0
    ctl.step(20.0, bus)
    ctl.step(20.05, bus)
    assert bus["uuv.thrust_port_cmd"] == pytest.approx(-ucfg.max_reverse_kgf * KGF)


@pytest.mark.parametrize("s0", [[0, 0, 0, -2.0, 1.5, 0.5, 0, 0, 0], [0, 0, 1.0, 1.0, -1.0, -0.8, 0.3, 0.1, -0.2]])
def test_backstepping_lyapunov_function_decreases(s0):
    """Along closed-loop trajectories of the 3-DOF model (eq. 3.32) behind a manoeuvring leader, V = V1 + V3 + V4
    (eq. 3.28, 3.37) logged every 10 ms never rises: its finite-difference derivative stays below the
    differences' truncation error, agrees with the re-derived dV/dt = -k1 eps1^2 - k2 eps2^2 - k6 u_e^2 - k7 r_e^2,
    and V -> 0. With a plant 20 % off the controller's model the formula no longer describes the run."""
    run = backstepping_lyapunov(s0)  # the validation suite's closed loop (solve_ivp, rtol 1e-9)
    V, Vd, num = run["V"], run["Vdot"], run["Vdot_num"]
    inner = slice(2, -2)  # the end samples use one-sided differences
    peak = np.abs(Vd).max()
    assert run["trunc_max"] < 1e-6 * peak  # the differences are accurate enough for the checks below
    assert num[inner].max() <= 1e-6 * peak
    assert np.abs(num - Vd)[inner].max() < 1e-6 * peak
    assert V[-1] < 1e-6 * V[0]
    bad = backstepping_lyapunov(s0, plant_over={"drag_scale": 1.2})
    assert np.abs(bad["Vdot_num"] - bad["Vdot"])[inner].max() > 1e-2 * peak


def _straight_leader_run(m, g, s0, ul=0.6, t_end=80.0):
    import oceangnc.control.backstepping as bs

    cx = -0.5 + g.h

    def rhs(t, s):
        xl, yl, psil, xf, yf, psif, u, v, r = s
        e1, e2, ep = bs.errors(xl, yl, psil, xf, yf, psif, cx, 0.0, g.h)
        o = bs.control_law(m, g, e1, e2, ep, u, v, r, ul, 0.0, 0.0, cx=cx)
        du, dv, dr = m.accel(u, v, r, o["tau_u"], o["tau_r"])
        return [
            ul,
            0.0,
            0.0,
            u * math.cos(psif) - v * math.sin(psif),
            u * math.sin(psif) + v * math.cos(psif),
            r,
            du,
            dv,
            dr,
        ]

    return solve_ivp(rhs, (0.0, t_end), s0, rtol=1e-9, atol=1e-11).y[:, -1]


def test_backstepping_aligns_the_heading_with_the_printed_model():
    """Zero dynamics with the printed eq. 3.32 (bow thrust a pure moment): behind a leader going
    straight, e_psi -> 0 (the 2 k3 sin^2(e_psi/2) term of eq. 3.35 decays) and the UUV's centre
    ends l^d = 0.5 m astern."""
    import dataclasses

    g = BacksteppingConfig()
    m = dataclasses.replace(model_from_uuv(UUVConfig()), sway_from_bow=0.0)
    xl, yl, psil, xf, yf, psif, u, v, r = _straight_leader_run(m, g, [0, 0, 0, -1.0, 1.0, 0.7, 0, 0, 0])
    assert abs(psif) < 1e-3
    assert xf - xl == pytest.approx(-0.5, abs=1e-3) and yf == pytest.approx(0.0, abs=1e-3)


def test_backstepping_crab_angle_with_a_bow_side_force_matches_the_zero_dynamics():
    """With the bow thruster's side force (as in the plant) the zero dynamics has a crabbing
    equilibrium: v = U sin e, r = 0, and sway + yaw balance give B_f d22(v) = (m22 - m11) U cos e
    (derivation in docs/combined-vehicle.md); the position errors still vanish."""
    g = BacksteppingConfig()
    m = model_from_uuv(UUVConfig())
    U = 0.6
    xl, yl, psil, xf, yf, psif, u, v, r = _straight_leader_run(
        m, g, [0, 0, 0, -1.0, 1.0, 0.7, 0, 0, 0], ul=U, t_end=150.0
    )
    e = psil - psif
    assert abs(r) < 1e-6
    assert v == pytest.approx(U * math.sin(e), abs=1e-5)
    assert m.bow_arm * m.d22(v) == pytest.approx((m.m22 - m.m11) * U * math.cos(e), rel=1e-4)
    ch = math.cos(psif) * g.h
    sh = math.sin(psif) * g.h
    assert xf + ch - xl == pytest.approx(-0.5 + g.h, abs=1e-4) and yf + sh == pytest.approx(0.0, abs=1e-4)
