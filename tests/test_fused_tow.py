"""The tow scenarios on the fused compiled loop (issue 19): the same log as the Python clock,
including a winch that inserts cable nodes during a compiled call (variable node count)."""

from __future__ import annotations

import numpy as np
import pytest

from oceangnc.api import resolve_config
from oceangnc.errors import DivergenceError
from test_fused import _run

#: (scenario, overrides, horizon s): the commands start early so a short horizon exercises the loops
TOW = [
    ("tow-straight", {"command.start_s": 1.0}, 5.0),
    # the depth profile starts descending at 1 s: the drum pays out at its 0.5 m/s limit and the
    # winch inserts nodes (the top segment passes 1.5 l0 = 1.5 m)
    ("tow-deploy", {"winch_control.profile": [(0.0, 1.3), (1.0, 1.3), (20.0, 12.0)]}, 6.0),
    ("tow-survey-depth", {}, 4.0),
]


@pytest.mark.parametrize("name,over,dur", TOW, ids=[n for n, _, _ in TOW])
def test_tow_fused_log_equals_python_log(name, over, dur, tmp_path):
    sp, tp, a = _run(name, over, dur, False, tmp_path)
    sf, tf, b = _run(name, over, dur, True, tmp_path)
    assert sp.path == "python" and sf.path == "fused"
    assert tp == tf
    assert list(a.columns) == list(b.columns)
    assert len(a) == len(b) == int(round(tp * resolve_config(name, overrides=over)[1].sim.log_rate)) + 1
    x, y = a.to_numpy(), b.to_numpy()
    np.testing.assert_allclose(y, x, rtol=1e-9, atol=1e-12)
    # the loops did something: thrust or drum commands are not all zero
    cmd = [c for c in a.columns if c.endswith("_cmd") or c == "winch.speed_cmd_sat"]
    assert np.abs(a[cmd].to_numpy()).max() > 1.0e-3
    if name == "tow-deploy":  # nodes inserted inside the fused calls, on both paths alike
        nodes = b["cable.nodes"].to_numpy()
        assert nodes[-1] > nodes[0]
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
