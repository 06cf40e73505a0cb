"""The tow at sea (issue 29): wave loads on the cable and the UUV, the heaving top point, tension
statistics and snap events, the ``tow-sea-state`` scenario and its operability table.

Kinds of evidence: the expansions against the exact Airy sums (the module's own kinematics, an
implementation check); the Morison force on a fixed vertical segment against its closed form (analytic);
the hanging cable under a heaving top against the quasi-static rigid-body limit (analytic,
low-frequency); the snap counter on a case built to go slack (a constructed case); calm water unchanged
(regression: tests/test_baseline.py, and here a zero-amplitude sea against calm water).
"""

from __future__ import annotations

import math

import numpy as np
import pandas as pd
import pytest

from oceangnc.environment.waves import WaveConfig, WaveField
from oceangnc.models._combined_layout import H_SEA, P_UUV
from oceangnc.models._combined_sea import _expand, sea_block, sea_update
from oceangnc.models._sea_layout import NCOEF, S_NPT, S_TMID, coef_base, point_kinematics
from oceangnc.models.cable import CableConfig, cable_loads
from oceangnc.models.combined import CombinedPlant
from oceangnc.models.usv import USVConfig
from oceangnc.models.uuv import P_MA, UUVConfig
from oceangnc.tension import events, tension_statistics
from oceangnc.units import KGF, RHO_WATER, G


def _sea(kind="jonswap", **kw):
    return WaveField.from_config(WaveConfig(kind=kind, **kw), np.random.default_rng(3))


def _hanging(length=10.0, segments=10, E=7.5e6, **kw):
    cc = CableConfig(length=length, segments=segments, E=E, integrator="imex")
    uc = UUVConfig(x0=0.0, z0=length + 0.125)
    pl = CombinedPlant(USVConfig(), uc, cc, top="fixed", **kw)
    return pl


def _run(pl, duration, dt=0.01, tick=0.01):
    bus: dict = {}
    k = int(round(tick / dt))
    t = 0.0
    rows = []
    for _ in range(int(round(duration / tick))):
        t = pl.advance(t, dt, k)
        pl.publish(bus)
        rows.append((t, bus["cable.top_tension"], bus["cable.bottom_tension"], bus["uuv.z"]))
    return np.array(rows)


def test_zero_amplitude_sea_is_calm_water():
    """A sea of zero-amplitude components (every wave branch on, all loads zero) flies as calm water."""
    sea = _sea(hs=1.0)
    sea.a[:] = 0.0
    sea.comps[0, :] = 0.0
    calm = _hanging()
    wet = _hanging(waves=sea, heave="surface")
    a = _run(calm, 20.0)
    b = _run(wet, 20.0)
    assert np.max(np.abs(a - b)) < 1e-9 * np.max(np.abs(a))
    assert np.allclose(calm.x, wet.x, rtol=0, atol=1e-10)


def test_expansions_match_the_exact_kinematics_along_the_track():
    """The second-order expansions equal the exact Airy sums at the expansion time and within the
    interval to 1e-3 of the quantity's amplitude, for still nodes and for the UUV moving at 1.5 m/s."""
    sea = _sea(hs=1.5, tp=6.0)
    pl = _hanging(length=6.0, segments=6, waves=sea, heave="surface")
    o = pl.o_uuv
    pl.x[o + 6] = 1.5  # the UUV moves forward (level, heading north): its track is x + 1.5 tau
    t0 = 17.0
    sea_update(t0, pl.x, pl.p, 0.01)
    s = int(pl.p[H_SEA])
    tm = pl.p[s + S_TMID]
    assert math.isclose(tm, t0 + 0.05)
    c0 = coef_base(pl.p, s)
    n = pl.n
    nodes = np.vstack([[0.0, 0.0, 0.0], pl.x[6 : 6 + 3 * (n - 1)].reshape(-1, 3)])
    worst = 0.0
    for tau in (-0.05, 0.0, 0.03, 0.05):
        for i in range(1, n):  # segments between interior nodes (at rest)
            mid = 0.5 * (nodes[i - 1] + nodes[i])
            _, v, a = sea.kinematics(tm + tau, mid[None, :])
            got = point_kinematics(pl.p, c0 + NCOEF * (i - 1), tau, mid[2])
            scale = np.array([*np.abs(v[0]), *np.abs(a[0])]).max() + 1e-3
            worst = max(worst, float(np.max(np.abs(np.array(got) - np.r_[v[0], a[0]])) / scale))
        cb = pl.x[o : o + 3] + np.array([1.5 * 0.05, 0.0, 0.0])  # the UUV's centre at tm
        _, v, a = sea.kinematics(tm + tau, (cb + np.array([1.5 * tau, 0.0, 0.0]))[None, :])
        got = point_kinematics(pl.p, c0 + NCOEF * (int(pl.p[s + S_NPT]) - 2), tau, cb[2])
        scale = np.array([*np.abs(v[0]), *np.abs(a[0])]).max()
        worst = max(worst, float(np.max(np.abs(np.array(got) - np.r_[v[0], a[0]])) / scale))
    assert worst < 1e-3


def test_morison_force_on_a_fixed_vertical_segment_equals_the_closed_form():
    """A 1 m vertical segment (centre 5 m deep) held in a regular deep-water wave (H 2 m, T 6 s): the
    wave force of :func:`cable_loads` (both nodes, weight removed) equals Morison's equation per unit
    length, f = rho (1 + C_a) A du/dt + 1/2 rho C_d d |u| u (horizontal), rho A dw/dt (vertical,
    Froude-Krylov only), with u = a omega e^{-kd} cos(phi), du/dt = a omega^2 e^{-kd} sin(phi)
    (DNV-RP-C205 eq. 6.2.1 and table 3-1), to 1e-9 at the expansion time and 1e-4 0.05 s away."""
    H, T, d, l0, dia, cd, ca = 2.0, 6.0, 5.0, 1.0, 0.025, 1.2, 1.0
    sea = _sea("regular", hs=H, tp=T)
    w = 2 * math.pi / T
    k = w * w / G
    area = math.pi * dia**2 / 4
    blk = sea_block(sea, 1, 0.1, "none", RHO_WATER, area, l0, 100.0)
    c = coef_base(blk, 0)
    m_a = ca * RHO_WATER * area * l0
    kdrag = 0.5 * RHO_WATER * cd * dia * l0
    pos = np.array([0.0, 0.0, d - 0.5 * l0, 0.0, 0.0, d + 0.5 * l0])
    vel = np.zeros(6)
    F = np.zeros(6)
    Mn = np.zeros(12)
    for tm in np.linspace(0.0, T, 7):
        _expand(blk, 0, c, 0.0, 0.0, d, 0.0, 0.0, tm, True)
        for tau, tol in ((0.0, 1e-9), (0.05, 1e-4)):
            cable_loads(pos, vel, F, Mn, 1, l0, 1e5, 0.0, 1.0, m_a, 0.0, kdrag, 0.0, 0.0, -1.0, 1, 0.0, -1.0, 0.0,
                        blk[c : c + NCOEF], tau, RHO_WATER * area * l0)  # fmt: skip
            fx = F[0] + F[3]
            fz = F[2] + F[5]
            phi = -w * (tm + tau)
            u = H / 2 * w * math.exp(-k * d) * math.cos(phi)
            du = H / 2 * w * w * math.exp(-k * d) * math.sin(phi)
            dw = H / 2 * w * w * math.exp(-k * d) * math.cos(phi)  # dw_D/dt (NED, down)
            ref_x = RHO_WATER * (1 + ca) * area * l0 * du + kdrag * abs(u) * u
            ref_z = RHO_WATER * area * l0 * dw
            scale = RHO_WATER * (1 + ca) * area * l0 * H / 2 * w * w * math.exp(-k * d) + kdrag * (H / 2 * w) ** 2
            assert abs(fx - ref_x) <= tol * scale
            assert abs(fz - ref_z) <= tol * scale
            assert abs(F[1] + F[4]) <= 1e-12


def test_hanging_cable_under_a_heaving_top_follows_the_quasi_static_limit():
    """Top point heaving z = a sin(omega t) (a 0.5 m, T 20 s, far below the axial mode of a stiff 10 m
    cable, 54 rad/s): the top tension is T = W_sub - m_total z'' (quasi-static rigid-body limit of the
    hanging system, Newton's second law), m_total = the moving mass (the cable nodes that carry inertia -
    the two end half-segments carry weight only -, the UUV and its heave added mass M_A33). Its mean
    equals W_sub to 0.5 % and its component in phase with sin(omega t) equals m_total a omega^2 to 2 %
    (the drag parts, in phase with |cos| cos, are orthogonal to it; measured -0.9 %, of which about -1 %
    is the heave-pitch added-mass coupling M_A35 of the free-pitching UUV, which the rigid-body limit
    leaves out). Step 2 ms: at 10 ms the W-method is 7 % off with this 100x stiffer-than-default cable
    (0.6 % with the default one)."""
    a, period = 0.5, 20.0
    pl = _hanging(E=7.5e8, heave="sine", heave_amplitude=a, heave_period=period)
    rows = _run(pl, 5 * period, dt=0.002)
    t, top = rows[:, 0], rows[:, 1]
    sel = t > 2 * period  # three whole periods after the start-up
    w = 2 * math.pi / period
    mean = float(np.mean(top[sel]))
    b1 = 2.0 * float(np.mean((top[sel] - mean) * np.sin(w * t[sel])))
    cc = pl.cable_cfg
    w_sub = cc.weight_per_length * cc.length + pl.uuv_cfg.weight_in_water_kgf * KGF
    ma = pl.p[P_UUV + P_MA : P_UUV + P_MA + 36].reshape(6, 6)[2, 2]
    m_total = (cc.segments - 1) * cc.segment_mass + pl.uuv_cfg.mass + ma  # end half-segments: weight, no inertia
    assert abs(mean - w_sub) < 0.005 * w_sub
    assert abs(b1 - m_total * a * w * w) < 0.02 * m_total * a * w * w


def test_snap_counter_counts_a_cable_built_to_go_slack():
    """A top point heaving 1 m at 2 s accelerates down at up to 9.9 m/s^2, ten times what the hanging
    UUV can follow (W_sub / (m + m_a)): the cable goes slack every cycle and snaps taut again. The
    counter sees slack and snap events; the same cable hanging still has none."""
    pl = _hanging(heave="sine", heave_amplitude=1.0, heave_period=2.0)
    rows = _run(pl, 40.0)
    rows = rows[rows[:, 0] > 10.0]  # after the start (the cable starts unstretched)
    st = tension_statistics(rows[:, 0], rows[:, 1])
    assert st["slack_events"] >= 5
    assert st["snap_events"] >= 3
    assert st["snap_max_N"] > 2 * st["mean_N"]
    still = _run(_hanging(), 40.0)
    still = still[still[:, 0] > 10.0]
    st0 = tension_statistics(still[:, 0], still[:, 1])
    assert st0["slack_events"] == 0 and st0["snap_events"] == 0


def test_events_on_a_constructed_series():
    """Slack runs, the time spent slack, and snaps only within the window after a slack run."""
    t = np.arange(0.0, 100.0, 0.1)
    T = np.full(t.size, 100.0)
    T[100:110] = 0.0  # slack 1 s, then 300 N 0.5 s later: a snap
    T[115] = 300.0
    T[400:405] = 0.0  # slack 0.5 s, then 250 N 5 s later: outside the 2 s window
    T[455] = 250.0
    T[-3:] = 0.0  # slack at the end of the record
    ev = events(t, T, 1.0, 200.0, 2.0)
    assert ev["slack_events"] == 3
    assert ev["snap_events"] == 1
    assert ev["snap_max_N"] == 300.0
    assert math.isclose(ev["slack_time_s"], 1.8, rel_tol=1e-9)
    st = tension_statistics(t, T, slack=1.0)
    assert st["min_N"] == 0.0 and st["max_N"] == 300.0 and st["slack_threshold_N"] == 1.0


def test_tow_sea_state_summary_is_deterministic_and_scored(tmp_path):
    """Two runs with one seed give the same summary; a third seed draws another sea; the pass flag is
    the conjunction of the limits; a tension limit below the maximum fails the run."""
    import oceangnc

    kw = {"duration": 40.0, "plots": False}
    over = {"analysis.settle_s": 10.0, "sim.seed": 4}
    a = oceangnc.run("tow-sea-state", overrides=over, out=tmp_path / "a", **kw).summary
    b = oceangnc.run("tow-sea-state", overrides=over, out=tmp_path / "b", **kw).summary
    c = oceangnc.run("tow-sea-state", overrides={**over, "sim.seed": 5}, out=tmp_path / "c", **kw).summary
    keys = [k for k in a if not k.startswith("wall_time")]
    assert {k: a[k] for k in keys} == {k: b[k] for k in keys}
    assert a["cable.top_std_N"] != c["cable.top_std_N"]
    assert a["cable.top_std_N"] > 0.0 and a["uuv.depth_std_m"] > 0.0
    flags = [a[k] for k in ("limits.tension_ok", "limits.no_snap", "limits.depth_std_ok", "limits.pitch_std_ok")]
    assert a["sea.pass"] == int(all(flags))
    low = oceangnc.run(
        "tow-sea-state",
        overrides={**over, "limits.tension_max_N": 0.5 * a["cable.top_max_N"]},
        out=tmp_path / "d",
        **kw,
    ).summary
    assert low["limits.tension_ok"] == 0 and low["sea.pass"] == 0


def test_operability_table_counts_failures_and_marks_the_failed_limits(tmp_path):
    """Pass fraction per sea state over the seeds, failed/diverged runs counted as not passing, the
    failed limits' letters in the table."""
    from oceangnc.sweep.operability import operability

    rows = []
    for hs in (0.5, 2.0):
        for tp in (4.0, 8.0):
            for seed in (0, 1):
                big = hs > 1.0 and tp < 5.0
                rows.append(
                    {
                        "param.environment.waves.hs": hs,
                        "param.environment.waves.tp": tp,
                        "param.environment.waves.direction_deg": 0.0,
                        "status": "diverged" if (hs > 1 and tp > 5 and seed == 1) else "ok",
                        "sea.pass": 0 if big else 1,
                        "limits.tension_ok": 0 if big else 1,
                        "limits.no_snap": 0 if big else 1,
                        "limits.depth_std_ok": 1,
                        "limits.pitch_std_ok": 1,
                    }
                )
    files = operability(pd.DataFrame(rows), tmp_path, plots=True)
    t = pd.read_csv(files[0])
    frac = {(r["environment.waves.hs"], r["environment.waves.tp"]): r["pass_fraction"] for _, r in t.iterrows()}
    assert frac == {(0.5, 4.0): 1.0, (0.5, 8.0): 1.0, (2.0, 4.0): 0.0, (2.0, 8.0): 0.5}
    md = files[1].read_text()
    assert "| 2 m | TS | " in md and "(50%)" in md
    assert files[2].stat().st_size > 1000


@pytest.mark.slow
def test_operability_sweep_on_a_local_dask_cluster(tmp_path):
    """``oceangnc sweep tow-sea-state`` over Hs x Tp x heading on two local Dask workers, then
    ``sweep-report``: one operability row per sea state, whose pass fraction is the runs' sea.pass."""
    pytest.importorskip("distributed")
    from oceangnc.cli import main
    from oceangnc.sweep import read_results

    out = tmp_path / "ops"
    args = ["sweep", "tow-sea-state", "--grid", "environment.waves.hs=0.5,2.5", "--grid", "environment.waves.tp=5,8"]
    args += ["--grid", "environment.waves.direction_deg=0,180", "--duration", "30", "--set", "analysis.settle_s=10"]
    assert main([*args, "--workers", "2", "--quiet", "--out", str(out)]) == 0
    df = read_results(out)
    assert len(df) == 8 and (df["status"] == "ok").all()
    assert main(["sweep-report", str(out), "--quiet", "--no-plots"]) == 0
    t = pd.read_csv(out / "report" / "operability.csv")
    assert len(t) == 8
    m = t.merge(df, left_on=["environment.waves.hs", "environment.waves.tp", "environment.waves.direction_deg"],
                right_on=["param.environment.waves.hs", "param.environment.waves.tp",
                          "param.environment.waves.direction_deg"])  # fmt: skip
    assert np.array_equal(m["pass_fraction"].to_numpy(), m["sea.pass"].to_numpy().astype(float))
    assert (out / "report" / "operability.md").exists()


#: (scenario, overrides, horizon s): the sea on both paths, for each plant form and integrator
SEA_FUSED = [
    ("tow-sea-state", {"command.start_s": 0.5, "environment.waves.hs": 2.0}, 4.0),
    # the winch inserts a node during a compiled call while the waves load the cable (variable form)
    (
        "tow-deploy",
        {
            "winch_control.profile": [(0.0, 1.3), (0.5, 8.0), (3.0, 8.0), (6.0, 1.3)],
            "environment.waves.kind": "jonswap",
            "environment.waves.hs": 1.0,
        },
        8.0,
    ),
    # the split-RK4 cable of tow-straight in a regular beam sea with the top point held at its depth
    (
        "tow-straight",
        {
            "command.start_s": 0.5,
            "environment.waves.kind": "regular",
            "environment.waves.direction_deg": 90.0,
            "environment.tow_point_heave": "none",
        },
        3.0,
    ),
]


@pytest.mark.parametrize("name,over,dur", SEA_FUSED, ids=["tow-sea-state", "tow-deploy-winch", "tow-straight-split"])
def test_sea_fused_log_equals_python_log(name, over, dur, tmp_path):
    """The wave expansions are refreshed at the same ticks on the fused loop and the Python clock: the
    same log; and the waves do something (the log differs from calm water's)."""
    from fused_paths import run_both, run_path

    sp, sf, a, b, tp, cfg = run_both(name, over, dur, tmp_path)
    calm = {k: v for k, v in over.items() if not k.startswith("environment.")}
    calm["environment.waves.kind"] = "none"
    _, _, c, _ = run_path(name, calm, dur, True, tmp_path / "calm")
    assert np.max(np.abs(a["cable.top_tension"].to_numpy() - c["cable.top_tension"].to_numpy())) > 1.0


def test_a_neutrally_buoyant_uuv_follows_a_uniformly_accelerating_flow():
    """(M_RB + M_A) nu' = (rho V [I 0] + M_A) [R^T a_w; 0] with m = rho V and the centre of gravity at
    the centre of buoyancy has the exact solution nu' = [R^T a_w; 0]: a neutrally buoyant body at rest in
    the flow accelerates with it and does not rotate, whatever its added mass (analytic: the long-wave
    Morison inertia force of a small body; e.g. Maxey & Riley 1983 for the inviscid limit). Checked at a
    tilted attitude, so the rotation R^T is exercised; the calm-water call gives zero acceleration."""
    from oceangnc.models.uuv import uuv_deriv, uuv_deriv_flow

    cfg = UUVConfig(weight_in_water_kgf=0.0, zg=0.0)
    p = cfg.params()
    x = np.zeros(12)
    x[3:6] = (0.3, -0.5, 2.0)  # roll, pitch, yaw (rad)
    aw = np.array([0.4, -0.25, 0.7])  # m/s^2, NED
    out = np.zeros(12)
    uuv_deriv_flow(x, out, p, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, *aw, cfg.buoyancy / G, 0.0, 0.0, 0.0, True)
    from oceangnc.core.rotations import rzyx_entries

    R = np.array(rzyx_entries(*x[3:6])).reshape(3, 3)
    assert np.allclose(out[6:9], R.T @ aw, rtol=0, atol=1e-12)
    assert np.allclose(out[9:12], 0.0, rtol=0, atol=1e-12)
    still = np.zeros(12)
    uuv_deriv(x, still, p, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0)
    assert np.allclose(still[6:12], 0.0, atol=1e-12)
    # moving with a steady flow that has a vertical part: no relative velocity, no force
    vf = np.array([0.3, -0.2, 0.5])
    x[6:9] = R.T @ vf
    uuv_deriv_flow(x, out, p, 0.0, 0.0, 0.0, *vf, 0.0, 0.0, 0.0, cfg.buoyancy / G, 0.0, 0.0, 0.0, True)
    assert np.allclose(out[6:12], 0.0, atol=1e-12)
    uuv_deriv_flow(x, out, p, 0.0, 0.0, 0.0, vf[0], vf[1], 0.0, 0.0, 0.0, 0.0, cfg.buoyancy / G, 0.0, 0.0, 0.0, True)
    assert np.max(np.abs(out[6:9])) > 1e-3  # without the vertical flow the body drags against it


def test_batch_runs_in_waves_equal_single_runs(tmp_path):
    """The compiled batch (one prange over runs, each its own sea) gives each run's single-run summary."""
    import oceangnc
    from oceangnc.batch import run_batch

    ov = [{"environment.waves.hs": hs, "analysis.settle_s": 2.0} for hs in (1.0, 2.0)]
    got = run_batch("tow-sea-state", ov, seeds=[0, 1], duration=10.0, out=tmp_path / "b", threads=1)
    for s, o, seed in zip(got, ov, (0, 1)):
        one = oceangnc.run(
            "tow-sea-state", duration=10.0, overrides={**o, "sim.seed": seed}, plots=False, out=tmp_path / f"r{seed}"
        ).summary
        for k in ("cable.top_std_N", "cable.top_max_N", "uuv.depth_std_m"):
            assert s[k] == one[k]
    assert got[1]["cable.top_std_N"] > got[0]["cable.top_std_N"]


def test_wheeler_expansion_equals_the_stretched_kinematics():
    """With Wheeler stretching the expansion at its own time equals the module's stretched kinematics."""
    sea = WaveField.from_config(
        WaveConfig(kind="jonswap", hs=2.0, tp=7.0, depth=30.0, wheeler=True), np.random.default_rng(5)
    )
    blk = sea_block(sea, 4, 0.1, "none", RHO_WATER, 1e-3, 1.0, 100.0)
    c = coef_base(blk, 0)
    pts = np.array([[0.0, 0.0, 0.3], [3.0, -2.0, 1.5], [10.0, 4.0, 6.0], [-5.0, 1.0, 12.0]])
    for tm in (3.0, 11.7):
        _, v, a = sea.kinematics(tm, pts)
        for i, q in enumerate(pts):
            _expand(blk, 0, c + NCOEF * i, q[0], q[1], q[2], 0.0, 0.0, tm, True)
            got = point_kinematics(blk, c + NCOEF * i, 0.0, q[2])
            assert np.allclose(got, np.r_[v[i], a[i]], rtol=1e-9, atol=1e-12)
