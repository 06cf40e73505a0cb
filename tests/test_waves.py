"""Sea waves (issue 29): Airy kinematics against the velocity potential, irregular records against
their target Hs and peak, the spectra against wavespectra's (a maintained ocean-wave library)."""

from __future__ import annotations

import math

import numpy as np
import pytest
from scipy.signal import welch

from oceangnc.environment.waves import WaveConfig, WaveField, jonswap, pierson_moskowitz, wave_number
from oceangnc.errors import ConfigError
from oceangnc.io.config import validate
from oceangnc.units import G


def _potential(a, w, k, th, eps, h, t, x, y, z_up):
    """Linear wave potential (DNV-RP-C205 table 3-1 form): Phi = g a / w cosh(k (z + h)) / cosh(k h)
    sin(k (x cos th + y sin th) - w t + eps), z up from the mean surface."""
    phase = k * (x * math.cos(th) + y * math.sin(th)) - w * t + eps
    return G * a / w * math.cosh(k * (z_up + h)) / math.cosh(k * h) * math.sin(phase)


@pytest.mark.parametrize("depth", [15.0, 1000.0])
@pytest.mark.parametrize("d", [0.0, 2.5, 9.0])
def test_airy_kinematics_are_the_gradient_of_the_wave_potential(depth, d):
    """Analytic check: velocity = grad Phi, eta = -(1/g) dPhi/dt at the surface, by central
    differences of the potential (not the module's formulas); the dispersion relation links them."""
    a, T, th, eps = 0.8, 7.0, math.radians(30.0), 0.4
    w = 2 * math.pi / T
    field = WaveField([a], [w], [th], [eps], depth)
    k = float(field.k[0])
    assert w**2 == pytest.approx(G * k * math.tanh(k * depth), rel=1e-12)
    p, t, s = np.array([3.0, -2.0, d]), 1.7, 1e-4
    eta, vel, acc = field.kinematics(t, p[None, :])

    def phi(t_, x_, y_, z_):
        return _potential(a, w, k, th, eps, depth, t_, x_, y_, z_)

    x, y, z = p[0], p[1], -d
    u_n = (phi(t, x + s, y, z) - phi(t, x - s, y, z)) / (2 * s)
    u_e = (phi(t, x, y + s, z) - phi(t, x, y - s, z)) / (2 * s)
    w_up = (phi(t, x, y, z + s) - phi(t, x, y, z - s)) / (2 * s)
    assert vel[0] == pytest.approx([u_n, u_e, -w_up], abs=1e-7 * a * w)
    eta_phi = -(phi(t + s, x, y, 0.0) - phi(t - s, x, y, 0.0)) / (2 * s) / G
    assert eta[0] == pytest.approx(eta_phi, abs=1e-7 * a)
    # the acceleration is the time derivative of the velocity (central differences of the field)
    _, v1, _ = field.kinematics(t + s, p[None, :])
    _, v0, _ = field.kinematics(t - s, p[None, :])
    assert acc[0] == pytest.approx((v1[0] - v0[0]) / (2 * s), abs=1e-6 * a * w * w)


def test_wave_number_solves_the_dispersion_relation_from_shallow_to_deep():
    w = np.array([0.2, 0.6, 1.0, 3.0])
    for h in (2.0, 30.0, 5000.0):
        k = wave_number(w, h)
        np.testing.assert_allclose(G * k * np.tanh(k * h), w**2, rtol=1e-12)
    np.testing.assert_allclose(wave_number(w, 5000.0), w**2 / G, rtol=1e-12)  # deep water
    np.testing.assert_allclose(wave_number([0.05], 2.0), 0.05 / math.sqrt(G * 2.0), rtol=2e-3)  # shallow: c = sqrt(gh)


@pytest.mark.parametrize("kind", ["jonswap", "pierson-moskowitz"])
def test_a_long_irregular_record_has_the_target_hs_and_peak(kind):
    cfg = validate(WaveConfig, {"kind": kind, "hs": 1.5, "tp": 7.0, "components": 256})
    field = WaveField.from_config(cfg, np.random.default_rng(7))
    dt, n = 0.25, 4 * 3 * 3600  # three hours
    pts = np.zeros((1, 3))
    eta = np.empty(n)
    for i in range(n):  # the elevation record at one point
        eta[i] = field.kinematics(i * dt, pts)[0][0]
    assert 4 * eta.std() == pytest.approx(1.5, rel=0.05)
    f, pxx = welch(eta, fs=1 / dt, nperseg=4096)
    smooth = np.convolve(pxx, np.ones(5) / 5, mode="same")
    assert f[np.argmax(smooth)] == pytest.approx(1 / 7.0, rel=0.05)


def test_the_spectra_match_wavespectra():
    """The JONSWAP and Pierson-Moskowitz shapes against wavespectra's (same Hs over the same band)."""
    frequency = pytest.importorskip("wavespectra.construct.frequency")
    f = np.linspace(0.03, 0.6, 400)
    df = f[1] - f[0]
    for gamma in (1.0, 2.0, 3.3, 5.0):
        ref = np.asarray(frequency.jonswap(freq=f, fp=1 / 8.0, gamma=gamma, hs=2.0))
        ours = jonswap(f, 2.0, 8.0, gamma)
        ours = ours * (ref.sum() * df) / (ours.sum() * df)
        assert np.max(np.abs(ours - ref)) < 1e-3 * ref.max(), gamma
    ref = np.asarray(frequency.pierson_moskowitz(freq=f, fp=1 / 8.0, hs=2.0))
    ours = pierson_moskowitz(f, 2.0, 8.0)
    assert np.max(np.abs(ours * ref.sum() / ours.sum() - ref)) < 1e-3 * ref.max()
    # the JONSWAP normalisation C(gamma) keeps Hs within ~1 % before any rescaling (DNV-RP-C205)
    fine = np.linspace(1e-3, 3.0, 30000)
    hs = 4 * math.sqrt(float(np.sum(jonswap(fine, 2.0, 8.0, 3.3)) * (fine[1] - fine[0])))
    assert hs == pytest.approx(2.0, rel=0.015)


def test_the_sea_is_deterministic_for_a_seed_and_spreads_with_s():
    cfg = validate(WaveConfig, {"kind": "jonswap", "components": 32, "directions": 9, "spreading_s": 4.0})
    a = WaveField.from_config(cfg, np.random.default_rng(1))
    b = WaveField.from_config(cfg, np.random.default_rng(1))
    c = WaveField.from_config(cfg, np.random.default_rng(2))
    assert np.array_equal(a.comps, b.comps) and not np.array_equal(a.comps, c.comps)
    assert a.hs() == pytest.approx(cfg.hs, rel=1e-12)  # the discretised sea keeps Hs exactly
    energy = (a.a**2).reshape(32, 9).sum(axis=0)
    assert np.argmax(energy) in (4, 5) and energy[0] < 0.05 * energy.max()  # mean direction, little behind
    with pytest.raises(ConfigError, match="spreading_s"):
        validate(WaveConfig, {"kind": "jonswap", "directions": 5})


def test_wheeler_stretching_reaches_the_crest_and_nothing_above_it():
    a, T, depth = 1.0, 6.0, 12.0
    w = 2 * math.pi / T
    lin = WaveField([a], [w], [0.0], [0.0], depth)
    wh = WaveField([a], [w], [0.0], [0.0], depth, wheeler=True)
    crest = np.array([[0.0, 0.0, -a]])  # at t = 0 the crest stands over x = 0: eta = a
    eta, v_wh, _ = wh.kinematics(0.0, crest)
    assert eta[0] == pytest.approx(a)
    _, v_surface, _ = lin.kinematics(0.0, np.array([[0.0, 0.0, 0.0]]))
    assert v_wh[0] == pytest.approx(v_surface[0], rel=1e-12)  # the crest gets the mean surface's value
    _, v_above, _ = wh.kinematics(0.0, np.array([[0.0, 0.0, -a - 0.1]]))
    assert np.all(v_above == 0.0)  # out of the water
    _, v_bed_wh, _ = wh.kinematics(0.0, np.array([[0.0, 0.0, depth]]))
    _, v_bed, _ = lin.kinematics(0.0, np.array([[0.0, 0.0, depth]]))
    assert v_bed_wh[0] == pytest.approx(v_bed[0], rel=1e-12)  # the seabed is not moved
    assert abs(v_bed[0][2]) < 1e-12  # no flow through the seabed
