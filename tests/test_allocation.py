"""The redistributing thrust allocator (issue 30, ``control.allocator = "redistribute"``): where a demand
is feasible although the pseudo-inverse saturates a thruster, the redistributed pseudo-inverse meets it
exactly within the limits (uniform scaling does not); with no thrust past a limit it is the
pseudo-inverse; past what the thrusters can give it falls back to the uniform scaling."""

from __future__ import annotations

import numpy as np
import pytest
from scipy.optimize import linprog

from oceangnc.control.thrust_allocation import RedistributingAllocation, ThrustAllocation, allocation_block
from oceangnc.models.vehicle import load_vehicle, thruster_matrix

KEYS = [f"rov.tau_{a}" for a in "XYZKMN"]


@pytest.fixture(scope="module")
def rov():
    vf = load_vehicle("bluerov2-heavy")
    vf = vf.model_copy(update={"control": vf.control.model_copy(update={"priority": None})})  # uniform scaling
    B = thruster_matrix(vf)
    hi = np.array([t.max_forward for t in vf.thrusters])
    lo = -np.array([t.max_reverse for t in vf.thrusters])
    return vf, B, hi, lo, RedistributingAllocation(vf, 0.05, "rov"), ThrustAllocation(vf, 0.05, "rov")


def _alloc(blk, tau, **extra):
    bus = dict(zip(KEYS, tau), **extra)
    blk.step(0.0, bus)
    return np.array([bus[k] for k in blk.outputs])


def _feasible(B, tau, lo, hi) -> bool:
    """Whether some thrusts within the limits give tau exactly (a linear programme)."""
    r = linprog(np.zeros(B.shape[1]), A_eq=B, b_eq=tau, bounds=list(zip(lo, hi)), method="highs")
    return r.status == 0


def test_with_no_thrust_past_a_limit_it_is_the_pseudo_inverse(rov):
    vf, B, hi, lo, red, pinv = rov
    rng = np.random.default_rng(3)
    for _ in range(20):
        tau = rng.normal(size=6) * [10, 10, 10, 0.5, 0.5, 1.0]
        f = _alloc(red, tau)
        assert np.all(f < hi) and np.all(f > lo)
        np.testing.assert_allclose(f, _alloc(pinv, tau), rtol=0, atol=1e-12)
        np.testing.assert_allclose(B @ f, tau, atol=1e-9)


def test_a_saturated_thruster_is_redistributed_and_the_demand_met(rov):
    """Demands 15 % past what the uniform scaling can give in their direction, but feasible (a linear
    programme says so): the redistributed thrusts give tau exactly, within every limit, with at least
    one thruster at its limit; the uniformly scaled ones fall 13 % short."""
    vf, B, hi, lo, red, pinv = rov
    P = np.linalg.pinv(B)
    rng = np.random.default_rng(7)
    met = 0
    for _ in range(200):
        d = rng.normal(size=6) * [40, 40, 40, 2, 2, 4]
        f_d = P @ d
        s = np.min(np.where(f_d > 0, hi / np.maximum(f_d, 1e-12), lo / np.minimum(f_d, -1e-12)))
        tau = 1.15 * s * d
        if not _feasible(B, tau, lo, hi):
            continue
        f = _alloc(red, tau)
        assert np.all(f <= hi + 1e-9) and np.all(f >= lo - 1e-9)
        assert np.any(np.isclose(f, hi) | np.isclose(f, lo)), "a thruster at its limit"
        np.testing.assert_allclose(B @ f, tau, atol=1e-8 * np.abs(tau).max())
        short = np.linalg.norm(B @ _alloc(pinv, tau) - tau) / np.linalg.norm(tau)
        assert short == pytest.approx(1 - 1 / 1.15, rel=1e-6)
        met += 1
    assert met >= 20, f"only {met} feasible saturating demands in 200 directions"


def test_past_what_the_thrusters_give_it_falls_back_to_uniform_scaling(rov):
    vf, B, hi, lo, red, pinv = rov
    tau = np.array([400.0, -150.0, 300.0, 5.0, -4.0, 30.0])
    assert not _feasible(B, tau, lo, hi)
    f = _alloc(red, tau)
    np.testing.assert_allclose(f, _alloc(pinv, tau), atol=1e-12)
    assert np.all(f <= hi + 1e-9) and np.all(f >= lo - 1e-9)
    achieved = B @ f
    np.testing.assert_allclose(achieved / np.linalg.norm(achieved), tau / np.linalg.norm(tau), atol=1e-9)


def test_an_estop_zeroes_it_and_the_thrust_ramps_back(rov):
    vf, B, hi, lo, red, pinv = rov
    tau = np.array([30.0, 0.0, 20.0, 0.0, 0.0, 2.0])
    assert not _alloc(red, tau, _estop=True).any()
    f1 = _alloc(red, tau)  # one period after the stop: w = 0.05 / 2 s
    red.reset(None)
    np.testing.assert_allclose(f1, _alloc(red, tau) * 0.05 / 2.0, atol=1e-12)


def test_the_vehicle_file_selects_it_and_a_scenario_runs_on_it(tmp_path):
    from importlib import resources

    from oceangnc.api import run

    text = resources.files("oceangnc.models").joinpath("vehicles", "bluerov2-heavy.toml").read_text()
    path = tmp_path / "rov.toml"
    text = text.replace('name = "bluerov2-heavy"', 'name = "rov-redistribute"')
    path.write_text(text + '\nallocator = "redistribute"\n')  # the last table is [control]
    vf = load_vehicle(path)
    assert vf.control.allocator == "redistribute"
    assert isinstance(allocation_block(vf), RedistributingAllocation)
    assert type(allocation_block("bluerov2-heavy")) is ThrustAllocation
    r = run("rov-station-keeping", overrides={"vehicle": str(path)}, out=tmp_path / "r", plots=False, duration=30)
    s = r.summary
    assert s["status"] == "ok" and s["vehicle"] == "rov-redistribute"
    assert abs(r.df["vehicle.z"].iloc[-1] - 5.0) < 0.2  # it dived and holds
    assert s["vehicle.thrust_max_N"] <= 51.48 + 1e-9
