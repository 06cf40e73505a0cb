"""Control surfaces of a vehicle file (``[[fins]]``, :mod:`oceangnc.models._fins`; issue 38): lift
-1/2 rho U_p^2 A C_L,delta delta on the fin's plane, induced drag with delta^2, saturation at delta_max,
first-order angle lag, and the moment r x F about CO."""

from __future__ import annotations

import math

import numpy as np
import pytest

from oceangnc.models._fins import Fin
from oceangnc.models.vehicle import load_vehicle, vehicle_model, vehicle_params

RUDDER = Fin(name="rudder", plane="rudder", position=(-0.8, 0.0, 0.0), area=0.0133, cl_delta=0.5,
             max_angle_deg=15.0, time_constant=0.1)  # fmt: skip
STERN = Fin(name="stern", plane="stern", position=(-0.8, 0.0, 0.0), area=0.0133, cl_delta=0.7,
            max_angle_deg=15.0, time_constant=0.0)  # fmt: skip


@pytest.fixture(scope="module")
def auv():
    vf = load_vehicle("bluerov2-heavy")
    vf = vf.model_copy(update={"fins": [RUDDER, STERN]})
    return vf, vehicle_model(vf)


def _force(vf, m, delta_r, cmd_r, cmd_s, u=2.0, v=0.3, w=-0.2):
    """The generalised force the fins add (N, N m): (M_RB + M_A)(nu'(fins) - nu'(fins at 0)), at depth 5 m."""
    n = len(vf.thrusters)
    x = np.zeros(m.nx)
    x[2], x[6], x[7], x[8] = 5.0, u, v, w
    x[12 + n] = delta_r
    uin = np.zeros(m.nu)
    uin[n], uin[n + 1] = cmd_r, cmd_s
    d1 = m.deriv(x, uin)
    x0, u0 = x.copy(), np.zeros(m.nu)
    x0[12 + n] = 0.0
    d0 = m.deriv(x0, u0)
    p = vehicle_params(vf)
    from oceangnc.models.vehicle import P_MA, P_MRB

    M = p[P_MRB : P_MRB + 36].reshape(6, 6) + p[P_MA : P_MA + 36].reshape(6, 6)
    return M @ (d1[6:12] - d0[6:12]), d1


def test_rudder_and_stern_plane_forces_lag_and_saturation(auv):
    vf, m = auv
    n = len(vf.thrusters)
    rho = vf.hydrostatics.rho
    d = math.radians(10.0)
    tau, d1 = _force(vf, m, d, d, 0.0)
    q = 0.5 * rho * (2.0**2 + 0.3**2) * 0.0133 * 0.5
    np.testing.assert_allclose(tau, [-q * d * d, -q * d, 0.0, 0.0, 0.0, -0.8 * -q * d], rtol=1e-9, atol=1e-9)
    assert tau[5] > 0  # positive rudder: bow to starboard
    assert d1[12 + n] == pytest.approx(0.0)  # at its command: no motion of the angle
    _, d2 = _force(vf, m, 0.0, math.radians(40.0), 0.0)
    assert d2[12 + n] == pytest.approx(math.radians(15.0) / 0.1)  # saturated command, lag 0.1 s
    tau_s, _ = _force(vf, m, 0.0, 0.0, math.radians(40.0))  # stern plane: no lag, saturated at 15 deg
    ds = math.radians(15.0)
    qs = 0.5 * rho * (2.0**2 + 0.2**2) * 0.0133 * 0.7
    np.testing.assert_allclose(tau_s, [-qs * ds * ds, 0.0, -qs * ds, 0.0, 0.8 * -qs * ds, 0.0], rtol=1e-9, atol=1e-9)
    assert tau_s[4] < 0  # positive stern plane: bow down
    assert list(m.state_names[-2:]) == ["fin_rudder", "fin_stern"]
    assert list(m.input_names[-4:]) == ["fin_rudder_cmd", "fin_stern_cmd", "current_n", "current_e"]
