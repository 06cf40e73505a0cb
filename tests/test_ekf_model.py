"""Heave-pitch submarine of document 002 (eq. 2.1-2.5, tables 2.1/4.1/5.2/5.3) and its zig-zags."""

import math

import numpy as np
import pytest

from oceangnc.identification.ekf import model_jacobians, submarine_vertical_model
from oceangnc.identification.maneuvers import parse_maneuver, zigzag
from oceangnc.models.submarine_vertical import (
    COEFF_NAMES,
    P_NAMES,
    SubmarineVerticalConfig,
    default_params,
    dimensional,
    eigenvalues,
    sub_f,
    sub_jac,
)
from oceangnc.errors import ConfigError


def _fd_jacobian(x, p, u):
    """Central finite differences of sub_f with respect to [x, p] (step 1e-6 relative)."""
    y = np.concatenate([x, p])
    J = np.zeros((3, y.size))
    o1 = np.zeros(3)
    o2 = np.zeros(3)
    for k in range(y.size):
        h = 1e-6 * max(abs(y[k]), 1e-3)
        yp = y.copy()
        yp[k] += h
        ym = y.copy()
        ym[k] -= h
        sub_f(yp[:3], yp[3:], u, o1)
        sub_f(ym[:3], ym[3:], u, o2)
        J[:, k] = (o1 - o2) / (2 * h)
    return J


@pytest.mark.parametrize("seed", [0, 1, 2])
def test_analytic_jacobian_matches_finite_differences(seed):
    """d f / d [w, theta, q, all 19 parameters] agrees with central differences to 1e-6 relative."""
    rng = np.random.default_rng(seed)
    p = default_params()
    p[14] = 0.8  # a non-zero x_G exercises its terms
    x = np.array([0.1, 0.15, 0.01]) * rng.uniform(-1, 1, 3)
    u = np.array([math.radians(10.0) * rng.uniform(-1, 1)])
    J = np.zeros((3, 3 + p.size))
    sub_jac(x, p, u, J)
    Jf = _fd_jacobian(x, p, u)
    scale = np.maximum(np.abs(Jf).max(axis=0), 1e-300)
    rel = np.abs(J - Jf).max(axis=0) / scale
    assert rel.max() < 1e-6, dict(zip(["w", "theta", "q", *P_NAMES], rel))


@pytest.mark.parametrize("mode", ["analytic", "complex-step"])
def test_filter_jacobians_match_finite_differences(mode):
    """The filter's own F (analytic or complex step) and H agree with central differences to 1e-6."""
    model = submarine_vertical_model()
    p = model.params
    x = np.array([0.08, -0.12, 0.006])
    u = np.array([math.radians(-10.0)])
    F, H = model_jacobians(model, x, u, list(COEFF_NAMES), jacobian=mode)
    Jf = _fd_jacobian(x, p, u)[:, :13]
    rel = np.abs(F - Jf).max(axis=0) / np.abs(Jf).max(axis=0).clip(1e-300)
    assert rel.max() < 1e-6
    assert np.allclose(H, np.hstack([np.eye(3), np.zeros((3, 10))]), atol=1e-15)


def test_vertical_offset_sign_settles_stability():
    """z_G = +0.27414 m (CG below CB, table 4.1's |Z_theta|): all modes stable; z_G = -0.27414: one unstable."""
    p = default_params()
    assert np.all(eigenvalues(p).real < 0)
    p[P_NAMES.index("zG")] = -0.27414
    assert np.max(eigenvalues(p).real) > 0


def test_munk_moment_sign_and_true_values():
    """True coefficients are 002 tables 5.2/5.3 with M_w' > 0 (destabilising Munk moment)."""
    c = SubmarineVerticalConfig()
    assert c.Mw == pytest.approx(0.004059) and c.Mw > 0
    assert c.Zqdot == pytest.approx(-0.000016) and c.Mds == pytest.approx(-0.003663)
    # W / m = 9.8 m/s^2 exactly (table 4.1)
    assert c.W / c.m == pytest.approx(9.8, rel=1e-12)


def test_table_2_1_scaling():
    """Dimensional coefficients scale as rho/2 L^a U^b of table 2.1 (M_ds with U^2)."""
    p = default_params()
    d1 = dimensional(p)
    p2 = p.copy()
    p2[P_NAMES.index("U")] *= 2.0
    d2 = dimensional(p2)
    assert d2["Mds"] / d1["Mds"] == pytest.approx(4.0)
    assert d2["Zds"] / d1["Zds"] == pytest.approx(4.0)
    assert d2["Mq"] / d1["Mq"] == pytest.approx(2.0)
    assert d2["Mqdot"] / d1["Mqdot"] == pytest.approx(1.0)
    rho, L = 1025.9, 63.955
    assert d1["Iy"] == pytest.approx(0.0006088 * 0.5 * rho * L**5)


def test_zigzag_switching_rule():
    """10-5 zig-zag: the plane is +/-10 deg and reverses only once pitch passed -/+5 deg (bow down first)."""
    c = SubmarineVerticalConfig()
    d = zigzag(c.params(), c.x0(), "10-5", duration=200.0, rate_hz=100.0, dt_truth=1e-3)
    ds_deg = np.degrees(d.ds)
    assert np.allclose(np.abs(ds_deg), 10.0)
    assert ds_deg[0] == pytest.approx(10.0)
    sw = np.nonzero(np.diff(d.ds))[0] + 1
    assert len(sw) == d.n_reversals >= 2
    th = np.degrees(d.x_true[sw, 1])
    for k, i in enumerate(sw):
        before = ds_deg[i - 1]
        # a positive plane pitches the bow down (M_ds' < 0): reversal once theta <= -5 deg, and vice versa
        assert -np.sign(before) * th[k] >= 5.0 - 1e-9
        assert -np.sign(before) * np.degrees(d.x_true[i - 2, 1]) < 5.0
    with pytest.raises(ConfigError):
        parse_maneuver("ten-five")


def test_truth_rk4_converges():
    """The truth integrator converges at 4th order: halving a coarse step cuts the error ~16 times."""
    c = SubmarineVerticalConfig()
    # the modes are slow (~0.01-0.04 1/s), so the steps must be large for the error to show
    kw = dict(duration=40.0, rate_hz=0.25)
    ref = zigzag(c.params(), c.x0(), "10-5", dt_truth=1e-3, **kw).x_true[-1]
    e1 = np.abs(zigzag(c.params(), c.x0(), "10-5", dt_truth=4.0, **kw).x_true[-1] - ref).max()
    e2 = np.abs(zigzag(c.params(), c.x0(), "10-5", dt_truth=2.0, **kw).x_true[-1] - ref).max()
    assert 10 < e1 / e2 < 22


def _equivalent_coefficients(p, g11, g21):
    """Coefficients giving M~ = G M, Theta~ = (G - I) K + G Theta with G = [[g11, 0], [g21, 1]]
    (K = the known terms m U q, -W z_G sin(theta)): the same (w', q') whenever the rigid-body
    coupling terms m z_G q^2 and m z_G w q are absent."""
    d = dimensional(p)
    m, U = p[P_NAMES.index("m")], p[P_NAMES.index("U")]
    new = {
        "Zw": g11 * d["Zw"],
        "Mw": g21 * d["Zw"] + d["Mw"],
        "Zq": g11 * d["Zq"] + (g11 - 1) * m * U,
        "Mq": g21 * (d["Zq"] + m * U) + d["Mq"],
        "Zds": g11 * d["Zds"],
        "Mds": g21 * d["Zds"] + d["Mds"],
        "Zwdot": m - g11 * (m - d["Zwdot"]),
        "Zqdot": g11 * d["Zqdot"],
        "Mwdot": d["Mwdot"] - g21 * (m - d["Zwdot"]),
        "Mqdot": d["Mqdot"] + g21 * d["Zqdot"],
    }
    q = p.copy()
    unit = {k: d[k] / p[i] for i, k in enumerate(COEFF_NAMES)}
    for i, k in enumerate(COEFF_NAMES):
        q[i] = new[k] / unit[k]
    return q


@pytest.mark.parametrize("zG, identifiable", [(0.0, False), (0.27414, True)])
def test_identifiability_rests_on_cg_coupling(zG, identifiable):
    """With W = B the heave equation has no known-coefficient term but m z_G q^2: without it a
    two-parameter family of coefficient sets (G = [[1.1, 0], [0.05, 1]] here, coefficients changed by
    up to 10 %) gives exactly the same motion; with z_G = 0.27414 m the family differs where q != 0."""
    p = default_params()
    p[P_NAMES.index("zG")] = zG
    p2 = _equivalent_coefficients(p, 1.1, 0.05)
    assert np.abs(p2[:10] / p[:10] - 1).max() > 0.05
    rng = np.random.default_rng(3)
    o1, o2 = np.zeros(3), np.zeros(3)
    diff = 0.0
    for _ in range(20):
        x = rng.uniform(-1, 1, 3) * np.array([0.2, 0.2, 0.01])
        u = rng.uniform(-1, 1, 1) * 0.17
        sub_f(x, p, u, o1)
        sub_f(x, p2, u, o2)
        diff = max(diff, np.abs(o2 - o1).max() / np.abs(o1).max())
        x[2] = 0.0  # without pitch rate the coupling terms vanish: always indistinguishable
        sub_f(x, p, u, o1)
        sub_f(x, p2, u, o2)
        assert np.abs(o2 - o1).max() <= 1e-9 * np.abs(o1).max()
    if identifiable:
        assert diff > 1e-5
    else:
        assert diff < 1e-9
