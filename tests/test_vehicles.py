"""Your own vehicle (issue 30): the generic 6-DOF form of oceangnc.models.vehicle, its files and checks."""

from __future__ import annotations

import time

import numpy as np
import pytest

from oceangnc.core.model import get_model
from oceangnc.errors import ConfigError
from oceangnc.models.uuv import uuv_model
from oceangnc.models.vehicle import (
    P_DL,
    P_DQ,
    P_DU,
    hoerner_cd,
    load_vehicle,
    shipped_vehicles,
    thruster_matrix,
    vehicle_deriv,
    vehicle_energy,
    vehicle_model,
)


def test_the_003_uuv_in_the_generic_form_flies_like_its_dedicated_model():
    """Round trip of the form (not a validation): the 003 UUV's file (numbers taken from
    oceangnc.models.uuv) and the dedicated right-hand side give the same trajectories for a manoeuvre
    set with current; the arithmetic differs in summation order only, so 1e-9 relative."""
    ref, gen = uuv_model(), vehicle_model("uuv-003")
    t = np.linspace(0.0, 30.0, 301)
    manoeuvres = [
        (30.0, 30.0, 0.0, 0.0, 0.0),  # straight ahead
        (40.0, 10.0, 5.0, 0.2, -0.1),  # turning, bow thrust, in a current
        (-15.0, 25.0, -8.0, -0.3, 0.3),  # reversing one side
    ]
    x0 = np.zeros(12)
    x0[2], x0[6] = 3.0, 0.5
    for m in manoeuvres:
        U = np.tile(m, (t.size, 1))
        a = ref.simulate(t, U, x0, substeps=20)
        b = gen.simulate(t, U, np.concatenate([x0, np.zeros(3)]), substeps=20)[:, :12]
        scale = np.maximum(np.abs(a).max(axis=0), 1e-3)
        assert np.max(np.abs(a - b) / scale) < 1e-9, m
        assert np.ptp(a[:, 0]) > 1.0  # the manoeuvre moved the vehicle


@pytest.mark.parametrize("munk", [1.0, 0.0], ids=["full-C_A", "munk-yaw-neglected"])
@pytest.mark.parametrize("name", ["bluerov2-heavy", "otter", "uuv-003"])
def test_kinetic_energy_is_conserved_without_damping_thrust_or_restoring_work(name, munk):
    """Physical law: C_RB and C_A are skew-symmetric, so with D = 0 (cross-flow drag too), no thrust, and
    weight and buoyancy balanced at one point (no restoring work) 1/2 nu^T M nu stays constant (RK4: to its
    order). With the Munk moment in yaw neglected (munk_yaw = 0, the Otter's file) C_A drops it with its
    surge and sway partners and stays skew-symmetric: dropping the yaw moment alone did work ~ u v r."""
    m = vehicle_model(name)
    p = m.p.copy()
    p[P_DL : P_DL + 36] = 0.0
    p[P_DQ : P_DQ + 6] = 0.0
    p[P_DU : P_DU + 36] = 0.0
    lay = m.layout
    p[lay.index("cf_strips")] = 0.0
    p[lay.index("linear_restoring")] = 0.0
    p[lay.index("munk_yaw")] = munk
    p[lay.index("B")] = p[lay.index("W")]
    p[lay.block("r_b")] = p[lay.block("r_g")]
    p[lay.index("hull_height")] = 0.0  # no free surface: the buoyancy of an emerging hull does work
    x0 = np.zeros(m.nx)
    x0[6:12] = [0.8, -0.3, 0.2, 0.4, -0.3, 0.5]
    t = np.linspace(0.0, 10.0, 101)
    X = m.simulate(t, np.zeros((t.size, m.nu)), x0, substeps=50, p=p)
    e = np.array([vehicle_energy(x, p) for x in X])
    assert np.max(np.abs(e / e[0] - 1.0)) < 1e-7
    assert np.ptp(X[:, 3:6]) > 0.5  # it tumbled: the check saw the Coriolis terms at work
    # and with its damping back (restoring still neutral), kinetic energy is dissipated
    for blk in (slice(P_DL, P_DL + 36), slice(P_DQ, P_DQ + 6), slice(P_DU, P_DU + 36)):
        p[blk] = m.p[blk]
    p[lay.index("cf_strips")] = m.p[lay.index("cf_strips")]
    X = m.simulate(t, np.zeros((t.size, m.nu)), x0, substeps=50, p=p)
    e = np.array([vehicle_energy(x, p) for x in X])
    assert e[-1] < 0.5 * e[0] and np.all(np.diff(e) <= 1e-9 * e[0])


def _crossflow_only(vf_text, tmp_path):
    """Parameters of a file with only its cross-flow drag left, M^-1 = I: dnu/dt is then the cross-flow force."""
    m = vehicle_model(load_vehicle(_write(tmp_path, vf_text)))
    p = m.p.copy()
    lay = m.layout
    for k in ("M_RB", "M_A", "D_L", "D_Q", "D_U", "G_lin"):
        p[lay.block(k)] = 0.0
    p[lay.block("M_inv")] = np.eye(6).ravel()
    return m, p


def _crossflow_force(m, p, v, r):
    x = np.zeros(m.nx)
    x[7], x[11] = v, r
    out = np.zeros(m.nx)
    vehicle_deriv(0.0, x, np.zeros(m.nu), p, out)
    return out[6:12]


def test_crossflow_drag_strip_integral_against_closed_forms(tmp_path):
    """The cross-flow drag of [damping.crossflow] (strip theory, Fossen 2021 ch. 6; Hoerner 1965) against
    integrals done by hand. Otter's pontoon: L = 2 m, B = 0.25 m, T = 0.19512 m, so B / (2 T) = 0.640625 and
    Hoerner's C_d interpolates linearly between his points (0.5585, 1.0836) and (0.6464, 0.9986).
    Pure sway: Y = -1/2 rho C_d T L v|v| exactly (the integrand is constant). Pure yaw about a centred hull:
    N = -1/2 rho C_d T r|r| int x^2 |x| dx = -... L^4 / 32, which the midpoint rule on n (even) strips gives
    as L^4 / 32 (1 - 2 / n^2) (Euler-Maclaurin, exact for a cubic). A hull 0.3 m forward of CO in pure sway
    feels the sway force at its centre: N = 0.3 Y."""
    rho, L, T = 1026.0, 2.0, 0.19512195121951217  # the file's crossflow.rho (crossFlowDrag's) and draft
    cd = 1.0836 + (0.25 / (2 * T) - 0.5585) / (0.6464 - 0.5585) * (0.9986 - 1.0836)
    assert hoerner_cd(0.25, T) == pytest.approx(cd, rel=1e-12)
    k = 0.5 * rho * cd * T
    m, p = _crossflow_only(_otter_text(), tmp_path)
    for v in (0.7, -1.3):
        f = _crossflow_force(m, p, v, 0.0)
        assert f[1] == pytest.approx(-k * L * v * abs(v), rel=1e-12)
        assert abs(f[5]) < 1e-12 and np.all(f[[0, 2, 3, 4]] == 0.0)
    for r, n in ((0.4, 20), (-0.9, 20), (0.4, 200)):
        text = _otter_text().replace("strips = 20", f"strips = {n}")
        mn, pn = _crossflow_only(text, tmp_path)
        f = _crossflow_force(mn, pn, 0.0, r)
        exact = -k * r * abs(r) * L**4 / 32
        assert f[5] == pytest.approx(exact * (1 - 2 / n**2), rel=1e-12)
        assert abs(f[1]) < 1e-12  # symmetric hull: the fore and aft sway forces cancel
    assert f[5] == pytest.approx(exact, rel=1e-4)  # 200 strips: the integral itself
    # sway and yaw rate couple through (v + x r)|v + x r|, which a diagonal D_Q cannot hold
    f_both = _crossflow_force(m, p, 0.5, 0.4)
    f_sum = _crossflow_force(m, p, 0.5, 0.0) + _crossflow_force(m, p, 0.0, 0.4)
    assert abs(f_both[5] - f_sum[5]) > 0.1 * abs(f_sum[5])
    text = _otter_text().replace("strips = 20", "strips = 20\nx_center = 0.3")
    mx, px = _crossflow_only(text, tmp_path)
    f = _crossflow_force(mx, px, 0.8, 0.0)
    assert f[1] == pytest.approx(-k * L * 0.64, rel=1e-12) and f[5] == pytest.approx(0.3 * f[1], rel=1e-12)


def test_shipped_vehicles_are_models_by_name():
    assert {"bluerov2-heavy", "otter", "uuv-003"} <= set(shipped_vehicles())
    rov = get_model("bluerov2-heavy")
    assert rov.nu == 8 + 2 and rov.nx == 12 + 8
    B = thruster_matrix(load_vehicle("bluerov2-heavy"))
    assert np.linalg.matrix_rank(B) == 6  # 8 thrusters reach all six DOF


def _write(tmp_path, text: str):
    base = tmp_path / "v.toml"
    base.write_text(text)
    return base


def _otter_text():
    from importlib import resources

    return resources.files("oceangnc.models").joinpath("vehicles", "otter.toml").read_text()


def test_a_vehicle_with_too_few_thrusters_for_its_dofs_is_refused(tmp_path):
    text = _otter_text().replace('dofs = ["surge", "yaw"]', 'dofs = ["surge", "yaw", "sway"]')
    with pytest.raises(ConfigError, match=r"control\.dofs: 'sway' cannot be controlled by the 2 thrusters"):
        load_vehicle(_write(tmp_path, text))


def test_a_mass_matrix_that_is_not_positive_definite_is_refused(tmp_path):
    text = _otter_text().replace("M_A = [5.5, 82.5,", "M_A = [5.5, -182.5,")
    with pytest.raises(ConfigError, match=r"M_RB \+ M_A is not positive definite"):
        load_vehicle(_write(tmp_path, text))


def test_bad_keys_and_ranges_are_one_line_naming_the_key(tmp_path):
    text = _otter_text().replace("mass = 55.0", "mass = -55.0")
    with pytest.raises(ConfigError, match=r"rigid_body\.parts\.0\.mass") as e:
        load_vehicle(_write(tmp_path, text))
    assert "\n" not in str(e.value)
    with pytest.raises(ConfigError, match=r"unknown key 'rigid_body\.colour'"):
        load_vehicle(_write(tmp_path, _otter_text().replace("[rigid_body]\n", "[rigid_body]\ncolour = 1\n")))
    with pytest.raises(ConfigError, match=r"rigid_body: .*either mass and inertia .* or parts"):
        load_vehicle(_write(tmp_path, _otter_text().replace("[rigid_body]\n", "[rigid_body]\nmass = 80.0\n")))
    with pytest.raises(ConfigError, match="neither a shipped vehicle"):
        load_vehicle("no-such-vehicle")


def test_allocation_meets_the_asked_force_and_scales_into_the_limits():
    """The weighted pseudo-inverse gives B f = tau on the controlled DOFs with the least-norm thrusts;
    past a limit the whole vector is scaled (tau's direction kept); an e-stop zeroes every thruster."""
    from oceangnc.control.thrust_allocation import ThrustAllocation

    vf = load_vehicle("bluerov2-heavy")
    vf = vf.model_copy(update={"control": vf.control.model_copy(update={"priority": None})})  # one tier
    blk = ThrustAllocation(vf, 0.05, "rov")
    B = thruster_matrix(vf)
    keys = [f"rov.tau_{a}" for a in "XYZKMN"]

    def alloc(tau, **extra):
        bus = dict(zip(keys, tau), **extra)
        blk.step(0.0, bus)
        return np.array([bus[k] for k in blk.outputs])

    tau = np.array([10.0, -4.0, 6.0, 0.5, -0.3, 1.2])
    f = alloc(tau)
    np.testing.assert_allclose(B @ f, tau, atol=1e-9)
    f_big = alloc(20 * tau)
    assert np.abs(f_big).max() == pytest.approx(51.48) or -f_big.min() == pytest.approx(40.21)
    np.testing.assert_allclose(B @ f_big / np.linalg.norm(B @ f_big), tau / np.linalg.norm(tau), atol=1e-9)
    assert not alloc(tau, _estop=True).any()


def test_the_rov_holds_position_and_depth_in_a_current(tmp_path):
    from oceangnc.api import run

    r = run("rov-station-keeping", out=tmp_path / "r", plots=False, duration=60)
    s = r.summary
    assert s["status"] == "ok" and s["vehicle"] == "bluerov2-heavy"
    assert s["vehicle.position_error_rms_m"] < 0.1 and s["vehicle.depth_error_rms_m"] < 0.1
    assert s["vehicle.heading_error_rms_deg"] < 2.0
    df = r.df
    assert df["vehicle.z"].iloc[0] == 0.0 and abs(df["vehicle.z"].iloc[-1] - 5.0) < 0.1  # it dived


def test_the_otter_flies_its_route(tmp_path):
    from oceangnc.api import run

    s = run("otter-waypoints", out=tmp_path / "o", plots=False).summary
    assert s["status"] == "ok" and s["guidance.final_leg"] == 4 and s["duration_s"] < 300  # ended at the last
    assert s["guidance.cross_track_rms_m"] < 3.0 and abs(s["vehicle.speed_mean_mps"] - 1.5) < 0.2


def test_a_vehicle_file_runs_fused_and_on_the_python_clock_alike(tmp_path):
    from fused_paths import run_both

    run_both("rov-station-keeping", {}, 5.0, tmp_path)
    run_both("otter-waypoints", {}, 5.0, tmp_path)


def test_a_users_vehicle_file_is_a_scenario_choice(tmp_path):
    """``--set vehicle=path``: a file alone (no Python) is flown; a gain on a DOF it does not control
    is refused naming the key."""
    from oceangnc.api import run

    text = _otter_text().replace('name = "otter"', 'name = "my-boat"').replace("mass = 80.0", "mass = 90.0")
    f = _write(tmp_path, text)
    s = run("otter-waypoints", out=tmp_path / "m", plots=False, duration=20, overrides={"vehicle": str(f)}).summary
    assert s["vehicle"] == "my-boat" and s["status"] == "ok"
    with pytest.raises(ConfigError, match=r"control\.gains\.sway: vehicle 'otter' does not control sway"):
        run("otter-waypoints", out=tmp_path / "n", plots=False, duration=5,
            overrides={"control.gains.sway": [1.0, 0.0, 0.0]})  # fmt: skip


def test_the_ekf_identifies_a_vehicle_files_damping_by_name():
    """Round trip (the generator is the Otter's own file): the augmented EKF (002's method, any model by
    parameter name) recovers the surge and yaw linear damping D_L[0], D_L[35] from noisy positions,
    heading and rates of a manoeuvre, starting 40 % off."""
    from oceangnc.identification.ekf import run_ekf

    m = vehicle_model("otter")
    t = np.arange(0.0, 120.0, 0.1)
    U = np.zeros((t.size, m.nu))
    U[:, 0] = np.where((t // 20) % 2 == 0, 90.0, 40.0)  # left propeller: steps
    U[:, 1] = np.where((t // 30) % 2 == 0, 60.0, 100.0)  # right: other steps
    x0 = np.zeros(m.nx)
    X = m.simulate(t, U, x0, substeps=5)
    rng = np.random.default_rng(3)
    meas = [0, 1, 5, 6, 11]  # x, y, psi, u, r
    sd = np.array([0.05, 0.05, 0.005, 0.02, 0.002])
    Z = X[:, meas] + rng.normal(0.0, sd, (t.size, len(meas)))
    names = ["D_L[0]", "D_L[35]"]
    truth = np.array([m.p[m.layout.index(n)] for n in names])

    res = run_ekf(
        _measuring(m, meas), t, Z, U, names, x0, 0.6 * truth, np.r_[np.full(m.nx, 1e-4), (0.5 * truth) ** 2],
        np.r_[np.full(m.nx, 1e-6), 0.0, 0.0], sd**2, substeps=2,
    )  # fmt: skip
    est = res.X[-1, m.nx :]
    np.testing.assert_allclose(est, truth, rtol=0.05)


def _measuring(m, idx):
    """``m`` with an output function measuring the states ``idx``."""
    from numba import njit

    from oceangnc.core.model import Model

    sel = np.asarray(idx, dtype=np.int64)

    @njit
    def h(t, x, u, p, out):
        for i in range(sel.size):
            out[i] = x[sel[i]]

    outs = [(m.state_names[i], m.state_units[i]) for i in idx]
    return Model(m.name, m.f, list(zip(m.state_names, m.state_units)), list(zip(m.input_names, m.input_units)),
                 m.layout, m.p, h=h, outputs=outs)  # fmt: skip


def test_trim_and_linearisation_take_a_vehicle_file():
    """Analytic check: the Otter running straight at 2 m/s needs a total thrust D_L[0] U (its surge
    damping is linear, Fossen's X_u = -24.4 g / U_max); the linearised surge pole there is
    -D_L[0] / (m + X_udot-added mass)."""
    from oceangnc.core.linearize import linearize, trim

    m = vehicle_model("otter")
    x0 = np.zeros(m.nx)
    x0[6] = 2.0
    x0[12:] = 50.0  # the thruster states (lagged shaft speeds, rad/s) are free too
    u0 = np.array([50.0, 50.0, 0.0, 0.0])
    tr = trim(m, x0, u0, free=("thrust_left_cmd", "thrust_right_cmd", "shaft_left", "shaft_right"),
              zero=("u", "r", "shaft_left", "shaft_right"))  # fmt: skip
    d_l0 = m.p[m.layout.index("D_L[0]")]
    assert tr.u[0] + tr.u[1] == pytest.approx(d_l0 * 2.0, rel=1e-9)
    A = linearize(m, tr.x, tr.u).A
    mrb = m.p[m.layout.index("M_RB[0]")]
    ma = m.p[m.layout.index("M_A[0]")]
    minv = m.p[m.layout.block("M_inv")].reshape(6, 6)
    # d(u')/du at the trim: -(M^-1 D_L)[0, 0] plus the Coriolis terms, which vanish with v = r = 0
    assert A[6, 6] == pytest.approx(-(minv @ m.p[m.layout.block("D_L")].reshape(6, 6))[0, 0], rel=1e-6)
    assert A[6, 6] < -0.5 * d_l0 / (mrb + ma)  # of the order of the surge-only pole (CG offset couples)


VEHICLE_TYPES = [
    ("rov-station-keeping", "MAV_TYPE_SUBMARINE", True),
    ("otter-waypoints", "MAV_TYPE_SURFACE_BOAT", False),
]


@pytest.mark.parametrize(("scenario", "mav_type", "dives"), VEHICLE_TYPES)
def test_a_vehicle_file_is_a_mavlink_vehicle(scenario, mav_type, dives, tmp_path):
    """Ground stations see a vehicle file's craft as what it is (an ROV: MAV_TYPE_SUBMARINE) and where it is
    (its own body's depth, not the 003 USV's), on 127.0.0.1 with bounded waits."""
    from mavlink_gcs import GCS
    from oceangnc.mavlink.protocol import mavlink as M
    from oceangnc.mavlink.vehicle import MavlinkVehicle

    v = MavlinkVehicle(scenario, listen="udp:127.0.0.1:0", speed=4.0, out_root=tmp_path)
    v.start()
    g = GCS(v.address)
    try:
        hb = g.wait("HEARTBEAT", 5.0)
        assert hb.type == getattr(M, mav_type) and hb.get_srcSystem() == 1
        assert v.body == "vehicle"
        v.sim.plants[0].x[0] = 40.0  # the vehicle moved 40 m north (and the ROV 2.5 m down): the telemetry
        v.sim.plants[0].x[2] = 2.5 if dives else 0.0  # follows its own body
        deadline, north = time.monotonic() + 10.0, None
        while time.monotonic() < deadline:
            m = g.wait("GLOBAL_POSITION_INT", 2.0)
            if m.get_srcSystem() == 1 and m.lat > v.cfg_mav.origin_lat_deg * 1e7 + 200:  # 200e-7 deg: 2.2 m
                north, depth = (m.lat / 1e7 - v.cfg_mav.origin_lat_deg) * 111_000.0, -m.relative_alt / 1000.0
                break
        assert north is not None and 30.0 < north < 50.0
        assert (depth > 0.0) == dives  # an ROV reports its depth, a boat floats
    finally:
        g.close()
        v.stop()
