"""The worked examples of docs/developing.md (issue 25): a user's package (examples/mygnc) with a
controller with its compiled law, a sensor with noise and dropouts, and a plant, each in one file,
run on the fused loop and on the Python clock with the same log; the docs show the files as they are."""

from __future__ import annotations

import re
import sys
from pathlib import Path

import numpy as np
import pytest

from fused_paths import run_both, same_log
from oceangnc.core.blocks import ConstantBlock
from oceangnc.core.clock import Simulation
from oceangnc.io.logs import LogWriter, read_log

ROOT = Path(__file__).resolve().parents[1]
MARK = re.compile(r"<!--\s*no-test:\s*(examples/\S+\.py)[^>]*-->\s*\n```python\n(.*?)```", re.S)


@pytest.fixture(scope="module", autouse=True)
def mygnc():
    sys.path.insert(0, str(ROOT / "examples"))
    import mygnc.compass  # noqa: F401  (registers the kinds)
    import mygnc.controller  # noqa: F401

    yield
    sys.path.remove(str(ROOT / "examples"))


def test_the_docs_show_the_example_files_as_they_are():
    text = (ROOT / "docs" / "developing.md").read_text()
    shown = {path: code for path, code in MARK.findall(text)}
    assert set(shown) == {"examples/mygnc/controller.py", "examples/mygnc/compass.py", "examples/mygnc/buoy.py"}
    for path, code in shown.items():
        assert code == (ROOT / path).read_text(), f"docs/developing.md shows an old {path}"


def test_the_users_controller_and_sensor_run_fused_and_on_the_python_clock(tmp_path):
    over = {
        "control.uuv": {"kind": "mygnc.heading_hold", "k_heading": 8.0},
        "sensors.extra": [{"kind": "mygnc.compass", "sigma_deg": 0.5, "p_drop": 0.2}],
    }
    sp, sf, a, b, t_end, cfg = run_both("combined-survey", over, 6.0, tmp_path)
    e = (a["usv.psi"] - a["compass.psi"] + np.pi) % (2 * np.pi) - np.pi
    assert np.abs(a["uuv.thrust_bow_cmd"] - np.clip(8.0 * e, -40, 40)).max() < 1e-9  # the law, every row
    lost = 1.0 - a["compass.valid"]
    assert 0.05 < lost.mean() < 0.4  # dropouts at about p_drop (of the logged samples)


def test_the_users_sensor_holds_its_last_heading_through_a_dropout():
    from mygnc.compass import Compass

    from oceangnc.core.registry import BlockContext

    c = Compass({"sigma_deg": 0.5, "p_drop": 0.3}, BlockContext(period=0.05))
    c.reset(np.random.default_rng(3))
    bus, out, valid = {}, [], []
    for k in range(400):
        bus["uuv.psi"] = 0.001 * k  # a slow turn: every good sample differs from the one before
        c.step(0.05 * k, bus)
        out.append(bus["compass.psi"])
        valid.append(bus["compass.valid"])
    out, valid = np.array(out), np.array(valid)
    lost = np.flatnonzero(valid[1:] == 0.0) + 1
    assert 60 < lost.size < 180  # about p_drop of 400 samples
    assert np.array_equal(out[lost], out[lost - 1])  # a lost sample holds the heading before it
    good = np.flatnonzero(valid == 1.0)
    assert np.abs(out[good] - 0.001 * good).max() < np.radians(0.5) * 5  # noise of sigma 0.5 deg
    assert np.abs(out[good] - 0.001 * good).std() > np.radians(0.5) * 0.5


def _buoy_log(fused: bool, tmp_path):
    from mygnc.buoy import buoy_model

    model = buoy_model()
    winch = ConstantBlock("winch", 0.1, {"buoy.force": 150.0}, units={"buoy.force": "N"})
    sim = Simulation([model.plant("buoy", [0.0, 0.0])], [winch], dt=0.01, log_period=0.1)
    sim.use_fused = fused
    path = tmp_path / f"buoy-{int(fused)}.parquet"
    with LogWriter(path) as log:
        sim.run(60.0, log=log)
    assert sim.path == ("fused" if fused else "python")
    return read_log(path), model


def test_the_users_plant_runs_fused_and_on_the_python_clock(tmp_path):
    a, model = _buoy_log(False, tmp_path)
    b, _ = _buoy_log(True, tmp_path)
    same_log(a, b)
    k = model.p[model.layout.index("k_heave")]
    assert a["buoy.z"].iloc[-1] == pytest.approx(150.0 / k, rel=1e-3)  # the static heave under the winch force
    assert a["buoy.z"].max() > 150.0 / k * 1.05  # and an overshoot on the way (under-damped)
