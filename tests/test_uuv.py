"""UUV of 003 ch. 2.2: 6-DOF Fossen model with scaled REMUS-100 coefficients, thrusters, turning radius."""

import math

import numpy as np
import pytest

from oceangnc.api import resolve_config
from oceangnc.core.integrators import rk4_advance, rk4_workspace
from oceangnc.errors import ConfigError
from oceangnc.models.uuv import (
    P_MA,
    P_MINV,
    P_MRB,
    UUVConfig,
    UUVThrusters,
    scaled_coefficients,
    uuv_energy,
    uuv_min_turning_radius,
    uuv_rhs,
)
from oceangnc.units import KGF


def _run(cfg: UUVConfig, u, t_end, dt=0.01, x0=None):
    p = cfg.params()
    x = cfg.initial_state() if x0 is None else np.array(x0, float)
    w = rk4_workspace(12)
    rk4_advance(uuv_rhs, 0.0, x, np.asarray(u, float), p, dt, int(round(t_end / dt)), w)
    return x, p


def test_surge_steady_speed_matches_drag_coefficients():
    """A constant surge force F gives the speed solving X_u U + X_u|u| U|U| + F = 0 (within 0.5 %).

    Neutrally buoyant here so that the surge balance is isolated (the default UUV sinks).
    """
    cfg = UUVConfig(weight_in_water_kgf=0.0)
    for force in (5.0, 20.0, 60.0):
        x, _ = _run(cfg, [force / 2, force / 2, 0.0, 0.0, 0.0], 120.0)
        a, b = -cfg.X_uu_total, -cfg.X_u
        u_pred = (-b + math.sqrt(b * b + 4 * a * force)) / (2 * a)
        assert x[6] == pytest.approx(u_pred, rel=5e-3)
        assert abs(x[7]) < 1e-6 and abs(x[11]) < 1e-6  # straight: no sway, no yaw


def test_surge_speed_in_current_is_relative_to_the_water():
    """In a current the same thrust gives the same speed through the water (ground speed = U + V_c)."""
    cfg = UUVConfig(weight_in_water_kgf=0.0)
    x0, _ = _run(cfg, [10.0, 10.0, 0.0, 0.0, 0.0], 120.0)
    x1, _ = _run(cfg, [10.0, 10.0, 0.0, 0.3, 0.0], 120.0)
    assert x1[6] - 0.3 == pytest.approx(x0[6], rel=5e-3)


def test_ideal_fluid_conserves_energy():
    """With damping off, the Kirchhoff form of C_RB + C_A does no work and the restoring forces are
    conservative: 1/2 nu^T M nu - W z_G + B z_B stays constant (RK4 at 5 ms: drift < 1e-6 relative).

    Neutrally buoyant: with 12 kgf net weight and no damping the vehicle would free-fall without
    bound. The pendulum (CG below CB) still exchanges energy between roll/pitch and motion.
    """
    cfg = UUVConfig(damping_on=False, weight_in_water_kgf=0.0)
    x0 = cfg.initial_state()
    x0[6:12] = [0.8, 0.3, -0.2, 0.2, 0.1, -0.2]
    x0[3:5] = [0.2, -0.1]
    p = cfg.params()
    e0 = uuv_energy(x0, p)
    x, _ = _run(cfg, [0, 0, 0, 0, 0], 20.0, dt=0.005, x0=x0)
    e1 = uuv_energy(x, p)
    scale = 0.5 * x0[6:12] @ (p[P_MRB : P_MRB + 36].reshape(6, 6) + p[P_MA : P_MA + 36].reshape(6, 6)) @ x0[6:12]
    assert abs(e1 - e0) < 1e-6 * scale + 1e-9
    assert np.linalg.norm(x[6:12] - x0[6:12]) > 0.05  # it did move (energy exchanged between modes)


def test_damping_only_dissipates():
    """With damping and lift on, the energy decreases monotonically from an arbitrary motion."""
    cfg = UUVConfig()
    p = cfg.params()
    x = cfg.initial_state()
    x[6:12] = [1.0, 0.4, -0.3, 0.8, 0.2, -0.5]
    w = rk4_workspace(12)
    e_prev = uuv_energy(x, p)
    u = np.zeros(5)
    t = 0.0
    for _ in range(400):
        t = rk4_advance(uuv_rhs, t, x, u, p, 0.005, 5, w)
        e = uuv_energy(x, p)
        assert e <= e_prev + 1e-9
        e_prev = e


def test_lift_terms_are_dissipative():
    """The body/fin lift terms (Prestero minus the Munk parts) form negative-definite quadratic forms."""
    lf = UUVConfig().lift_coefficients()
    for a, b, c, d in (("Y_uv", "Y_ur", "N_uv", "N_ur"), ("Z_uw", "Z_uq", "M_uw", "M_uq")):
        A = np.array([[lf[a], 0.5 * (lf[b] + lf[c])], [0.5 * (lf[b] + lf[c]), lf[d]]])
        assert np.all(np.linalg.eigvalsh(A) < 0)


def test_scaling_reproduces_prestero_at_remus_size():
    """At REMUS-100 size (1.33 m x 0.191 m) the scaled coefficients are Prestero's (2001) values."""
    c = scaled_coefficients(1.33, 0.191)
    assert c["Y_vdot"] == pytest.approx(-35.5)
    assert c["N_rr"] == pytest.approx(-94.0)
    assert c["X_uu"] == pytest.approx(-1.62)
    c2 = scaled_coefficients(2 * 1.33, 0.191)
    assert c2["N_rdot"] == pytest.approx(-4.88 * 8)  # kg m2 of a slender body ~ L^3


def test_mass_matrix_symmetric_positive_definite():
    """003 A-3 property 1: M = M_RB + M_A > 0 and symmetric; its stored inverse is right."""
    p = UUVConfig().params()
    M = p[P_MRB : P_MRB + 36].reshape(6, 6) + p[P_MA : P_MA + 36].reshape(6, 6)
    assert np.allclose(M, M.T)
    assert np.all(np.linalg.eigvalsh(M) > 0)
    assert np.allclose(p[P_MINV : P_MINV + 36].reshape(6, 6) @ M, np.eye(6), atol=1e-10)


def test_negatively_buoyant_uuv_sinks_level():
    """12 kgf submerged weight (003 table 2-5): the UUV sinks at the heave speed its Z_w, Z_w|w| predict within 2 %
    , nearly level (CG below CB; the fins' Z_qdot, M_w couplings tilt it by well under 1 deg)."""
    x, _ = _run(UUVConfig(), [0, 0, 0, 0, 0], 20.0)
    assert x[8] > 0.3  # sinking at a steady heave speed
    assert abs(x[4]) < math.radians(1.0) and abs(x[3]) < 1e-9
    c = UUVConfig()
    a = -c.coefficients()["Z_ww"]
    b = -c.Z_w
    f = c.weight_in_water_kgf * KGF
    w_pred = (-b + math.sqrt(b * b + 4 * a * f)) / (2 * a)
    assert x[8] == pytest.approx(w_pred, rel=2e-2)


def test_min_turning_radius_matches_simulated_turn():
    """uuv_min_turning_radius (planar steady solve) agrees within 5 % with a circle fitted to the track of
    a full-thrust turn of the 6-DOF model whose roll and pitch are held by a stiff pendulum (z_G = 0.5 m,
    neutrally buoyant), i.e. an independent simulation of the same level turn."""
    from oceangnc.scenarios._common import circle_fit_drifting

    R = uuv_min_turning_radius(UUVConfig())
    cfg = UUVConfig(weight_in_water_kgf=0.0, zg=0.5)
    hi, lo = cfg.max_thrust_kgf * KGF, cfg.max_reverse_kgf * KGF
    x, p = _run(cfg, [hi, -lo, hi, 0.0, 0.0], 100.0)
    w = rk4_workspace(12)
    u = np.array([hi, -lo, hi, 0.0, 0.0])
    track = []
    for k in range(300):
        rk4_advance(uuv_rhs, 0.0, x, u, p, 0.01, 10, w)
        track.append((k * 0.1, x[0], x[1], x[5]))
    t, xs, ys, psi = np.array(track).T
    rad, drift, _, rms = circle_fit_drifting(t, xs, ys, psi)
    assert 0.5 < R < 50
    assert rad == pytest.approx(R, rel=0.05)
    assert abs(x[4]) < math.radians(3) and abs(x[3]) < math.radians(10)  # it did stay nearly level


def test_thruster_block_saturates_and_estops():
    """Commands beyond 7.7 kgf forward / 3.2 kgf reverse are clipped; an emergency stop zeroes all."""
    blk = UUVThrusters(UUVConfig())
    bus = {"uuv.thrust_port_cmd": 200.0, "uuv.thrust_stbd_cmd": -200.0, "uuv.thrust_bow_cmd": 10.0}
    blk.step(0.0, bus)
    assert bus["uuv.thrust_port"] == pytest.approx(7.7 * KGF)
    assert bus["uuv.thrust_stbd"] == pytest.approx(-3.2 * KGF)
    assert bus["uuv.thrust_bow"] == pytest.approx(10.0)
    bus["_estop"] = True
    blk.step(0.01, bus)
    assert bus["uuv.thrust_port"] == bus["uuv.thrust_stbd"] == bus["uuv.thrust_bow"] == 0.0


@pytest.mark.parametrize("key,val", [("uuv.mass", 0.0), ("uuv.length", -1.0), ("uuv.diameter", 0.0)])
def test_bad_uuv_config_is_a_config_error(key, val):
    """Non-positive mass or size is refused with a one-line error naming the key."""
    with pytest.raises(ConfigError, match=key.replace(".", r"\.")):
        resolve_config("cable-current", overrides={key: val})


def test_steady_planar_straight_branch():
    """Equal stern thrusts and no bow thrust: the planar steady state is straight ahead (v = r = 0), at
    the drag-balance speed, although the vehicle is directionally unstable (spiral equilibria exist)."""
    from oceangnc.models.uuv import uuv_steady_planar

    cfg = UUVConfig()
    for T in (2.0, 20.0, 75.0):
        u, v, r = uuv_steady_planar(cfg, T, T, 0.0)
        a, b = -cfg.X_uu_total, -cfg.X_u
        assert u == pytest.approx((-b + math.sqrt(b * b + 8 * a * T)) / (2 * a), rel=1e-6)
        assert v == 0.0 and r == 0.0


def test_turning_circle_drifts_with_the_current():
    """A steady turn in a uniform current (0.2 m/s toward east) is the calm-water turn carried by the
    current: the fitted circle's centre drifts at 0.2 m/s toward 90 deg (within 3 % / 3 deg) and the
    radius is unchanged (1 %). Checks nu_r and the M_A (omega x v_c) term of the current model."""
    from oceangnc.scenarios._common import circle_fit_drifting

    cfg = UUVConfig(weight_in_water_kgf=0.0, zg=0.5)
    hi = cfg.max_thrust_kgf * KGF
    res = []
    for vce in (0.0, 0.2):
        u = np.array([5.0, 5.0, hi, 0.0, vce])
        x, p = _run(cfg, u, 60.0)
        w = rk4_workspace(12)
        track = []
        for k in range(400):
            rk4_advance(uuv_rhs, 0.0, x, u, p, 0.01, 10, w)
            track.append((k * 0.1, x[0], x[1], x[5]))
        t, xs, ys, psi = np.array(track).T
        res.append(circle_fit_drifting(t, xs, ys, psi))
    (r0, d0, _, _), (r1, d1, dir1, _) = res
    assert d0 < 1e-3
    assert d1 == pytest.approx(0.2, rel=0.03)
    assert dir1 == pytest.approx(90.0, abs=3.0)
    assert r1 == pytest.approx(r0, rel=0.01)
