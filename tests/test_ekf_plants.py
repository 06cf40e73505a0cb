"""The augmented EKF identifies coefficients of plants other than the submarine through the one model
contract (issue 17 part B): the model is taken by name (:func:`get_model`), the parameters to estimate
are named, the truth is a simulated trial of the same Model, and the guesses start 50 % off.

Consistency: a single noisy run per plant; each estimate must lie within 3 sigma of the truth and the
NEES of the estimated block below the 99.9 % chi-square quantile of its dimension (a single draw:
this rejects an over-confident filter, not a slightly conservative one). Figures in
docs/ekf-identification.md ("Identifying any plant").
"""

from __future__ import annotations

import numpy as np
import pytest
from scipy.stats import chi2

from oceangnc.identification.ekf import get_model, nees, run_ekf
from oceangnc.units import KGF


def _identify(model, t, U, x0, sd, est, factors, seed, q_rel=1e-4, substeps=2):
    X = model.simulate(t, U, x0, substeps=20)
    Z = X + np.random.default_rng(seed).standard_normal(X.shape) * sd
    truth = np.array([model.p[model.layout.index(k)] for k in est])
    a0 = truth * np.asarray(factors)
    P0 = np.concatenate([(2 * sd) ** 2, (0.5 * truth) ** 2])
    Q = np.concatenate([q_rel * sd**2, np.zeros(len(est))])
    res = run_ekf(model, t, Z, U, est, Z[0], a0, P0, Q, sd**2, substeps=substeps)
    n = model.nx
    fin, sig = res.X[-1, n:], res.sigma[-1, n:]
    return truth, fin, sig, nees(fin - truth, res.P[n:, n:]), float(np.nanmean(res.nis))


@pytest.mark.slow
def test_usv_damping_from_a_thrust_zigzag():
    """USV (003 eq. 2.3): d11, d22, d33 and d11_rr from 120 s of a differential-thrust zig-zag
    (25 +- 10 kgf per side, switched every 10 s), all six states measured at 10 Hz (GPS 5 cm, heading
    and yaw rate 0.2 deg(/s), velocities 1 cm/s), guesses 0.5x / 1.5x the truth: each within 1 %."""
    m = get_model("usv")
    t = np.arange(0.0, 120.0 + 1e-9, 0.1)
    sgn = np.where((t // 10) % 2 == 0, 1.0, -1.0)
    U = np.zeros((t.size, 6))
    U[:, 0] = (25 + 10 * sgn) * KGF
    U[:, 1] = (25 - 10 * sgn) * KGF
    sd = np.array([0.05, 0.05, np.radians(0.2), 0.01, 0.01, np.radians(0.2)])
    est = ["d11", "d22", "d33", "d11_rr"]
    truth, fin, sig, q, nis = _identify(m, t, U, np.zeros(6), sd, est, [0.5, 1.5, 0.5, 1.5], seed=1)
    assert np.all(np.abs(fin / truth - 1) < 0.01), dict(zip(est, fin / truth - 1))
    assert np.all(np.abs(fin - truth) < 3 * sig)
    assert q < chi2.ppf(0.999, len(est))
    assert 0.5 * 6 < nis < 2.0 * 6  # mean NIS near its 6 degrees of freedom


@pytest.mark.slow
def test_uuv_coefficients_from_a_manoeuvre():
    """UUV (003 ch. 2.2, 6-DOF): axial drag X_u|u|, yaw lift N_ur and pitch lift M_uw from 90 s of
    stern-differential and bow-thruster reversals every 6 s (the heavy vehicle sinks and pitches, which
    excites M_uw), 12 states at 10 Hz, guesses 0.5x / 1.5x / 0.5x: X_uu within 2 %, N_ur within 5 %,
    M_uw within 1 %."""
    from oceangnc.models.uuv import UUVConfig

    m = get_model("uuv")
    t = np.arange(0.0, 90.0 + 1e-9, 0.1)
    sgn = np.where((t // 6) % 2 == 0, 1.0, -1.0)
    U = np.zeros((t.size, 5))
    U[:, 0] = 20 + 8 * sgn
    U[:, 1] = 20 - 8 * sgn
    U[:, 2] = 6 * sgn * (t > 3)
    sd = np.array([0.05] * 3 + [np.radians(0.2)] * 3 + [0.01] * 3 + [np.radians(0.2)] * 3)
    est = ["X_uu", "N_ur", "M_uw"]
    truth, fin, sig, q, nis = _identify(m, t, U, UUVConfig().initial_state(), sd, est, [0.5, 1.5, 0.5], seed=1)
    rel = np.abs(fin / truth - 1)
    assert rel[0] < 0.02 and rel[1] < 0.05 and rel[2] < 0.01, dict(zip(est, rel))
    assert np.all(np.abs(fin - truth) < 3 * sig)
    assert q < chi2.ppf(0.999, len(est))
    assert 0.5 * 12 < nis < 2.0 * 12


def test_first_order_speed_and_nomoto_coefficients():
    """First-order USV of 000 (speed lag and Nomoto yaw, eq. 8 and 15): the intercepts of K_v, T_v,
    K_r and T_r from 120 s of 10 deg rudder reversals every 10 s with 1500 +- 300 rpm steps every
    25 s, 5 states at 10 Hz, guesses 0.5x / 1.5x: each within 0.5 %."""
    m = get_model("first-order")
    t = np.arange(0.0, 120.0 + 1e-9, 0.1)
    U = np.zeros((t.size, 3))
    U[:, 0] = 1500 + 300 * np.where((t // 25) % 2 == 0, 1.0, -1.0)
    U[:, 1] = np.radians(10) * np.where((t // 10) % 2 == 0, 1.0, -1.0)
    sd = np.array([0.5, 0.5, np.radians(0.2), 0.02, np.radians(0.1)])
    est = ["kv_intercept", "tv_intercept", "kr_intercept", "tr_intercept"]
    truth, fin, sig, q, nis = _identify(m, t, U, [0.0, 0.0, 0.0, 5.25, 0.0], sd, est, [0.5, 1.5, 0.5, 1.5], seed=1)
    assert np.all(np.abs(fin / truth - 1) < 5e-3), dict(zip(est, fin / truth - 1))
    assert np.all(np.abs(fin - truth) < 3 * sig)
    assert q < chi2.ppf(0.999, len(est))
    assert 0.5 * 5 < nis < 2.0 * 5


def test_estimating_a_derived_parameter_is_refused():
    """The UUV's inverse mass matrix is derived from M_RB + M_A: asking to estimate it is an InputError."""
    from oceangnc.errors import InputError

    m = get_model("uuv")
    with pytest.raises(InputError, match=r"M_inv\[0\].*derived"):
        run_ekf(
            m, [0.0, 0.1], np.zeros((2, 12)), np.zeros((2, 5)), "M_inv[0]", np.zeros(12), [1.0], 1.0, 0.0, np.ones(12)
        )


def test_registry_names_every_plant():
    from oceangnc.errors import InputError

    from oceangnc.core.model import model_names

    names = ("bluerov2-heavy", "first-order", "otter", "ship", "submarine-vertical", "usv", "uuv", "uuv-003")
    assert tuple(model_names()) == names  # one registry: the oceangnc.models entry points (vehicle files too)
    for name in names:
        assert get_model(name).name in (name, "first-order")
    with pytest.raises(InputError, match="known models: bluerov2-heavy, first-order, otter, ship, submarine-vertical"):
        get_model("tanker")
