"""The USV's wave-frequency motions (issue 29 part B): hydrodynamic coefficients, the radiation fit,
Cummins' equation in the combined plant, the 6-DOF tow point.

Kinds of evidence: the simulated regular-wave amplitudes against the frequency-domain RAO of the same
coefficients (a round trip between two independent solutions: a time integration of Cummins' equation
with a fitted radiation memory and the linear solve of the RAO, which the simulation never evaluates);
capytaine's results against physical laws on a coarse mesh (the Haskind relation between the
radiation damping and the diffraction force of two separate BEM problems, the hydrostatic stiffness
against rho g times the designed waterplane area, the long-wave heave force); the committed file
loads without capytaine; calm water unchanged (tests/test_baseline.py).
"""

from __future__ import annotations

import math

import numpy as np
import pytest

from oceangnc.environment import USVMotionsConfig
from oceangnc.environment.waves import WaveField
from oceangnc.errors import ConfigError, InputError
from oceangnc.hydro.coefficients import HydroCoefficients, default_usv_coefficients
from oceangnc.hydro.radiation import fit_radiation
from oceangnc.models._combined_layout import H_SEA
from oceangnc.models._sea_layout import S_WF, W_XO
from oceangnc.models._usv_waves import manoeuvring_damping
from oceangnc.models.cable import CableConfig
from oceangnc.models.combined import CombinedPlant
from oceangnc.models.usv import USVConfig
from oceangnc.models.uuv import UUVConfig


def _plant(waves, **kw):
    """A short tow (2 segments) with the USV's motions on; the USV lies still (no thrust, no current)."""
    cc = CableConfig(length=4.0, segments=2, integrator="imex")
    uc = UUVConfig(x0=0.0, z0=4.1)
    return CombinedPlant(USVConfig(), uc, cc, top="usv", waves=waves, usv_motions=USVMotionsConfig(enabled=True, **kw))


def _regular(a, omega, mu):
    return WaveField(np.array([a]), np.array([omega]), np.array([mu]), np.array([0.3]), depth=1000.0)


def _amplitudes(pl, omega, duration, window, dt=0.01):
    """Amplitudes of heave, roll, pitch (xi_3..5) over the last ``window`` s: least-squares sinusoid at
    ``omega`` plus a mean."""
    o = int(pl.p[int(pl.p[int(pl.p[H_SEA]) + S_WF]) + W_XO])
    t = 0.0
    ts, xs = [], []
    n = int(round(duration / (5 * dt)))
    for _ in range(n):
        t = pl.advance(t, dt, 5)
        if t >= duration - window:
            ts.append(t)
            xs.append(pl.x[o + 2 : o + 5].copy())
    ts = np.array(ts)
    A = np.stack([np.cos(omega * ts), np.sin(omega * ts), np.ones_like(ts)], axis=1)
    coef = np.linalg.lstsq(A, np.array(xs), rcond=None)[0]
    return np.hypot(coef[0], coef[1])


# three periods (on the file's frequency grid: below, near and above the heave resonance) x two headings
CASES = [(iw, ib) for iw in (5, 11, 15) for ib in (2, 5)]


@pytest.mark.parametrize("iw,ib", CASES)
def test_regular_wave_amplitudes_equal_the_rao(iw, ib):
    """In a regular wave the simulated heave, roll and pitch amplitudes equal |RAO| x a within 5 %.

    The RAO solves [-w^2 (M + A(w)) - i w (B(w) + B_v) + C] xi = X at the wave frequency; the simulation
    integrates Cummins' equation (A_inf, the vector-fitted memory, the excitation expansions) in time."""
    c = default_usv_coefficients()
    w, mu = c.omega[iw], c.headings[ib]
    a = 0.05
    pl = _plant(_regular(a, w, mu))
    amp = _amplitudes(pl, w, duration=70.0, window=20.0)
    Bx, Cx = c.time_domain_extras(c.hull["roll_damping_ratio"])
    u = USVConfig()
    Bx = Bx + manoeuvring_damping(u.d11, u.d22, u.d33)  # the plant's default (usv_motions.manoeuvring_damping)
    rao = np.abs(c.rao(iw, ib, Bx, Cx))[2:5] * a
    assert rao.min() > 1e-4 * a  # every one of the three responds at these oblique headings
    np.testing.assert_allclose(amp, rao, rtol=0.05)


def test_committed_file_loads_without_capytaine(monkeypatch):
    """The seeds' USV file is package data and loads with numpy alone (capytaine made unimportable)."""
    import sys

    monkeypatch.setitem(sys.modules, "capytaine", None)
    c = default_usv_coefficients()
    assert c.omega.size >= 30 and c.headings.size >= 4
    assert c.drift is not None
    # the barge of 003 table 5-1 / 2-2 floats its 200 kg: C33 = rho g L B within the mesh's own accuracy
    assert c.C[2, 2] == pytest.approx(c.rho * c.g * 2.5 * 1.62, rel=1e-3)
    assert c.M[0, 0] == pytest.approx(200.0)
    # low frequency: the heave force is the hydrostatic one on the elevation (up at a crest: -z)
    assert c.X[0, 0, 2].real == pytest.approx(-c.C[2, 2], rel=0.02)


def test_radiation_fit_reproduces_the_coefficients():
    """The state-space memory gives back A(w) and B(w) of the diagonal within 5 % of each entry's peak,
    has K(0) = 0 and stable poles."""
    c = default_usv_coefficients()
    r = fit_radiation(c)
    assert np.all(np.linalg.eigvals(r.Ar).real < 0)
    A, B = r.added_mass_damping(c.omega, c.A_inf)
    for i in range(6):
        assert np.max(np.abs(B[:, i, i] - c.B[:, i, i])) < 0.05 * np.max(np.abs(c.B[:, i, i]))
        da = np.abs(A[:, i, i] - c.A[:, i, i])[c.omega > 1.0]
        assert np.max(da) < 0.05 * np.max(np.abs(c.A[:, i, i]))
    assert np.max(np.abs(r.transfer(np.array([0.0])))) < 1e-8 * np.max(np.abs(c.B))


def test_tow_point_follows_the_usv_in_six_dof():
    """The cable's top node is the attachment point moved by the USV's wave-frequency motion: with a
    lever r = (1, 0.3, 0.2) m it moves by xi_1..3 + xi_4..6 x r (small rotations)."""
    cc = CableConfig(length=4.0, segments=2, integrator="imex", top_x=1.0, top_y=0.3, top_z=0.2)
    uc = UUVConfig(x0=0.0, z0=4.1)
    pl = CombinedPlant(
        USVConfig(), uc, cc, top="usv", waves=_regular(0.05, 2.0, 1.0), usv_motions=USVMotionsConfig(enabled=True)
    )
    nodes0 = pl.cable_snapshot()[0][0].copy()
    o = int(pl.p[int(pl.p[int(pl.p[H_SEA]) + S_WF]) + W_XO])
    xi = np.array([0.01, -0.02, 0.03, 0.02, -0.01, 0.015])
    pl.x[o : o + 6] = xi
    moved = pl.cable_snapshot()[0][0]
    r = np.array([1.0, 0.3, 0.2])
    expect = xi[:3] + np.cross(xi[3:], r)
    np.testing.assert_allclose(moved - nodes0, expect, atol=1e-12)


def test_bad_inputs_are_one_line_errors(tmp_path):
    bad = tmp_path / "x.npz"
    bad.write_text("not a file")
    with pytest.raises(InputError, match="not an npz"):
        HydroCoefficients.load(bad)
    with pytest.raises(InputError, match="not found"):
        HydroCoefficients.load(tmp_path / "none.npz")
    c = default_usv_coefficients()
    c.version = 99
    c.save(tmp_path / "v.npz")
    with pytest.raises(InputError, match="version 99"):
        HydroCoefficients.load(tmp_path / "v.npz")
    with pytest.raises(ConfigError, match="needs waves"):
        _plant(None)


def test_mean_drift_pushes_the_usv_along_the_waves():
    """With the drift on, a USV lying in beam seas (waves travelling to starboard) drifts to starboard
    (east, heading north) and one without drift stays put: the Maruo far-field force of the file."""
    c = default_usv_coefficients()
    w = c.omega[14]
    sea = _regular(0.25, w, math.pi / 2)
    moved = []
    for drift in (False, True):
        pl = _plant(sea, drift=drift)
        t = 0.0
        for _ in range(200):
            t = pl.advance(t, 0.01, 10)
        moved.append(pl.x[1])
    assert abs(moved[0]) < 0.05
    assert moved[1] > 0.2


#: the USV's motions on both paths: tow-sea-state (fixed form, imex) and tow-deploy with the winch
#: inserting nodes (variable form), in oblique seas so that heave, roll and pitch all move
WF_FUSED = [
    ("tow-sea-state", {"command.start_s": 0.5, "environment.waves.direction_deg": 135.0}, 4.0),
    (
        "tow-deploy",
        {
            "winch_control.profile": [(0.0, 1.3), (0.5, 8.0), (3.0, 8.0), (6.0, 1.3)],
            "environment.waves.kind": "jonswap",
            "environment.waves.direction_deg": 60.0,
        },
        8.0,
    ),
]


@pytest.mark.parametrize("name,over,dur", WF_FUSED, ids=["tow-sea-state", "tow-deploy-winch"])
def test_usv_motions_fused_log_equals_python_log(name, over, dur, tmp_path):
    """The same law on the fused loop and the Python clock: the same log, with usv.z, usv.phi and
    usv.theta in it and moving; the tow point moves with them (the top tension differs from the run
    without the USV's motions)."""
    from fused_paths import run_both, run_path

    over = {**over, "environment.usv_motions.enabled": True}
    _, _, a, _, _, _ = run_both(name, over, dur, tmp_path)
    for k in ("usv.z", "usv.phi", "usv.theta"):
        assert np.std(a[k].to_numpy()) > 1e-4
    off = {**over, "environment.usv_motions.enabled": False}
    _, _, b, _ = run_path(name, off, dur, True, tmp_path / "off")
    assert "usv.z" not in b
    assert np.max(np.abs(a["cable.top_tension"].to_numpy() - b["cable.top_tension"].to_numpy())) > 1.0


def test_long_waves_lift_the_usv_with_the_surface():
    """A boat much shorter than the waves rides them: in a 7.9 s wave (125 m long, 50x the hull) the
    simulated heave is the surface's, xi_3(t) = -eta(t) at the USV (z down), within 3 % of the amplitude
    - a physical limit that checks the excitation's phase convention, which the RAO comparison (both
    sides from the same X) cannot."""
    a, w, eps = 0.1, 0.8, 0.3
    pl = _plant(WaveField(np.array([a]), np.array([w]), np.array([2.6]), np.array([eps]), depth=1000.0))
    o = int(pl.p[int(pl.p[int(pl.p[H_SEA]) + S_WF]) + W_XO])
    t, err = 0.0, []
    for _ in range(1000):
        t = pl.advance(t, 0.01, 5)
        if t > 30.0:
            eta = a * math.cos(-w * t + eps)  # the USV lies at the origin
            err.append(pl.x[o + 2] + eta)
    assert np.max(np.abs(err)) < 0.03 * a
