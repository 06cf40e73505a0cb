"""The fused loop on the remaining scenarios of ``oceangnc list`` (issue 19): the first-order USV
(autopilots, waypoints, towed trailer), the console USV, berthing in every mode and the inner runs
of the multi-run scenarios give the same log on the fused and the Python path."""

from __future__ import annotations

import warnings

import numpy as np
import pytest

from oceangnc.api import resolve_config
from oceangnc.io.logs import LogWriter, read_log

#: (scenario, overrides, horizon s) that must run fused with the Python path's log
FUSED_MORE = [
    ("autopilot-heading", {}, 6.0),
    ("autopilot-speed", {}, 6.0),
    ("usv-waypoints-7", {}, 20.0),
    ("usv-waypoints-7", {"guidance.mode": "los"}, 20.0),
    ("uuv-profile-plan", {}, 70.0),  # through several leg switches
    ("uuv-profile-plan", {"guidance.mode": "los"}, 10.0),
]


def _run(name, over, dur, fused, tmp_path):
    sc, cfg = resolve_config(name, overrides=over, duration=dur)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", RuntimeWarning)  # the first-order schedule's range warning
        sim = sc.build(cfg, np.random.default_rng(cfg.sim.seed))
        sim.use_fused = fused
        path = tmp_path / f"{name}-{int(fused)}.parquet"
        with LogWriter(path) as log:
            t = sim.run(dur, log=log)
    return sim, t, read_log(path), cfg


def _same_log(a, b):
    assert list(a.columns) == list(b.columns)
    assert len(a) == len(b)
    np.testing.assert_allclose(b.to_numpy(), a.to_numpy(), rtol=1e-9, atol=1e-12)


@pytest.mark.parametrize(
    "name,over,dur", FUSED_MORE, ids=[f"{n}-{'-'.join(map(str, o.values()))}" for n, o, _ in FUSED_MORE]
)
def test_fused_log_equals_python_log(name, over, dur, tmp_path):
    sp, tp, a, cfg = _run(name, over, dur, False, tmp_path)
    sf, tf, b, _ = _run(name, over, dur, True, tmp_path)
    assert sp.path == "python" and sf.path == "fused"
    assert tp == tf
    assert len(a) == int(round(tp * cfg.sim.log_rate)) + 1
    _same_log(a, b)


def test_fused_waypoint_guidance_switches_legs_and_stops_like_python(tmp_path):
    over = {"waypoints": [[0.0, 40.0], [0.0, 120.0], [60.0, 170.0]]}
    sp, tp, a, _ = _run("usv-waypoints-7", over, 120.0, False, tmp_path)
    sf, tf, b, _ = _run("usv-waypoints-7", over, 120.0, True, tmp_path)
    assert sf.path == "fused"
    assert tp < 120.0 and tf == tp  # the last waypoint stops both runs at the same tick
    assert set(b["guidance.leg"]) == {1.0, 2.0}
    _same_log(a, b)
