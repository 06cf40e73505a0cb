"""An ROV that stays in the water (issue 38): the buoyancy of the emerged volume and the thrust of a
thruster out of the water are lost (:mod:`oceangnc.models._surface`), and the allocation serves the
attitude before a saturated translation (:mod:`oceangnc.control.priority_allocation`)."""

from __future__ import annotations

import numpy as np
import pytest

from oceangnc.control.thrust_allocation import ThrustAllocation, pinv_scaled
from oceangnc.models.vehicle import load_vehicle, thruster_matrix, vehicle_model

KEYS = [f"rov.tau_{a}" for a in "XYZKMN"]


def _alloc(blk, tau):
    bus = dict(zip(KEYS, tau))
    blk.step(0.0, bus)
    return np.array([bus[k] for k in blk.outputs])


@pytest.fixture(scope="module")
def heavy():
    return load_vehicle("bluerov2-heavy")


def test_one_tier_is_the_uniform_scaling_and_tiers_keep_the_pitch_moment(heavy):
    """Without ``control.priority`` the thrusts are pinv_scaled's to rounding; with the file's tiers a
    surge demand past the reverse thrust keeps the asked pitch moment and depth force exactly, where the
    uniform scaling cuts them with the surge (by 22 % on this demand)."""
    one = heavy.model_copy(update={"control": heavy.control.model_copy(update={"priority": None})})
    flat, tiered = ThrustAllocation(one, 0.05, "rov"), ThrustAllocation(heavy, 0.05, "rov")
    rng = np.random.default_rng(5)
    f = np.empty(8)
    for _ in range(50):
        tau = rng.normal(size=6) * [120, 120, 150, 5, 5, 10]
        pinv_scaled(flat.pa, 9, 8, tau, f)  # ALLOC_HEAD: n, period, ramp_s, tier (6)
        np.testing.assert_allclose(_alloc(flat, tau), f, rtol=0, atol=1e-9)
    B = thruster_matrix(heavy)
    tau = np.array([-145.6, 0.0, 60.0, 0.0, 5.0, 0.0])
    got_flat, got_tier = B @ _alloc(flat, tau), B @ _alloc(tiered, tau)
    assert got_flat[4] < 0.8 * tau[4] and got_flat[2] < 0.8 * tau[2]
    np.testing.assert_allclose(got_tier[[2, 3, 4]], tau[[2, 3, 4]], atol=1e-9)
    assert -115.0 < got_tier[0] < -100.0  # the surge gets what the reverse thrust has left


def _rise(vf, seconds=20.0):
    """Released at 1 m depth with every vertical thruster pushing up at full reverse thrust: the depth
    history (m, down positive) by RK4 at 5 ms."""
    m = vehicle_model(vf)
    x = np.zeros(m.nx)
    x[2] = 1.0
    u = np.zeros(m.nu)
    for i, t in enumerate(vf.thrusters):
        if t.name.startswith("vert"):
            u[i] = -t.max_reverse
            x[12 + i] = u[i]
    t = np.linspace(0.0, seconds, int(seconds / 0.05) + 1)
    X = m.simulate(t, np.tile(u, (t.size, 1)), x, substeps=10)
    return X[:, 2]


def test_full_up_thrust_cannot_lift_the_rov_out_of_the_water(heavy):
    """With the free surface the ROV rises to the surface and settles there with its hull still in the
    water (origin above -h/2, where no buoyancy and no thrust would be left; measured: it settles 5 mm
    above the mean surface, where up-thrust and the remaining buoyancy balance the weight); without it
    (``hydrostatics.height`` and ``thruster_immersion`` unset, the model before issue 38) the same
    thrust flies it metres out of the water."""
    h = heavy.hydrostatics.height
    z = _rise(heavy)
    assert z.min() > -0.5 * h and abs(z[-1] - z[-40]) < 1e-3 and z[-1] < 0.05
    bare = heavy.model_copy(
        update={"hydrostatics": heavy.hydrostatics.model_copy(update={"height": None, "thruster_immersion": None})}
    )
    assert _rise(bare).min() < -3.0


def test_bluerov2_heavy_against_blue_robotics_figures():
    """The new cases (validation/cases/bluerov2_heavy.py) measure the file through its allocation and stay
    documented deviations: forward 14.85 kgf and vertical 21.0 kgf are the T200 data sheet's sums (4 x 5.25
    kgf x cos 45 deg, 4 x 5.25 kgf), lateral 11.6 kgf is bound by the reverse thrust, all above Blue
    Robotics' vehicle figures; at the published 9 kgf the file's surge damping gives 0.744 m/s."""
    from oceangnc.validation import Runner, run_case
    from oceangnc.validation.cases import bluerov2_heavy

    r = Runner()
    try:
        out = {c.id: run_case(c, r) for c in bluerov2_heavy.CASES}
    finally:
        r.close()
    assert all(o.status == "deviation" for o in out.values()), {k: o.status for k, o in out.items()}
    v = {k.removeprefix("vehicle-bluerov2-heavy-"): o.measured.value for k, o in out.items()}
    c45 = np.cos(np.pi / 4)
    assert v["bollard-forward"] == pytest.approx(4 * 5.25 * c45, rel=2e-3)
    assert v["bollard-lateral"] == pytest.approx(4 * 4.1 * c45, rel=2e-3)
    assert v["bollard-vertical"] == pytest.approx(4 * 5.25, rel=2e-3)
    assert v["speed-published-thrust"] == pytest.approx(0.744, abs=1e-3)
