"""Cable of 003 ch. 2.3 and the coupled USV + cable + UUV plant: statics, energy, stability, bad input."""

import math

import numpy as np
import pytest

import oceangnc
from oceangnc.api import resolve_config
from oceangnc.core.clock import Simulation
from oceangnc.errors import ConfigError, DivergenceError
from oceangnc.models.cable import (
    CableConfig,
    atan_ratio,
    axial_stability_limit,
    cable_loads,
    loading_functions,
    stable_step,
)
from oceangnc.models.combined import CombinedPlant
from oceangnc.models.usv import USVConfig
from oceangnc.models.uuv import UUVConfig
from oceangnc.units import G
from oceangnc.validation.physics import quasi_static_hang


def _run(name, tmp_path, **over):
    return oceangnc.run(name, overrides=over, out=tmp_path / name, plots=False).summary


# --- statics ---------------------------------------------------------------------------------------


def test_hanging_top_tension_is_submerged_weight(tmp_path):
    """Still water: the hanging cable + UUV settles with the top tension equal to the submerged weight
    of the cable plus the UUV (within 1 %), vertical."""
    s = _run("cable-current", tmp_path, **{"environment.current.speed": 0.0})
    w = CableConfig().weight_per_length * 3.0 + 12.0 * G
    assert s["cable.top_tension_N"] == pytest.approx(w, rel=0.01)
    assert s["cable.bottom_tension_N"] == pytest.approx(
        12.0 * G + 0.5 * CableConfig().weight_per_length * 0.15, rel=0.01
    )
    assert s["cable.angle_deg"] < 0.5
    assert s["uuv.offset_m"] < 0.02


def _quasi_static(current: float, theta_hint: float, cable_over: dict | None = None):
    """The independent continuous quasi-static solution of the validation registry (shooting on the UUV's
    pitch balance + catenary-with-drag ODE, :func:`oceangnc.validation.physics.quasi_static_hang`):
    top tension (N), bottom tension (N), angle of the top-to-bottom line from vertical (deg), UUV pitch (deg)."""
    q = quasi_static_hang(current, theta_hint, cable_over=cable_over)
    return q["top_tension_N"], q["bottom_tension_N"], q["angle_deg"], q["pitch_deg"]


@pytest.mark.parametrize("current", [0.25, 0.5, 1.0])
def test_equilibrium_in_current_matches_quasi_static_solution(tmp_path, current):
    """Settled lumped-mass equilibrium in a current matches the independent continuous quasi-static
    solution (shooting on the UUV's pitch balance + catenary-with-drag ODE): 5 % on tensions, 2 deg on
    the cable angle and on the UUV pitch (measured agreement: 5 significant digits). 003 fig 2-10: the
    cable is pushed back by the current."""
    s = _run("cable-current", tmp_path, **{"environment.current.speed": current})
    assert s["cable.settled"]
    top, bottom, angle, pitch = _quasi_static(current, math.radians(s["uuv.pitch_deg"]))
    assert s["cable.top_tension_N"] == pytest.approx(top, rel=0.05)
    assert s["cable.bottom_tension_N"] == pytest.approx(bottom, rel=0.05)
    assert s["cable.angle_deg"] == pytest.approx(angle, abs=2.0)
    assert s["uuv.pitch_deg"] == pytest.approx(pitch, abs=2.0)
    assert s["cable.angle_deg"] > 1.0  # pushed back


# --- energy ------------------------------------------------------------------------------------------


def _conservative_plant(x_off=0.6, **cable):
    """Top fixed, still water, no drag, no damping, no added mass on the cable, UUV damping off; the
    UUV 0.6 m aside with the cable just taut (3.1 m between the ends), so it swings and bounces."""
    cc = CableConfig(drag_on=False, damping=0.0, added_mass_coeff=0.0, **cable)
    uc = UUVConfig(damping_on=False, x0=x_off, z0=3.166)
    return CombinedPlant(USVConfig(), uc, cc, top="fixed")


def test_energy_conserved_without_drag_and_damping():
    """Cable + UUV with drag, damping and cable added mass off conserve mechanical energy to RK4's
    accuracy: the largest energy error over 10 s of a swinging, bouncing pendulum is below 1e-5 of the
    energy of its initial 0.6 m swing at 20 % of the stability limit, and falls by more than 8x when the
    step is halved (fourth-order RK4: 16x asymptotically). The cable's added
    mass (003 eq. 2.28) is off because a mass matrix that turns with the segment is not derived from a
    Lagrangian: with it the lumped model is not exactly conservative."""
    errs = []
    for frac in (0.2, 0.1):
        pl = _conservative_plant()
        dt = frac * pl.stability_limit
        e0 = pl.energy()
        es = []
        t = 0.0
        for _ in range(100):
            t = pl.advance(t, dt, int(round(0.1 / dt)))
            es.append(pl.energy())
        errs.append(max(abs(np.array(es) - e0)))
    scale = 12.0 * G * 0.6  # potential energy of the UUV's initial 0.6 m swing, order of the motion
    assert errs[0] < 1e-5 * scale
    assert errs[0] / errs[1] > 8.0


@pytest.mark.parametrize("integrator", ["rk4", "rk4-split"])
def test_energy_only_decreases_with_drag_and_damping(integrator):
    """With drag, axial damping and UUV damping on (cable added mass off, see above), energy never rises,
    with both integrators (the split one damps implicitly: backward Euler is dissipative)."""
    cc = CableConfig(added_mass_coeff=0.0, integrator=integrator)
    pl = CombinedPlant(USVConfig(), UUVConfig(x0=0.6, z0=2.9), cc, top="fixed")
    dt = 0.8 * pl.stability_limit
    e_prev = pl.energy()
    e0 = e_prev
    t = 0.0
    for _ in range(200):
        t = pl.advance(t, dt, int(round(0.05 / dt)))
        e = pl.energy()
        assert e <= e_prev + 1e-6 * abs(e0)
        e_prev = e
    assert e_prev < e0 - 1.0  # and it did dissipate


# --- tension only, stability --------------------------------------------------------------------------


def test_slack_cable_has_no_compression():
    """Nodes closer than l0 (slack) and even approaching each other give no axial force at all."""
    n = 4
    l0 = 0.5
    pos = np.zeros(3 * (n + 1))
    pos[2::3] = np.linspace(0.0, 1.2, n + 1)  # 0.3 m spacing < 0.5 m
    vel = np.zeros(3 * (n + 1))
    vel[2::3] = -np.linspace(0.0, 1.0, n + 1)  # closing up
    F = np.zeros(3 * (n + 1))
    Mn = np.zeros(6 * (n + 1))
    cable_loads(pos, vel, F, Mn, n, l0, 1e4, 100.0, 1.0, 0.0, 0.0, 0.0, 0.0, 0.0)
    assert np.all(F == 0.0)
    # stretched but closing fast: the damping may cancel tension but never push
    pos[2::3] = np.linspace(0.0, 2.04, n + 1)  # spacing 0.51 m: 2 % strain
    vel[2::3] = -np.linspace(0.0, 10.0, n + 1)
    cable_loads(pos, vel, F, Mn, n, l0, 1e4, 100.0, 1.0, 0.0, 0.0, 0.0, 0.0, 0.0)
    assert np.all(F == 0.0)
    vel[:] = 0.0
    cable_loads(pos, vel, F, Mn, n, l0, 1e4, 100.0, 1.0, 0.0, 0.0, 0.0, 0.0, 0.0)
    assert F[2] == pytest.approx(1e4 * 0.02)  # at rest: EA * strain pulls the top node down


def test_slack_cable_carries_no_tension_in_simulation():
    """A UUV released 1 m above the taut position free-falls with zero bottom tension until taut."""
    pl = CombinedPlant(USVConfig(), UUVConfig(z0=2.0), CableConfig(), top="fixed")
    bus = {}
    t = 0.0
    dt = stable_step(pl.stability_limit)
    t = pl.advance(t, dt, int(round(0.2 / dt)))
    pl.publish(bus)
    assert bus["cable.bottom_tension"] < 0.5 * CableConfig().weight_per_length * 0.15 + 1e-6
    assert bus["uuv.w"] > 0.1  # falling


@pytest.mark.parametrize("integrator,lo,hi,over", [("rk4", 1e-3, 3e-3, 1.05), ("rk4-split", 3e-3, 6e-3, 1.3)])
def test_stability_limit_is_real(integrator, lo, hi, over):
    """The computed limit is sharp: at 0.97x the hanging cable settles (node speeds of cm/s after 5 s),
    at 1.05x the highest axial mode grows until segments go slack and the cable chatters (node speeds
    5x larger; tension-only caps the growth, so it chatters instead of diverging). RK4: ~1.9 ms
    (overdamped highest axial mode); split (damping implicit): ~4.3 ms from the explicit part (springs and
    the last damper), which is conservative: the split scheme goes unstable between 1.1x and 1.2x (1.3x
    tested)."""
    cc = CableConfig(integrator=integrator)
    limit = CombinedPlant(USVConfig(), UUVConfig(), cc, top="fixed").stability_limit
    assert lo < limit < hi
    n = cc.segments
    speeds = []
    for frac in (0.97, over):
        pl = CombinedPlant(USVConfig(), UUVConfig(z0=3.2), cc, top="fixed")
        try:
            pl.advance(0.0, frac * limit, int(5.0 / (frac * limit)))
            speeds.append(float(np.max(np.abs(pl.x[6 + 3 * (n - 1) : 6 + 6 * (n - 1)]))))
        except DivergenceError:
            speeds.append(math.inf)
    assert speeds[0] < 0.1
    assert speeds[1] > 5 * speeds[0]


def test_stability_limit_scales_with_stiffness():
    """Undamped chain: the limit is 2.785 / omega_max with omega_max -> 2 sqrt(k/m) (RK4 on the imaginary
    axis); stiffer cable -> smaller step, proportional to 1/sqrt(EA)."""
    cc = CableConfig(damping=0.0)
    h = axial_stability_limit(cc, end_mass=None)
    k, m = cc.EA / cc.l0, cc.segment_mass
    n = cc.segments
    w_max = 2 * math.sqrt(k / m) * math.sin((n - 1) * math.pi / (2 * n))
    assert h == pytest.approx(2 * math.sqrt(2) / w_max, rel=1e-3)
    h4 = axial_stability_limit(CableConfig(damping=0.0, E=4 * 7.5e6), end_mass=None)
    assert h4 == pytest.approx(h / 2, rel=1e-6)


def test_step_above_limit_is_refused(tmp_path):
    """sim.dt above the cable's stability limit is a ConfigError naming sim.dt and the limit."""
    pl = CombinedPlant(USVConfig(), UUVConfig(), CableConfig(), top="fixed")
    assert pl.max_dt == pl.stability_limit
    with pytest.raises(ConfigError, match=r"sim\.dt.*stability limit"):
        Simulation([pl], [], 0.01, 0.1)
    with pytest.raises(ConfigError, match=r"sim\.dt"):
        oceangnc.run("cable-current", overrides={"sim.dt": 0.01}, out=tmp_path / "refused", plots=False)


@pytest.mark.parametrize(
    "key,val",
    [
        ("cable.segments", 0),
        ("cable.length", 0.0),
        ("cable.diameter", -0.01),
        ("cable.E", 0.0),
        ("cable.density", 0.0),
        ("uuv.mass", -1.0),
    ],
)
def test_bad_cable_config_is_a_config_error(key, val):
    """Segments < 1, non-positive length, diameter, modulus (hence EA) or mass: one-line ConfigError."""
    with pytest.raises(ConfigError, match=key.replace(".", r"\.")):
        resolve_config("cable-current", overrides={key: val})


# --- pieces --------------------------------------------------------------------------------------------


def test_loading_functions_limits():
    """003 eq. 2.25: f_p = 0 along the flow and 1 across it; f_q = 0.02 along and ~0 across."""
    fp0, fq0 = loading_functions(0.0)
    fp1, fq1 = loading_functions(math.pi / 2)
    assert fp0 == pytest.approx(0.0, abs=1e-12) and fp1 == pytest.approx(1.0)
    assert fq0 == pytest.approx(0.02008) and fq1 == pytest.approx(0.0, abs=1e-4)
    for y, x in ((0.3, 1.0), (1.0, 0.2), (0.0, 1.0), (2.0, 2.0)):
        assert atan_ratio(y, x) == pytest.approx(math.atan2(y, x), abs=5e-8)


def test_tow_straight_depth_change_figs_4_2_to_4_5(tmp_path):
    """003 figs 4-2 to 4-5: USV at 0.5 m/s with the UUV commanded 0.27 m/s: the UUV is dragged up by
    a large depth change (> 0.3 m); with 0.48 m/s the change is small (< 0.15 m, and < 1/4 of the other)."""
    slow = _run("tow-straight", tmp_path / "a", **{"command.uuv_speed": 0.27, "sim.duration": 60.0})
    fast = _run("tow-straight", tmp_path / "b", **{"command.uuv_speed": 0.48, "sim.duration": 60.0})
    assert slow["usv.speed_final_mps"] == pytest.approx(0.5, abs=0.02)
    assert slow["uuv.depth_change_max_m"] > 0.3
    assert fast["uuv.depth_change_max_m"] < 0.15
    assert fast["uuv.depth_change_max_m"] < 0.25 * slow["uuv.depth_change_max_m"]
    assert slow["uuv.depth_final_m"] < fast["uuv.depth_final_m"]  # the slow UUV rides higher


def test_automatic_step_divides_the_control_period():
    """stable_step: the largest step <= 90 % of the limit that divides 10 ms an integer number of times."""
    for lim in (1.943e-3, 4.342e-3, 0.098e-3, 0.02):
        h = stable_step(lim, 0.01, 0.9)
        k = round(0.01 / h)
        assert abs(k * h - 0.01) < 1e-12
        assert h <= 0.9 * lim + 1e-15
        if k > 1:
            assert 0.01 / (k - 1) > 0.9 * lim  # the next larger divisor would exceed it


def test_split_integrator_matches_rk4():
    """The Strang-split integrator (implicit axial damping, 2x the step) follows plain RK4 through the
    onset of a 0.5 m/s current: UUV depth within 1 mm, top tension within 2 % of its peak, 20 s."""
    out = {}
    for integ in ("rk4", "rk4-split"):
        pl = CombinedPlant(USVConfig(), UUVConfig(psi0_deg=180.0, z0=3.25), CableConfig(integrator=integ), top="fixed")
        pl.u[2] = 0.5
        dt = stable_step(pl.stability_limit)
        rows = []
        bus = {}
        t = 0.0
        for _ in range(100):
            t = pl.advance(t, dt, int(round(0.2 / dt)))
            pl.publish(bus)
            rows.append((bus["uuv.z"], bus["cable.top_tension"]))
        out[integ] = np.array(rows)
    a, b = out["rk4"], out["rk4-split"]
    assert np.max(np.abs(a[:, 0] - b[:, 0])) < 1e-3
    assert np.max(np.abs(a[:, 1] - b[:, 1])) < 0.02 * np.max(a[:, 1])


# --- implicit (IMEX) integrator (issue 19) ---------------------------------------------------------------


def test_imex_at_control_period_still_water_tension(tmp_path):
    """cable.integrator = "imex" at dt = 10 ms (5x the explicit limit): stable, and the hanging cable's top
    tension equals the submerged weight of cable + UUV within 1 %."""
    pl = CombinedPlant(USVConfig(), UUVConfig(), CableConfig(integrator="imex"), top="fixed")
    assert pl.max_dt is None  # no axial step limit
    s = _run(
        "cable-current", tmp_path, **{"environment.current.speed": 0.0, "cable.integrator": "imex", "sim.dt": 0.01}
    )
    w = CableConfig().weight_per_length * 3.0 + 12.0 * G
    assert s["cable.top_tension_N"] == pytest.approx(w, rel=0.01)
    assert s["cable.settled"]


@pytest.mark.parametrize("current", [0.25, 0.5, 1.0])
def test_imex_equilibrium_in_current(tmp_path, current):
    """At dt = 10 ms the implicit integrator reaches the same equilibria in current as the explicit ones, within
    the tolerances of the quasi-static comparison above (5 % tension, 2 deg angle and pitch)."""
    s = _run(
        "cable-current", tmp_path, **{"environment.current.speed": current, "cable.integrator": "imex", "sim.dt": 0.01}
    )
    assert s["cable.settled"]
    top, bottom, angle, pitch = _quasi_static(current, math.radians(s["uuv.pitch_deg"]))
    assert s["cable.top_tension_N"] == pytest.approx(top, rel=0.05)
    assert s["cable.bottom_tension_N"] == pytest.approx(bottom, rel=0.05)
    assert s["cable.angle_deg"] == pytest.approx(angle, abs=2.0)
    assert s["uuv.pitch_deg"] == pytest.approx(pitch, abs=2.0)


def _onset(integrator, dt, t_sim=10.0):
    pl = CombinedPlant(USVConfig(), UUVConfig(psi0_deg=180.0, z0=3.25), CableConfig(integrator=integrator), top="fixed")
    pl.u[2] = 0.5
    bus, rows, t = {}, [], 0.0
    for _ in range(int(round(t_sim / 0.1))):
        t = pl.advance(t, dt, int(round(0.1 / dt)))
        pl.publish(bus)
        rows.append((bus["uuv.z"], bus["cable.top_tension"]))
    return np.array(rows)


def test_imex_converges_at_second_order():
    """Onset of a 0.5 m/s current (10 s) against RK4 at 0.1 ms: the implicit scheme's top-tension error falls
    by more than 3x when the step is halved from 2 ms to 1 ms (second order: 4x), and at the 10 ms control
    period the UUV depth is within 1 mm and the top tension within 3 % of its peak (measured: 0.4 mm, 1.4 %)."""
    ref = _onset("rk4", 1e-4)
    e = {dt: np.max(np.abs(_onset("imex", dt) - ref), axis=0) for dt in (0.01, 0.002, 0.001)}
    assert e[0.002][1] / e[0.001][1] > 3.0
    assert e[0.01][0] < 1e-3
    assert e[0.01][1] < 0.03 * np.max(ref[:, 1])


def test_imex_cost_grows_linearly_with_segments():
    """Cost of one implicit step (block-tridiagonal solve, O(n)): 80 segments cost less than 8x 20 segments
    (linear: 4x; a dense solve would be 64x)."""
    import time

    cost = {}
    for n in (20, 80):
        pl = CombinedPlant(
            USVConfig(), UUVConfig(psi0_deg=180.0, z0=3.25), CableConfig(segments=n, integrator="imex"), top="fixed"
        )
        pl.u[2] = 0.5
        pl.advance(0.0, 0.01, 10)
        best = math.inf
        for _ in range(3):
            c0 = time.process_time()
            pl.advance(0.0, 0.01, 2000)
            best = min(best, time.process_time() - c0)
        cost[n] = best
    assert cost[80] / cost[20] < 8.0


# --- long cables (issue 16) ------------------------------------------------------------------------------


def test_segment_count_follows_length():
    """Default segment count max(20, ceil(L / 2 m)); cable.segment_length as the alternative; both: refused."""
    assert CableConfig().segments == 20
    assert CableConfig(length=100.0).segments == 50
    assert CableConfig(length=300.0).segments == 150
    assert CableConfig(length=30.0, segment_length=1.5).segments == 20
    with pytest.raises(ConfigError, match=r"cable\.segments and cable\.segment_length"):
        resolve_config("cable-current", overrides={"cable.segments": 10, "cable.segment_length": 1.0})
    with pytest.raises(ConfigError, match=r"cable\.segment_length"):
        resolve_config("cable-current", overrides={"cable.length": 300.0, "cable.segment_length": 0.01})


@pytest.mark.slow
@pytest.mark.parametrize("length,current", [(100.0, 0.25), (300.0, 0.1)])
def test_long_cable_statics_in_current(length, current):
    """100 m (50 segments) and 300 m (150 segments) cables with the UUV in a uniform current, implicit
    integrator at 20 ms, settled: top tension within 2 % and the top-to-bottom angle within 1 deg of the
    independent shooting solution (continuous catenary with drag, UUV pitch balance)."""
    cc = CableConfig(length=length, integrator="imex")
    uc = UUVConfig(psi0_deg=180.0, z0=length * 1.05)
    pl = CombinedPlant(USVConfig(), uc, cc, top="fixed")
    pl.u[2] = current
    bus, t, hist = {}, 0.0, []
    for _ in range(int(1500 / 10)):
        t = pl.advance(t, 0.02, 500)
        pl.publish(bus)
        hist.append((bus["cable.top_tension"], bus["cable.angle_deg"]))
    h = np.array(hist[-5:])
    assert np.ptp(h[:, 0]) < 0.002 * h[-1, 0] and np.ptp(h[:, 1]) < 0.05  # settled
    top, _, angle, _ = _quasi_static(current, bus["uuv.theta"], {"length": length})
    assert bus["cable.top_tension"] == pytest.approx(top, rel=0.02)
    assert bus["cable.angle_deg"] == pytest.approx(angle, abs=1.0)


# --- drag laws -------------------------------------------------------------------------------------------


def test_normal_tangential_drag_law():
    """drag_law = "normal-tangential": -1/2 rho C_dn d l |V_n| V_n and -1/2 rho C_dt pi d l |v_t| v_t (each
    half on each node); across the flow it equals the loading-function law (f_p(90 deg) = 1) with C_dn = C_d."""
    cc = CableConfig(drag_law="normal-tangential")
    n, l0 = 1, 1.0
    pos = np.zeros(6)
    pos[5] = 0.999  # vertical, slack: no tension
    F = np.zeros(6)
    Mn = np.zeros(12)
    kn = 0.5 * 1000.0 * cc.cd_n * cc.diameter * l0
    kt = 0.5 * 1000.0 * cc.cd_t * math.pi * cc.diameter * l0
    vel = np.zeros(6)
    vc = (0.6, 0.0)  # current across the (vertical) cable
    cable_loads(pos, vel, F, Mn, n, l0, 1e4, 0.0, 1.0, 0.0, 0.0, kn, *vc, -1.0, 1, kt)
    assert F[0] + F[3] == pytest.approx(kn * 0.36)
    F2 = np.zeros(6)
    cable_loads(pos, vel, F2, Mn, n, l0, 1e4, 0.0, 1.0, 0.0, 0.0, kn, *vc)
    assert F2[0] + F2[3] == pytest.approx(F[0] + F[3], rel=1e-3)  # loading functions at 90 deg
    vel[2] = vel[5] = -0.8  # moving up along the cable in still water: tangential drag only
    F3 = np.zeros(6)
    cable_loads(pos, vel, F3, Mn, n, l0, 1e4, 0.0, 1.0, 0.0, 0.0, kn, 0.0, 0.0, -1.0, 1, kt)
    assert F3[2] + F3[5] == pytest.approx(kt * 0.64)
    assert F3[0] == 0.0 and F3[1] == 0.0
