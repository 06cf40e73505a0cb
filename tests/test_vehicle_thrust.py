"""Issue 41: a vehicle file without ``time_constant`` logs the thrust its thrusters give (the docs' box ROV).

On the code at the issue's filing the state ``thrust_<name>`` of a lag-free thruster stayed at 0 while the
vehicle was driven, so every logged thrust was 0 and the summary said ``vehicle.thrust_max_N = 0``."""

from __future__ import annotations

import re
from pathlib import Path

import numpy as np

DOCS = Path(__file__).resolve().parents[1] / "docs" / "vehicles.md"


def box_rov_text() -> str:
    """The box-shaped ROV of docs/vehicles.md ("Writing a vehicle file"): no thruster has a time constant."""
    text = re.search(r'write_text\("""\n(name = "box-rov".*?)"""\)', DOCS.read_text(), re.S).group(1)
    assert "time_constant" not in text
    return text


def test_lag_free_thrusters_log_the_thrust_they_apply_on_both_paths(tmp_path):
    """The logged thrust of each lag-free thruster is its command clipped to [-max_reverse, max_forward],
    on the Python clock and in the fused loop alike, and the ROV is driven (it dives to its set point)."""
    from fused_paths import run_both
    from oceangnc.models.vehicle import load_vehicle

    f = tmp_path / "box-rov.toml"
    f.write_text(box_rov_text())
    gains = {"surge": [80, 5, 80], "sway": [80, 5, 80], "heave": [300, 30, 200], "yaw": [20, 0, 15]}
    over = {"vehicle": str(f), "control.gains": gains}
    _, _, py, fu, _, _ = run_both("rov-station-keeping", over, 4.0, tmp_path)
    vf = load_vehicle(f)
    for t in vf.thrusters:
        cmd = fu[f"vehicle.thrust_{t.name}_cmd"].to_numpy()
        thr = fu[f"vehicle.thrust_{t.name}"].to_numpy()
        # a row holds the command written this tick and the thrust applied over the step before it
        np.testing.assert_allclose(thr[1:], np.clip(cmd[:-1], -t.max_reverse, t.max_forward), atol=1e-9)
    assert np.abs(fu["vehicle.thrust_vertical"]).max() > 10.0  # heave is driven: 5 m below the surface


def test_the_summary_gives_the_largest_applied_thrust(tmp_path):
    from oceangnc.api import run

    f = tmp_path / "box-rov.toml"
    f.write_text(box_rov_text())
    gains = {"surge": [80, 5, 80], "sway": [80, 5, 80], "heave": [300, 30, 200], "yaw": [20, 0, 15]}
    r = run("rov-station-keeping", out=tmp_path / "r", plots=False, duration=4,
            overrides={"vehicle": str(f), "control.gains": gains})  # fmt: skip
    assert r.summary["status"] == "ok"
    assert r.summary["vehicle.thrust_max_N"] > 10.0
    assert r.summary["vehicle.thrust_max_N"] <= 60.0  # the largest max_forward of the file
