"""The tow scenarios on the fused compiled loop (issue 19): the same log as the Python clock,
including a winch that inserts cable nodes during a compiled call (variable node count)."""

from __future__ import annotations

import numpy as np
import pytest

from fused_paths import run_both
from oceangnc.api import resolve_config
from oceangnc.errors import DivergenceError

#: (scenario, overrides, horizon s): the commands start early so a short horizon exercises the loops
TOW = [
    ("tow-straight", {"command.start_s": 1.0}, 5.0),
    # the depth target drops 6.7 m at once and comes back: the drum pays out at its 0.5 m/s limit, the
    # winch inserts a node (top segment above 1.5 l0 = 1.5 m), then hauls in and removes it
    ("tow-deploy", {"winch_control.profile": [(0.0, 1.3), (0.5, 8.0), (3.0, 8.0), (6.0, 1.3)]}, 12.0),
    ("tow-survey-depth", {}, 4.0),
    # a seabed without a winch (variable-count plant form, fixed count), explicit RK4 cable
    (
        "tow-deploy",
        {
            "winch.enabled": False,
            "environment.seabed.depth": 1.5,
            "cable.integrator": "rk4",
            "sim.dt": 0.002,
            "winch_control.mode": "altitude",
        },
        3.0,
    ),
]


@pytest.mark.parametrize("name,over,dur", TOW, ids=[n for n, _, _ in TOW[:3]] + ["seabed-rk4"])
def test_tow_fused_log_equals_python_log(name, over, dur, tmp_path):
    sp, sf, a, b, tp, cfg = run_both(name, over, dur, tmp_path)
    assert len(a) == int(round(tp * cfg.sim.log_rate)) + 1
    # the loops did something: thrust or drum commands are not all zero
    cmd = [c for c in a.columns if c.endswith("_cmd") or c in ("winch.speed_cmd_sat", "winch.error")]
    assert np.abs(a[cmd].to_numpy()).max() > 1.0e-3
    if "winch.enabled" not in over and name == "tow-deploy":  # nodes inserted and removed in fused calls
        nodes = b["cable.nodes"].to_numpy()
        assert nodes.max() > nodes[0] and nodes[-1] < nodes.max()
        assert (a["cable.nodes"].to_numpy() == nodes).all()
        assert sf.plants[0].n == sp.plants[0].n == nodes[-1] - 1
    for k in ("uuv.z", "cable.length", "winch.speed", "usv.x", "cable.top_tension"):
        if k in sp.bus:
            assert sf.bus[k] == pytest.approx(sp.bus[k], rel=1e-9, abs=1e-12)


def _diverge(fused: bool) -> DivergenceError:
    sc, cfg = resolve_config("tow-deploy", duration=2.0)
    sim = sc.build(cfg, np.random.default_rng(0))
    sim.use_fused = fused
    sim.run(0.5)
    assert sim.path == ("fused" if fused else "python")
    sim.plants[0].x[sim.plants[0].o_uuv + 2] = np.nan  # the UUV's depth
    with pytest.raises(DivergenceError) as ei:
        sim.run(1.0)
    return ei.value


def test_tow_divergence_names_time_block_and_state():
    """A non-finite plant state stops the run with the same DivergenceError on both paths: the time
    of the failed step, the plant's name and its state (the poisoned depth shown as nan)."""
    ep, ef = _diverge(False), _diverge(True)
    for e in (ep, ef):
        assert e.block == "combined" and e.t == pytest.approx(0.51)
        assert "non-finite state" in str(e) and np.isnan(e.state["combined.uuv.z"])
    assert str(ef) == str(ep)


def test_profile_reference_is_numpy_interp_and_the_segment_slope():
    """The winch's moving target (one compiled home for the Python block and the kernel): equal to
    numpy.interp bit for bit, at and between the breakpoints and outside them, and its rate is the
    slope of the segment starting at or before t (0 outside the profile)."""
    from oceangnc.control.winch import profile_reference

    pt = np.array([0.0, 10.0, 150.0, 190.0, 330.0])
    pz = np.array([1.3, 1.3, 30.0, 30.0, 1.3])
    ts = np.concatenate([pt, pt + 1e-9, pt - 1e-9, np.linspace(-5.0, 340.0, 997)])
    for t in ts:
        z, rate = profile_reference(t, pt, pz)
        assert z == np.interp(t, pt, pz)
        i = int(np.searchsorted(pt, t, side="right"))
        want = (pz[i] - pz[i - 1]) / (pt[i] - pt[i - 1]) if 0 < i < len(pt) else 0.0
        assert rate == want
    assert profile_reference(80.0, pt, pz)[1] == pytest.approx(28.7 / 140.0, rel=1e-15)


def test_tension_payout_pays_out_above_the_margin_only():
    """Above T_margin the drum command is raised to K_T (T - T_margin), capped at speed_max; below it
    the loop's command passes unchanged (hauling in included)."""
    from oceangnc.control.winch import tension_payout

    assert tension_payout(-0.3, 700.0, 800.0, 0.005, 0.5) == -0.3
    assert tension_payout(-0.3, 840.0, 800.0, 0.005, 0.5) == pytest.approx(0.2)
    assert tension_payout(0.4, 840.0, 800.0, 0.005, 0.5) == 0.4
    assert tension_payout(-0.3, 2000.0, 800.0, 0.005, 0.5) == 0.5
