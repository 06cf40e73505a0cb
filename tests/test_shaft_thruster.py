"""Shaft-speed thrusters of the vehicle form (oceangnc.models._shaft): thrust k n|n| with a first-order
lag on the shaft speed, the usual propeller model of Fossen's vehicles (Fossen 2021 ch. 9; otter.py)."""

from __future__ import annotations

import math
import tomllib
from importlib import resources

import numpy as np
import pytest

from oceangnc.errors import ConfigError
from oceangnc.models._shaft import RPM, shaft_command, thrusts_from_states
from oceangnc.models.vehicle import VehicleFile, _check, vehicle_model

K_POS, K_NEG = 0.01108, 0.006445  # otter.py: 0.02216 / 2, 0.01289 / 2, N/(rad/s)^2


def _otter_dict() -> dict:
    """The Otter's file with thrust-state thrusters (no shaft tables)."""
    text = resources.files("oceangnc.models").joinpath("vehicles", "otter.toml").read_text()
    d = tomllib.loads(text)
    for t in d["thrusters"]:
        t.pop("shaft", None)
    return d


def _with_shaft(shaft: dict, tau: float = 0.1) -> VehicleFile:
    d = _otter_dict()
    for t in d["thrusters"]:
        t["shaft"] = dict(shaft)
        t["time_constant"] = tau
    vf = VehicleFile.model_validate(d)
    _check(vf, "test")
    return vf


def test_the_surge_force_is_k_n_abs_n_of_the_shaft_state_forward_and_reverse():
    """The shaft state n gives thrust k_pos n|n| forward and k_neg n|n| astern: the same acceleration as the
    thrust-state file holding that thrust (any other law, or the wrong coefficient per sign, differs)."""
    shaft = _with_shaft({"k_forward": K_POS, "k_reverse": K_NEG})
    m_n, m_t = vehicle_model(shaft), vehicle_model(VehicleFile.model_validate(_otter_dict()))
    assert m_n.state_names[12:] == ("shaft_left", "shaft_right")
    for n1, n2 in ((80.0, 50.0), (-60.0, 30.0), (-20.0, -70.0)):
        x = np.zeros(14)
        x[12:] = n1, n2
        xt = x.copy()
        xt[12:] = [(K_POS if n > 0 else K_NEG) * n * abs(n) for n in (n1, n2)]
        a, b = m_n.deriv(x, np.zeros(4)), m_t.deriv(xt, np.zeros(4))
        assert np.allclose(a[6:12], b[6:12], rtol=1e-12, atol=1e-12), (n1, n2)
        assert abs(a[6]) > 0.1 and abs(a[11]) > 0.01  # the thrust moved the boat


def test_the_shaft_speed_lags_its_command_and_saturates_at_the_bollard_limits():
    """n' = (n_c - n) / T_n with n_c = sign(T_c) sqrt(|T_c| / k); a command beyond max_forward holds n at
    n_max = sqrt(max_forward / k_pos) (otter.py: 103.93 rad/s); rpm coefficients give the same model."""
    vf = _with_shaft({"k_forward": K_POS, "k_reverse": K_NEG}, tau=0.1)
    m = vehicle_model(vf)
    sh = vf.thrusters[0].shaft
    x = np.zeros(14)
    x[12:] = 10.0, -5.0
    u = np.array([shaft_command(sh, 60.0), shaft_command(sh, -40.0), 0.0, 0.0])
    d = m.deriv(x, u)
    assert d[12] == pytest.approx((60.0 - 10.0) / 0.1, rel=1e-12)
    assert d[13] == pytest.approx((-40.0 + 5.0) / 0.1, rel=1e-12)
    n_max = math.sqrt(119.682 / K_POS)
    assert n_max == pytest.approx(103.93, abs=0.01)
    d = m.deriv(x, np.array([1e4, -1e4, 0.0, 0.0]))
    n_min = -math.sqrt(66.708 / K_NEG)
    assert d[12] == pytest.approx((n_max - 10.0) / 0.1, rel=1e-9)
    assert d[13] == pytest.approx((n_min + 5.0) / 0.1, rel=1e-9)
    rpm = _with_shaft({"unit": "rpm", "k_forward": K_POS * RPM**2, "k_reverse": K_NEG * RPM**2})
    assert np.allclose(vehicle_model(rpm).p, m.p, rtol=1e-12)
    assert shaft_command(rpm.thrusters[0].shaft, 600.0, "rpm") == pytest.approx(K_POS * (600 * RPM) ** 2)


def test_a_step_in_shaft_speed_reaches_63_percent_after_one_time_constant():
    """Integrated: from rest, n(T_n) = (1 - e^-1) n_c, and the logged state converts back to thrust k n|n|."""
    vf = _with_shaft({"k_forward": K_POS, "k_reverse": K_NEG}, tau=0.5)
    m = vehicle_model(vf)
    t = np.linspace(0.0, 0.5, 11)
    u = [shaft_command(vf.thrusters[0].shaft, 80.0), shaft_command(vf.thrusters[0].shaft, -80.0), 0.0, 0.0]
    X = m.simulate(t, np.tile(u, (t.size, 1)), np.zeros(14), substeps=20)
    assert X[-1, 12] == pytest.approx(80.0 * (1 - math.exp(-1)), rel=1e-6)
    assert X[-1, 13] == pytest.approx(-80.0 * (1 - math.exp(-1)), rel=1e-6)
    thr = thrusts_from_states(vf, X[:, 12:])
    assert thr[-1, 0] == pytest.approx(K_POS * X[-1, 12] ** 2) and thr[-1, 1] == pytest.approx(-K_NEG * X[-1, 13] ** 2)


def test_the_advance_term_and_the_shaft_torque_act_forward_only():
    """remus100.py's linear K_T(J), K_Q(J): T = k_fwd n|n| + k_adv |n| (1 - w) U_r and a torque about the
    thrust axis (roll for a stern propeller), for n > 0 only."""
    shaft = {"k_forward": K_POS, "k_reverse": K_NEG, "k_advance": -0.2, "wake": 0.056, "q_forward": 1e-3}
    vf = _with_shaft(shaft, tau=0.1)
    base = vehicle_model(_with_shaft({"k_forward": K_POS, "k_reverse": K_NEG}))
    m = vehicle_model(vf)
    x = np.zeros(14)
    x[6], x[12:] = 1.5, (50.0, 50.0)
    mi = np.linalg.inv(m.p[m.layout.block("M_inv")].reshape(6, 6))
    dtau = mi @ (m.deriv(x, np.zeros(4))[6:12] - base.deriv(x, np.zeros(4))[6:12])
    assert dtau[0] == pytest.approx(2 * -0.2 * 50.0 * (1 - 0.056) * 1.5, rel=1e-9)
    assert dtau[3] == pytest.approx(2 * 1e-3 * 2500.0, rel=1e-9)
    x[12:] = -50.0, -50.0
    dtau = mi @ (m.deriv(x, np.zeros(4))[6:12] - base.deriv(x, np.zeros(4))[6:12])
    assert np.allclose(dtau, 0.0, atol=1e-9)


def test_a_shaft_table_with_a_bad_coefficient_is_refused_naming_the_key(tmp_path):
    from oceangnc.models.vehicle import load_vehicle

    text = resources.files("oceangnc.models").joinpath("vehicles", "otter.toml").read_text()
    text = text.replace("k_forward = 0.01108", "k_forward = -1.0")
    f = tmp_path / "v.toml"
    f.write_text(text)
    with pytest.raises(ConfigError, match="k_forward"):
        load_vehicle(f)
