"""The model files split by responsibility (issue 17) keep their old import paths, and the laws that
the Python blocks and the fused kernels share are one function each."""

from __future__ import annotations

import importlib

import numpy as np
import pytest

# old module -> (new module, names that code, generated fused modules or tests import from the old one)
MOVED = {
    "oceangnc.models.combined": {
        "oceangnc.models._combined_imex": ["imex_advance"],
        "oceangnc.models._combined_split": ["split_advance", "damping_substep"],
        "oceangnc.models._combined_outputs": ["_fill_outputs", "_fill_outputs_var"],
        "oceangnc.models._combined_winch": ["remesh", "winch_command"],
        "oceangnc.models._combined_kernels": ["combined_rhs", "cable_state"],
        "oceangnc.models._combined_layout": ["H_N", "H_L0", "H_WO", "P_SCR", "INPUT_NAMES", "INTEGRATORS"],
    },
    "oceangnc.models.uuv": {"oceangnc.models._uuv_params": ["UUVConfig", "NP", "P_MA", "P_MRB", "P_RC", "LAYOUT"]},
    "oceangnc.models.ship_lowspeed": {"oceangnc.models._ship_params": ["ShipConfig", "P", "LAYOUT", "STATE_NAMES"]},
    "oceangnc.models.submarine_vertical": {
        "oceangnc.models._submarine_params": ["SubmarineVerticalConfig", "TRUE_COEFFS", "COEFF_NAMES", "P_NAMES"]
    },
    "oceangnc.models.cable": {"oceangnc.models._cable_config": ["CableConfig"]},
    "oceangnc.models.usv": {"oceangnc.models._hydro": ["wind_load"]},
    "oceangnc.core.linearize": {"oceangnc.core.jacobians": ["jacobian_functions", "cached_closure", "h_states"]},
}


@pytest.mark.parametrize("old", sorted(MOVED))
def test_old_import_paths_give_the_same_objects(old):
    m = importlib.import_module(old)
    for new, names in MOVED[old].items():
        n = importlib.import_module(new)
        for name in names:
            assert getattr(m, name) is getattr(n, name), f"{old}.{name} is not {new}.{name}"


def test_backstepping_block_and_law_agree():
    """The dict-returning control_law and the block's compiled update are the same law: one firing of
    update with the leader at rest gives the thrusts of control_law split and clipped."""
    from oceangnc.control.backstepping import (
        BacksteppingConfig,
        control_law,
        errors,
        law_params,
        model_from_uuv,
        update,
    )
    from oceangnc.models.uuv import UUVConfig

    m, g = model_from_uuv(UUVConfig()), BacksteppingConfig()
    pa = law_params(m, g, 1.2, 0.3, 0.05, 0.1, 1e6, -1e6)
    st = np.zeros(19)
    st[7:] = [5.0, 1.0, 0.2, 0.0, 0.0, 0.0, 2.0, 0.5, 0.1, 0.4, 0.05, 0.02]
    ts, tb, V, Vdot, e1, e2, tau_u, tau_r = update(st, pa)
    ref = control_law(m, g, *errors(5.0, 1.0, 0.2, 2.0, 0.5, 0.1, 1.2, 0.3, g.h), 0.4, 0.05, 0.02, 0.0, 0.0, 0.0,
                      cx=1.2, cy=0.3)  # fmt: skip
    assert (tau_u, tau_r, V, Vdot) == (ref["tau_u"], ref["tau_r"], ref["V"], ref["Vdot"])
    assert ts == 0.5 * tau_u and tb == tau_r / m.bow_arm
    assert Vdot < 0.0  # the nominal Lyapunov derivative is negative away from the origin


def test_a_pid_view_steps_its_blocks_arrays_with_the_one_law():
    """A PID is two slices of its block's arrays: stepping the view moves the block's state as the
    compiled law does on the whole array, and a gain set on the view reaches the law's parameters."""
    from oceangnc.control.pid import PID, PID_PARAMS, PID_STATE, pid_params, pid_run

    pa = np.concatenate([[9.0], PID_PARAMS.pack(pid_params(2.0, 0.5, 0.1, -1.0, 1.0))])
    st, st2 = np.zeros(1 + PID_STATE.size), np.zeros(1 + PID_STATE.size)
    pid = PID.view(st, 1, pa, 1)
    us = []
    for k, e in enumerate([0.3, 0.9, 1.5, -0.2, -2.0, 0.1]):
        us.append(pid.step(e, 0.1, feedforward=0.05 * k))
        assert pid_run(st2, 1, pa, 1, e, 0.1, 0.0, False, 0.05 * k, 1.0) == us[-1]
    assert np.array_equal(st, st2) and st[0] == 0.0 and pid.integral == st[1]
    assert us[2] == 1.0 and us[4] == -1.0  # both limits were met (the back-calculation path ran)
    pid.kp = 4.0
    assert pa[1 + PID_PARAMS.at.kp] == 4.0 and pa[1 + PID_PARAMS.at.kw] == 0.25  # K_w = 1/K_p follows
