"""Scenario ``ekf-zigzag`` and ``oceangnc identify ekf``: outputs, round trip through a log, bad input."""

import json

import numpy as np
import pandas as pd
import pytest

import oceangnc
from oceangnc.cli import main
from oceangnc.errors import ConfigError
from oceangnc.models.submarine_vertical import COEFF_NAMES, TRUE_COEFFS


@pytest.fixture(scope="module")
def run_dir(tmp_path_factory):
    out = tmp_path_factory.mktemp("ekf") / "run"
    res = oceangnc.run("ekf-zigzag", overrides={"noise": 1.0, "maneuver": "10-5"}, out=out)
    return res


def test_scenario_summary_and_plots(run_dir):
    """summary.json has <coef>.estimate/.true/.rel_error/.sigma for the ten and max_rel_error; the plots
    (estimates with 3-sigma bands, figs 5.3/5.4; measurements, fig 4.1) exist; the log holds both."""
    s = json.loads((run_dir.out_dir / "summary.json").read_text())
    for k in COEFF_NAMES:
        assert s[f"{k}.true"] == pytest.approx(TRUE_COEFFS[k])
        assert s[f"{k}.rel_error"] == pytest.approx((s[f"{k}.estimate"] - s[f"{k}.true"]) / abs(s[f"{k}.true"]))
        assert s[f"{k}.sigma"] > 0
    assert s["max_rel_error"] == pytest.approx(max(abs(s[f"{k}.rel_error"]) for k in COEFF_NAMES))
    assert s["n_within_3sigma"] >= 9
    assert {p.name for p in run_dir.plots} == {"estimates.png", "measurements.png"}
    df = run_dir.df
    assert len(df) == 20001 and {"sub.w", "sub.ds", "ekf.Zw", "ekf.Zw_sigma", "sub.w_true"} <= set(df.columns)


def test_cli_identifies_from_the_scenario_log(run_dir, tmp_path, capsys):
    """``oceangnc identify ekf LOG`` estimates the noise sigma from the data (within 20 % of the true
    0.002 m/s), its innovations have the predicted size (mean NIS 3 within 3 %), and the well identified
    pitch-moment coefficients land within 3 sigma of the truth; it writes a JSON table."""
    dest = tmp_path / "ident"
    rc = main(
        [
            "identify",
            "ekf",
            str(run_dir.out_dir / "log.parquet"),
            "--model",
            "submarine-vertical",
            "--estimate",
            ",".join(COEFF_NAMES),
            "--initial-scale",
            "1.2",
            "--out",
            str(dest),
        ]
    )
    assert rc == 0
    out = json.loads((dest / "ekf_submarine-vertical.json").read_text())
    assert out["measurement_sigma"]["sub.w"] == pytest.approx(0.002, rel=0.2)
    assert out["mean_nis"] == pytest.approx(3.0, rel=0.03)
    for k in ("Mw", "Mwdot", "Mq", "Mqdot", "Mds"):
        v = out["parameters"][k]
        assert abs(v["estimate"] - TRUE_COEFFS[k]) <= 3 * v["sigma"], k
    assert "Mqdot" in capsys.readouterr().out


def test_cli_csv_log_noise_free(tmp_path):
    """A CSV log written by the user: noise-free data, two coefficients, within 0.5 %."""
    res = oceangnc.run("ekf-zigzag", overrides={"sim.duration": 100.0}, out=tmp_path / "r", plots=False)
    df = res.df[["t", "sub.w", "sub.theta", "sub.q", "sub.ds"]]
    csv = tmp_path / "trial.csv"
    df.to_csv(csv, index=False)
    dest = tmp_path / "o"
    assert (
        main(
            [
                "identify",
                "ekf",
                str(csv),
                "--estimate",
                "Mq,Mds",
                "--initial",
                "Mq=-0.0025,Mds=-0.004",
                "--out",
                str(dest),
            ]
        )
        == 0
    )
    est = json.loads((dest / "ekf_submarine-vertical.json").read_text())["parameters"]
    for k in ("Mq", "Mds"):
        assert est[k]["estimate"] == pytest.approx(TRUE_COEFFS[k], rel=5e-3)


def test_cli_bad_input_exit_2(tmp_path, capsys):
    """Unknown parameter, missing columns, non-positive R: exit code 2 and a one-line message."""
    csv = tmp_path / "bad.csv"
    pd.DataFrame({"t": np.arange(10) * 0.01, "sub.w": np.zeros(10), "sub.q": np.zeros(10)}).to_csv(csv, index=False)
    assert main(["identify", "ekf", str(csv), "--estimate", "Zw"]) == 2
    err = capsys.readouterr().err
    assert "no column(s) sub.theta, sub.ds" in err and err.count("\n") == 1
    assert main(["identify", "ekf", str(csv), "--estimate", "Zw,Kp"]) == 2
    assert "unknown parameter(s) Kp" in capsys.readouterr().err
    good = tmp_path / "good.csv"
    pd.DataFrame(
        {
            "t": np.arange(10) * 0.01,
            "sub.w": np.zeros(10),
            "sub.theta": np.zeros(10),
            "sub.q": np.zeros(10),
            "sub.ds": np.zeros(10),
        }
    ).to_csv(good, index=False)
    assert main(["identify", "ekf", str(good), "--estimate", "Zw", "--r-sigma", "0.01,0,0.01"]) == 2
    assert "not positive definite" in capsys.readouterr().err
    assert main(["identify", "ekf", str(good), "--model", "airship", "--estimate", "Zw"]) == 2


def test_scenario_config_ranges():
    with pytest.raises(ConfigError, match="maneuver"):
        oceangnc.run("ekf-zigzag", overrides={"maneuver": "20-5"}, plots=False)
    with pytest.raises(ConfigError, match="noise"):
        oceangnc.run("ekf-zigzag", overrides={"noise": -1.0}, plots=False)
