"""The Otter against Fossen's current program (issue 38): the file in otter.py's form reproduces his numbers,
the numbers kept in the case module are the recipe's output, and an unfitted coefficient moves a case out."""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pytest

from oceangnc.models.vehicle import load_vehicle, rigid_body_matrix
from oceangnc.validation import Runner, run_case
from oceangnc.validation.cases import CASES
from oceangnc.validation.cases import _pvs_otter as pvs
from oceangnc.validation.cases.otter_pvs import pvs_form

ROOT = Path(__file__).resolve().parents[1]


def test_the_kept_reference_numbers_are_the_recipes_output():
    """docs/validation/reference/pvs_otter.json (written by pvs_otter.py from a clone at the named commit) and the
    constants the cases use are the same numbers, for the same commit."""
    ref = json.loads((ROOT / "docs/validation/reference/pvs_otter.json").read_text())
    assert ref["commit"] == pvs.COMMIT and ref["n_max_rad_s"] == pvs.N_MAX
    got = {(c["port"], c["starboard"]): (c["u"], c["v"], c["r"], c["speed"], c.get("radius")) for c in ref["cases"]}
    assert got == pvs.STEADY


def test_the_inertia_options_exact_parallel_axis_and_otter_py():
    """Exact: M_RB about CO of the hull (55 kg, radii 0.432/0.5/0.5 m about (0.2, 0, -0.2)) and the payload point
    mass (25 kg at (0.05, 0, -0.35)) summed about their combined CG equals the sum of each part's own M_RB about
    CO (the parallel-axis theorem for the whole; a double transport breaks it). otter.py's sum is his I_g
    (16.679, 21.517, 15.102, I_xz 2.517 kg m^2), which M_RB transports again."""
    from oceangnc.models.vehicle import RigidBody

    vf = load_vehicle("otter")
    m, ig, r_g = vf.rigid_body.resolved()
    assert m == 80.0 and np.allclose(r_g, [0.153125, 0.0, -0.246875])
    hull = RigidBody(mass=55.0, inertia=(55 * 0.432**2, 55 * 0.25, 55 * 0.25), r_g=(0.2, 0.0, -0.2))
    payload = RigidBody(mass=25.0, inertia=(0.0, 0.0, 0.0), r_g=(0.05, 0.0, -0.35))
    assert np.allclose(rigid_body_matrix(vf.rigid_body), rigid_body_matrix(hull) + rigid_body_matrix(payload))
    ig_pvs = pvs_form(vf).rigid_body.resolved()[1]
    want = [[16.678919609375, 0, 2.516650390625], [0, 21.51669921875, 0], [2.516650390625, 0, 15.102099609375]]
    assert np.allclose(ig_pvs, want)
    assert not np.allclose(rigid_body_matrix(pvs_form(vf).rigid_body), rigid_body_matrix(vf.rigid_body), atol=0.1)


def test_a_20_percent_error_in_n_r_r_fails_the_yaw_rate_case():
    """N_r|r| = 10 N_r (Fossen's rule, fitted to nothing) 20 % higher: the 100/0 turn's yaw rate leaves the 1 %
    band around his program's 17.64 deg/s, while the file as it is passes."""
    case = {c.id: c for c in CASES}["vehicle-otter-pvs-yaw-rate-100-0"]
    n_rr = load_vehicle("otter").damping.quadratic[5]
    r0, r1 = Runner(), Runner({"otter.D_Q[5]": 1.2 * n_rr})
    try:
        base, moved = run_case(case, r0), run_case(case, r1)
    finally:
        r0.close()
        r1.close()
    assert base.status == "pass" and base.measured.value == pytest.approx(17.639, rel=1e-3)
    assert moved.status == "fail" and moved.measured.value < 0.97 * base.measured.value
