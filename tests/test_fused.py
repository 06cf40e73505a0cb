"""The fused closed loop (issue 19): same log as the Python clock, cost linear in the horizon,
fallback with a reason for blocks without a compiled form."""

from __future__ import annotations

import time

import numpy as np
import pytest
from numba import njit

from fused_paths import run_both, run_path
from oceangnc.api import resolve_config
from oceangnc.core.blocks import ConstantBlock, FunctionBlock
from oceangnc.core.clock import Simulation
from oceangnc.core.fused import build_fused
from oceangnc.core.law import LawBlock, Opt, Out, Signals
from oceangnc.io.logs import LogWriter, read_log

#: scenarios (with overrides) that run fused; the test below runs both paths for each
FUSED = [
    ("combined-survey", {"control.uuv": "backstepping"}, 6.0),
    ("combined-survey", {"control.uuv": "pid"}, 6.0),
    # the implicit cable at the 10 ms control period (issue 19: the physics step set by accuracy)
    ("combined-survey", {"control.uuv": "backstepping", "cable.integrator": "imex", "sim.dt": 0.01}, 6.0),
    ("waypoints-square", {"formation.mode": "relative-angle"}, 4.0),
    ("cable-current", {"environment.current.speed": 0.3}, 3.0),
    ("field-test", {"sensors.usbl.dropout_start": 2.0, "sensors.usbl.dropout_duration": 3.0}, 8.0),
    ("berthing-channel", {}, 100.0),
    ("berthing-dock", {"control.mode": "nonlinear"}, 60.0),
    ("usv-turn", {}, 20.0),
    ("usv-turn-current", {}, 10.0),
    ("usv-turn-wind", {}, 10.0),
    ("usv-straight", {}, 10.0),
]


@pytest.mark.parametrize("name,over,dur", FUSED, ids=[f"{n}-{'-'.join(map(str, o.values()))}" for n, o, _ in FUSED])
def test_fused_log_equals_python_log(name, over, dur, tmp_path):
    sp, sf, a, b, tp, cfg = run_both(name, over, dur, tmp_path, nan_equal=False)
    assert len(a) == int(round(tp * cfg.sim.log_rate)) + 1
    # the bus after the run holds the same values on both paths
    for k in ("usv.x", "usv.psi", "guidance.wp_reached", "uuv.thrust_bow"):
        if k in sp.bus:
            assert sf.bus[k] == pytest.approx(sp.bus[k], rel=1e-9, abs=1e-12)


def test_fused_run_stops_on_the_last_waypoint_like_python(tmp_path):
    sp, tp, a, _ = run_path("combined-survey", {"guidance.waypoints": [(0.0, 0.0), (3.0, 0.0)]}, 60.0, False, tmp_path)
    sf, tf, b, _ = run_path("combined-survey", {"guidance.waypoints": [(0.0, 0.0), (3.0, 0.0)]}, 60.0, True, tmp_path)
    assert tp < 60.0 and tf == tp
    assert b["guidance.done"].iloc[-1] == 1.0 and len(a) == len(b)


def test_fused_cost_is_linear_in_the_horizon():
    sc, cfg = resolve_config("usv-turn", duration=1.0)

    def cost(dur):
        sim = sc.build(cfg, np.random.default_rng(0))
        sim.use_fused = True
        sim.run(0.0)  # first tick (Python) and the loop's build outside the timing
        sim._decide_fused()
        best = np.inf
        for _ in range(3):
            s = sc.build(cfg, np.random.default_rng(0))
            s.use_fused = True
            s.run(0.0)
            s._decide_fused()
            c0 = time.process_time()
            s.run(dur)
            best = min(best, time.process_time() - c0)
        return best

    cost(2.0)  # compile / load the cached driver
    short, long = cost(20.0), cost(200.0)
    assert 5.0 < long / short < 14.0, (short, long)


def test_a_python_block_falls_back_with_a_reason(capsys, tmp_path):
    sc, cfg = resolve_config("usv-turn", duration=1.0)
    sim = sc.build(cfg, np.random.default_rng(0))
    sim.blocks.append(FunctionBlock("mine", 0.01, lambda t, bus: bus.__setitem__("mine.x", t)))
    sim.block_steps.append(10)
    sim.fire_count.append(0)
    sim.use_fused = True
    sim.verbose = True
    sim.run(0.5)
    assert sim.path == "python"
    assert "block 'mine' (FunctionBlock) has no compiled form" in capsys.readouterr().err
    assert sim.bus["mine.x"] == pytest.approx(0.5)
    assert build_fused(sim)[0] is None


_READER = Signals(y=Opt("m"), x=Out("m"))
_R = _READER.at


@njit(cache=True)
def _reader_law(t, sig, sl, st, pa):
    """x = y, or -1 while y is absent (its slot -1)."""
    sig[sl[_R.x]] = sig[sl[_R.y]] if sl[_R.y] >= 0 else -1.0


class _Reader(LawBlock):
    """Reads an optional input that a block after it writes."""

    law = staticmethod(_reader_law)
    signals = _READER

    def __init__(self):
        self.name, self.period = "reader", 0.1
        self.bind(y="later.y", x="reader.x")
        self.pa, self.st = np.zeros(1), np.zeros(1)


def test_the_driver_runs_the_first_tick_as_the_python_clock(tmp_path, monkeypatch):
    """With every output declared, the fused driver runs the first tick too (no block's Python step, so
    no law is loaded on its own): an optional input written by a later block is absent at that tick,
    as on the Python clock, and present after it; the logs are equal."""
    logs = {}
    for fused in (False, True):
        sim = Simulation([], [_Reader(), ConstantBlock("later", 0.1, {"later.y": 2.0}, {"later.y": "m"})], 0.1, 0.1)
        sim.use_fused = fused
        if fused:
            monkeypatch.setattr(_Reader, "step", None)  # the driver must not need it
        with LogWriter(tmp_path / f"{fused}.parquet") as log:
            sim.run(0.3, log=log)
        assert sim.path == ("fused" if fused else "python")
        logs[fused] = read_log(tmp_path / f"{fused}.parquet")
    assert list(logs[True]["reader.x"]) == list(logs[False]["reader.x"]) == [-1.0, 2.0, 2.0, 2.0]
