"""Issue 41: ``identify ekf`` refuses a log that cannot identify the parameters (no excitation), in one line.

On the code at the issue's filing the filter ran on any log and returned estimates many times off with a
1-sigma of 0.00 %; now the Cramer-Rao bound along the log (oceangnc.identification.ekf_checks) decides first."""

from __future__ import annotations

import json

import numpy as np
import pandas as pd

import oceangnc
from oceangnc.cli import main


def test_a_log_whose_stern_plane_never_moved_is_refused_in_one_line(tmp_path, capsys):
    """A straight run of ekf-zigzag (the zig-zag never starts): the stern-plane coefficient has nothing to be
    identified from; refused naming it, exit 2, nothing written; --skip-check runs it and warns."""
    res = oceangnc.run("ekf-zigzag", overrides={"t_start_s": 1e4, "sim.duration": 20.0, "noise": 1.0},
                       out=tmp_path / "r", plots=False)  # fmt: skip
    assert (res.df["sub.ds"] == 0).all()
    log = str(tmp_path / "r" / "log.parquet")
    args = ["identify", "ekf", log, "--estimate", "Zw,Mq,Mds", "--out", str(tmp_path / "o")]
    capsys.readouterr()
    assert main(args) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "excitation" in err and "Mds" in err
    assert not (tmp_path / "o").exists()
    assert main([*args, "--skip-check", "excitation"]) == 0
    out = json.loads((tmp_path / "o" / "ekf_submarine-vertical.json").read_text())
    assert out["checks"]["rel_sigma"]["Mds"] > 10 and out["checks"]["rel_sigma"]["Mq"] < 1
    assert any("skip-check" in w and "Mds" in w for w in out["warnings"])


def test_a_log_in_which_nothing_moves_is_refused(tmp_path, capsys):
    """Every measurement constant at zero (a vehicle at rest, plane at zero): no parameter shows in the log."""
    n = 400
    z = np.zeros(n)
    csv = tmp_path / "rest.csv"
    pd.DataFrame({"t": np.arange(n) * 0.05, "sub.w": z, "sub.theta": z, "sub.q": z, "sub.ds": z}).to_csv(csv)
    assert main(["identify", "ekf", str(csv), "--estimate", "Zw,Mq", "--out", str(tmp_path / "o")]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "excitation" in err and "Zw, Mq" in err
