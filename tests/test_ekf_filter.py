"""Augmented-state EKF (002 ch. 3, table 3.1): identification of the ten coefficients of 002 and of a
user model, consistency, and bad input."""

import math

import numpy as np
import pytest
from numba import njit

from oceangnc.errors import ConfigError, InputError
from oceangnc.identification.ekf import EKFModel, FilterDivergedError, nees, run_ekf, submarine_vertical_model
from oceangnc.identification.maneuvers import zigzag
from oceangnc.models.submarine_vertical import COEFF_NAMES, TRUE_COEFFS, SubmarineVerticalConfig
from oceangnc.scenarios.ekf_zigzag import EKFZigzagConfig, identify

TRUE = np.array([TRUE_COEFFS[k] for k in COEFF_NAMES])


def _cfg(**over):
    data = {"sim": {"duration": 200.0, "dt": 1e-4}}
    for k, v in over.items():
        data[k] = v
    return EKFZigzagConfig.model_validate(data)


@pytest.mark.parametrize("maneuver", ["5-5", "10-5"])
def test_noise_free_all_ten_within_one_percent(maneuver):
    """Noise-free 200 s at 100 Hz: every coefficient within 1 % of 002 tables 5.2/5.3 (the paper: up to
    3.75 %), starting 20 % off (alternating signs) with P0 = (30 % of the guess)^2."""
    _, res, a0, _ = identify(_cfg(maneuver=maneuver), np.random.default_rng(0))
    assert np.all(np.abs(a0 / TRUE - 1) > 0.19)
    rel = np.abs(res.X[-1, 3:] / TRUE - 1)
    assert rel.max() < 0.01, dict(zip(COEFF_NAMES, rel))


def test_noise_free_from_table_4_1_values():
    """Starting from the truncated values of 002 table 4.1 (Zqdot 37 % off), 10-5: within 1 %."""
    _, res, _, _ = identify(_cfg(maneuver="10-5", filter={"initial_guess": "table4.1"}), np.random.default_rng(0))
    assert np.abs(res.X[-1, 3:] / TRUE - 1).max() < 0.01


@pytest.mark.parametrize("maneuver", ["5-5", "10-5"])
def test_noisy_errors_inside_three_sigma(maneuver):
    """Nominal sensor noise (0.002 m/s, 0.02 deg, 0.005 deg/s): >= 9 of 10 final errors inside 3 sigma,
    and the innovations are white with the predicted size (mean NIS = 3 measurements within 3 %)."""
    _, res, _, _ = identify(_cfg(maneuver=maneuver, noise=1.0), np.random.default_rng(1))
    err = np.abs(res.X[-1, 3:] - TRUE)
    inside = int(np.sum(err <= 3.0 * res.sigma[-1, 3:]))
    assert inside >= 9
    assert np.nanmean(res.nis) == pytest.approx(3.0, rel=0.03)


@pytest.mark.slow
def test_nees_consistent_over_20_seeds():
    """20 noise seeds (10-5, nominal noise, guesses drawn from the prior N(true, (0.2 true)^2)): the mean
    final NEES of the ten coefficients lies in the two-sided 99 % chi-square interval (10 dof)."""
    from scipy.stats import chi2

    c = SubmarineVerticalConfig()
    d = zigzag(c.params(), c.x0(), "10-5")
    model = submarine_vertical_model()
    sd = np.array([0.002, math.radians(0.02), math.radians(0.005)])
    vals = []
    for seed in range(20):
        rng = np.random.default_rng(1000 + seed)
        Z = d.x_true[:, :3] + rng.standard_normal((d.t.size, 3)) * sd
        a0 = TRUE * (1 + 0.2 * rng.standard_normal(10))
        P0 = np.concatenate([(2 * sd) ** 2, (0.2 * TRUE) ** 2])
        Q = np.concatenate([2.5e-5 * sd**2, np.zeros(10)])
        res = run_ekf(model, d.t, Z, d.ds[:, None], COEFF_NAMES, Z[0], a0, P0, Q, sd**2)
        vals.append(nees(res.X[-1, 3:] - TRUE, res.P[3:, 3:]))
    n = 20
    lo, hi = chi2.ppf([0.005, 0.995], 10 * n) / n
    assert lo < np.mean(vals) < hi, (np.mean(vals), lo, hi)


# -- a user model: nonlinear pendulum-spring with unknown stiffness and damping -------------------------


@njit(cache=True)
def osc_f(x, p, u, out):
    """x = [angle, rate]; p = [k, c, J]; J angle'' = u - c rate - k sin(angle)."""
    out[0] = x[1]
    out[1] = (u[0] - p[1] * x[1] - p[0] * np.sin(x[0])) / p[2]


@njit(cache=True)
def osc_h(x, p, out):
    out[0] = x[0]


def _osc_model():
    return EKFModel(
        name="oscillator",
        f=osc_f,
        h=osc_h,
        state_names=("angle", "rate"),
        param_names=("k", "c", "J"),
        input_names=("torque",),
        measurement_names=("angle",),
        params=np.array([2.0, 0.3, 1.0]),
        bound=1e3,
    )


def _osc_data(T=40.0, dt=0.02):
    m = _osc_model()
    t = np.arange(0.0, T + 1e-9, dt)
    U = np.where((t // 5) % 2 == 0, 1.0, -1.0)[:, None]
    x = np.array([0.0, 0.0])
    X = np.zeros((t.size, 2))
    k1, k2, k3, k4 = (np.zeros(2) for _ in range(4))
    n = 20
    h = dt / n
    for i in range(t.size):
        X[i] = x
        for _ in range(n):
            osc_f(x, m.params, U[i], k1)
            osc_f(x + 0.5 * h * k1, m.params, U[i], k2)
            osc_f(x + 0.5 * h * k2, m.params, U[i], k3)
            osc_f(x + h * k3, m.params, U[i], k4)
            x = x + h / 6 * (k1 + 2 * k2 + 2 * k3 + k4)
    return m, t, X, U


@pytest.mark.parametrize("mode", ["complex-step", pytest.param("finite-difference", marks=pytest.mark.slow)])
def test_generic_user_model(mode):
    """Any model f(x, p, u), h(x): the stiffness and damping of a nonlinear oscillator from its angle
    only (rate unmeasured), noise-free, 40 s at 50 Hz, guesses 40 % off: within 0.5 %."""
    m, t, X, U = _osc_data()
    res = run_ekf(
        m,
        t,
        X[:, :1],
        U,
        "k,c",
        [0.0, 0.0],
        [1.2, 0.42],
        [1e-6, 1e-2, 1.0, 0.1],
        [1e-10, 1e-10, 0.0, 0.0],
        [1e-8],
        jacobian=mode,
    )
    est = res.X[-1, 2:]
    assert np.abs(est / np.array([2.0, 0.3]) - 1).max() < 5e-3


# -- bad input -------------------------------------------------------------------------------------------


def _small_problem():
    c = SubmarineVerticalConfig()
    d = zigzag(c.params(), c.x0(), "10-5", duration=5.0, dt_truth=1e-3)
    sd = np.array([0.002, 3e-4, 1e-4])
    return submarine_vertical_model(), d, sd


def test_unknown_parameter_name():
    m, d, sd = _small_problem()
    with pytest.raises(InputError, match="unknown parameter.*Zfoo"):
        run_ekf(m, d.t, d.z_meas, d.ds[:, None], "Zw,Zfoo", d.z_meas[0], [-0.02, 0.0], 1.0, 0.0, sd**2)
    with pytest.raises(InputError, match="unknown parameter"):
        identify(_cfg(filter={"estimate": ["Zw", "Nr"]}), np.random.default_rng(0))


def test_covariances_must_be_positive_definite():
    m, d, sd = _small_problem()
    args = (m, d.t, d.z_meas, d.ds[:, None], "Zw", d.z_meas[0], [-0.02])
    with pytest.raises(ConfigError, match="P0 is not positive definite"):
        run_ekf(*args, [1e-6, 1e-6, -1e-6, 1e-6], 0.0, sd**2)
    with pytest.raises(ConfigError, match="R is not positive definite"):
        run_ekf(*args, 1e-6, 0.0, [1e-6, 0.0, 1e-6])
    with pytest.raises(ConfigError, match="Q is not positive semi-definite"):
        run_ekf(*args, 1e-6, [0.0, -1.0, 0.0, 0.0], sd**2)
    with pytest.raises(ConfigError, match="not symmetric"):
        run_ekf(*args, np.array([[1, 1, 0, 0], [0, 1, 0, 0], [0, 0, 1, 0], [0, 0, 0, 1.0]]), 0.0, sd**2)


def test_bad_samples():
    m, d, sd = _small_problem()
    t = d.t.copy()
    t[3] = t[2]
    with pytest.raises(InputError, match="strictly increasing"):
        run_ekf(m, t, d.z_meas, d.ds[:, None], "Zw", d.z_meas[0], [-0.02], 1e-6, 0.0, sd**2)
    with pytest.raises(InputError, match="measurements"):
        run_ekf(m, d.t, d.z_meas[:, :2], d.ds[:, None], "Zw", d.z_meas[0], [-0.02], 1e-6, 0.0, sd**2)


def test_diverging_filter_is_reported():
    """A wildly unstable guess (M_q' = +0.05), trusted (tiny P0) against ignored data (huge R): the
    estimate blows up and the filter stops with a one-line FilterDivergedError (an InputError)."""
    c = SubmarineVerticalConfig()
    d = zigzag(c.params(), c.x0(), "10-5", duration=200.0, dt_truth=1e-2)
    m = submarine_vertical_model()
    with pytest.raises(FilterDivergedError, match=r"EKF diverged at t=.* s") as e:
        run_ekf(
            m,
            d.t,
            d.z_meas,
            d.ds[:, None],
            "Mq",
            d.z_meas[0],
            [0.05],
            [1e-12, 1e-12, 1e-12, 1e-14],
            0.0,
            [1e12, 1e12, 1e12],
        )
    assert isinstance(e.value, InputError) and "\n" not in str(e.value)


@njit(cache=True)
def osc_f_real_only(x, p, u, out):
    out[0] = x[1]
    out[1] = (u[0] - p[1] * x[1] - p[0] * math.sin(x[0])) / p[2]  # math.sin: no complex arithmetic


def test_model_not_complex_step_safe_is_reported():
    """A user f written with math.sin cannot be complex-stepped: one-line InputError, not a traceback;
    the message names the alternatives."""
    m, t, X, U = _osc_data(T=2.0)
    m.f = osc_f_real_only
    with pytest.raises(InputError, match="complex arithmetic.*finite-difference"):
        run_ekf(m, t, X[:, :1], U, "k", [0.0, 0.0], [1.5], [1e-6, 1e-2, 1.0], 0.0, [1e-8])
