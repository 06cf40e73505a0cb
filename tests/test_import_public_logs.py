"""Import of public sample logs nobody on the project wrote (tests/data/public/README.md: source, licence).

pyulog's ``sample_appended_multiple.ulg`` (PX4/pyulog test data, BSD 3-Clause): a real PX4 ULog of a
quadrotor at rest with appended data sections. Round trip against the format's own reader (pyulog read
directly): the imported depth (``usv.z`` = vehicle_local_position.z) and heading (``usv.psi``, the yaw of
vehicle_attitude's quaternion) at the imported instants; the vehicle is read from the log (MAV_TYPE 2) and
boat identification refuses it in one line (exit 2)."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from oceangnc.cli import main
from oceangnc.io.importers import import_log

LOG = Path(__file__).parent / "data" / "public" / "pyulog_sample_appended_multiple.ulg"


def _direct(log: Path):
    """(t s, z m) of vehicle_local_position and (t s, yaw rad) of vehicle_attitude, read by pyulog itself."""
    from pyulog import ULog

    u = ULog(str(log))
    lp = u.get_dataset("vehicle_local_position").data
    att = u.get_dataset("vehicle_attitude").data
    q0, q1, q2, q3 = (att[f"q[{i}]"] for i in range(4))
    yaw = np.arctan2(2.0 * (q0 * q3 + q1 * q2), 1.0 - 2.0 * (q2**2 + q3**2))
    return (lp["timestamp"] * 1e-6, lp["z"]), (att["timestamp"] * 1e-6, yaw)


def test_pyulog_public_sample_imports_as_pyulog_reads_it(tmp_path, capsys):
    pytest.importorskip("pyulog")
    res = import_log(LOG, rate=10.0)
    (tz, z), (ta, yaw) = _direct(LOG)
    df = res.df
    t = df["t"].to_numpy() + res.report["t0_source_s"]
    assert len(df) > 80 and res.report["duration_s"] > 9.0  # the whole 9.5 s of local positions
    ok = (t >= tz[0]) & (t <= tz[-1])
    assert ok.sum() > 0.9 * len(df)
    dz = df["usv.z"].to_numpy()[ok] - np.interp(t[ok], tz, z)
    assert np.abs(dz).max() < 5e-3, np.abs(dz).max()  # resampling of a 10 Hz series at 10 Hz
    ok = (t >= ta[0]) & (t <= ta[-1])
    dpsi = df["usv.psi"].to_numpy()[ok] - np.interp(t[ok], ta, np.unwrap(yaw))
    assert np.abs((dpsi + np.pi) % (2 * np.pi) - np.pi).max() < 2e-3
    assert res.report["vehicle"]["type"] == "multirotor" and res.report["vehicle"]["marine"] is False
    assert not any(c.startswith("act.") for c in df.columns)  # quadrotor motors are not boat thrusters
    code = main(["identify", "first-order", str(LOG), "--out", str(tmp_path / "o")])
    err = capsys.readouterr().err.strip()
    assert code == 2 and len(err.splitlines()) == 1 and "multirotor" in err, err
