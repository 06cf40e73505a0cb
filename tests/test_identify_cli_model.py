"""Identification that cannot cheat, and models out: ``identify`` -> ``identified.toml`` -> ``run --model``."""

from __future__ import annotations

import json
import math
import tomllib
from pathlib import Path

import numpy as np
import pandas as pd
import pytest

import oceangnc
from oceangnc.cli import main


@pytest.fixture(scope="module")
def identified(tmp_path_factory):
    """The first-order USV's trials (table-2 model, with sensor noise) identified by the CLI."""
    d = tmp_path_factory.mktemp("fo")
    res = oceangnc.run(
        "trials",
        out=d / "trials",
        plots=False,
        overrides={"noise.speed_mps": 0.02, "noise.heading_deg": 0.2, "noise.yaw_rate_degps": 0.1},
    )
    assert main(["identify", "first-order", str(d / "trials" / "log.parquet"), "--out", str(d / "ident")]) == 0
    return d, res


def test_first_order_model_file_has_intervals_that_cover_the_truth(identified):
    d, res = identified
    doc = tomllib.loads((d / "ident" / "identified.toml").read_text())
    assert doc["model"]["kind"] == "usv-first-order"
    truth = res.config.usv
    for k, u in doc["uncertainty"].items():
        name = k.split(".", 1)[1]
        lo, hi = u["ci95"]
        assert lo < u["estimate"] < hi and u["std_error"] > 0
        assert doc["parameters"][k] == u["estimate"]
        # the table-2 coefficient the trials were simulated with lies within 4 standard errors
        assert abs(u["estimate"] - getattr(truth, name)) < 4 * u["std_error"] + 1e-9, (k, u, getattr(truth, name))
    assert doc["uncertainty"]["usv.kv_slope"]["dof"] == 9 - 2  # nine straight trials, two coefficients
    assert doc["parameters"]["usv.straight_lo_mps"] == pytest.approx(5.0, abs=0.01)


def test_identified_model_predicts_a_different_manoeuvre(identified):
    """The identified model flies the seven-waypoint route of 000 fig. 21 (a manoeuvre not in the trials,
    closed loop from rest): its track stays within 1 m of the table-2 model's over the 3.3 km route."""
    d, _ = identified
    truth = oceangnc.run("usv-waypoints-7", out=d / "truth", plots=False).df
    pred = oceangnc.run("usv-waypoints-7", out=d / "pred", plots=False, model=d / "ident" / "identified.toml").df
    assert len(truth) == len(pred)
    dev = np.hypot(truth["usv.x"] - pred["usv.x"], truth["usv.y"] - pred["usv.y"])
    length = float(np.sum(np.hypot(np.diff(truth["usv.x"]), np.diff(truth["usv.y"]))))
    assert length > 3000.0
    assert dev.max() < 1.0, dev.max()
    # and the file really changed the parameters: the run's config holds the identified values
    cfg = tomllib.loads((d / "pred" / "config.toml").read_text())
    model = tomllib.loads((d / "ident" / "identified.toml").read_text())["parameters"]
    assert cfg["usv"]["tr_intercept"] == model["usv.tr_intercept"] != 2.6341


def test_run_model_cli_and_set_wins(identified, tmp_path, capsys):
    d, _ = identified
    m = str(d / "ident" / "identified.toml")
    assert (
        main(
            [
                "run",
                "autopilot-heading",
                "--model",
                m,
                "--set",
                "usv.kr_intercept=0.7",
                "--out",
                str(tmp_path / "r"),
                "--quiet",
                "--no-plots",
            ]
        )
        == 0
    )
    cfg = tomllib.loads((tmp_path / "r" / "config.toml").read_text())
    assert cfg["usv"]["kr_intercept"] == 0.7  # --set wins over the model file
    assert cfg["usv"]["tv_slope"] == tomllib.loads(Path(m).read_text())["parameters"]["usv.tv_slope"]
    # a scenario whose vehicle has no such parameters: config error naming the key, exit 2
    assert main(["run", "usv-remote", "--model", m, "--out", str(tmp_path / "r2"), "--quiet"]) == 2
    assert "usv.kv_slope" in capsys.readouterr().err


def test_zero_row_logs_exit_2_in_both_commands(tmp_path, capsys):
    cols = ["t", "trial.steer", "trial.thrust", "trial.speed", "trial.heading", "trial.yaw_rate"]
    p = tmp_path / "empty.parquet"
    pd.DataFrame({c: np.array([], float) for c in cols}).to_parquet(p)
    assert main(["identify", "first-order", str(p), "--out", str(tmp_path / "o")]) == 2
    err = capsys.readouterr().err.strip()
    assert err.count("\n") == 0 and str(p) in err and "0 rows" in err
    q = tmp_path / "empty_sub.parquet"
    pd.DataFrame({c: np.array([], float) for c in ["t", "sub.w", "sub.theta", "sub.q", "sub.ds"]}).to_parquet(q)
    assert main(["identify", "ekf", str(q), "--estimate", "Mq", "--out", str(tmp_path / "o2")]) == 2
    err = capsys.readouterr().err.strip()
    assert err.count("\n") == 0 and str(q) in err and "0 rows" in err
    assert not (tmp_path / "o").exists() and not (tmp_path / "o2").exists()


def test_no_usable_manoeuvre_exit_2(tmp_path, capsys):
    t = np.arange(0, 30, 0.1)
    df = pd.DataFrame(
        {
            "t": t,
            "trial.steer": 0.0,
            "trial.thrust": 1000.0,
            "trial.speed": 5.0,
            "trial.heading": 0.0,
            "trial.yaw_rate": 0.0,
        }
    )
    p = tmp_path / "steady.csv"
    df.to_csv(p, index=False)
    assert main(["identify", "first-order", str(p), "--out", str(tmp_path / "o")]) == 2
    err = capsys.readouterr().err.strip()
    assert err.count("\n") == 0 and str(p) in err and "nothing to identify" in err


def test_ekf_starts_off_the_truth_says_so_and_warns_when_stuck(tmp_path, capsys):
    # a log with a manoeuvre: from 0.5 x nominal the estimates move to the truth (the nominal values)
    oceangnc.run("ekf-zigzag", out=tmp_path / "zz", plots=False, overrides={"sim.duration": 100.0, "noise": 1.0})
    assert main(["identify", "ekf", str(tmp_path / "zz"), "--estimate", "Mq,Mds", "--out", str(tmp_path / "a")]) == 0
    out = capsys.readouterr().out
    assert "0.5 x the model's nominal values - not the nominal values" in out and "warning" not in out
    res = json.loads((tmp_path / "a" / "ekf_submarine-vertical.json").read_text())
    for k, truth in (("Mq", -0.002995), ("Mds", -0.003663)):
        p = res["parameters"][k]
        assert p["initial"] == pytest.approx(0.5 * truth, rel=1e-3)
        assert abs(p["estimate"] - truth) < 0.01 * abs(truth)
    doc = tomllib.loads((tmp_path / "a" / "identified.toml").read_text())
    u = doc["uncertainty"]["vehicle.Mq"]
    assert u["ci95"][0] < u["estimate"] < u["ci95"][1]
    assert u["ci95"][1] - u["estimate"] == pytest.approx(1.96 * u["std_error"], rel=1e-3)
    # a straight run without a plane deflection: Mds cannot move, and the command says so
    oceangnc.run(
        "ekf-zigzag", out=tmp_path / "st", plots=False, overrides={"sim.duration": 5.0, "t_start_s": 10.0, "noise": 1.0}
    )
    assert main(["identify", "ekf", str(tmp_path / "st"), "--estimate", "Mq,Mds", "--out", str(tmp_path / "b")]) == 0
    out = capsys.readouterr().out
    assert "warning: Mds never left its initial value" in out
    # starting at the nominal values is flagged
    assert (
        main(
            [
                "identify",
                "ekf",
                str(tmp_path / "zz"),
                "--estimate",
                "Mq",
                "--initial-scale",
                "1",
                "--out",
                str(tmp_path / "c"),
            ]
        )
        == 0
    )
    assert "warning: the initial guess of Mq is the model's nominal value" in capsys.readouterr().out
    # --out is a folder in both commands: a .json name is refused
    assert main(["identify", "ekf", str(tmp_path / "zz"), "--estimate", "Mq", "--out", str(tmp_path / "x.json")]) == 2


def test_first_order_reads_a_field_log_with_a_column_map(identified, tmp_path, capsys):
    """One turning trial written as a CSV with the user's names and units, identified through the importer
    (``--map``): K_r and T_r of that trial within 2 % of the scenario's truth."""
    _d, res = identified
    df = res.df
    turn = df[df["trial.kind"] == 1.0]
    tid = turn["trial.id"].iloc[0]
    one = df[df["trial.id"] == tid]
    csv = pd.DataFrame(
        {
            "time_ms": ((one["t"] - one["t"].iloc[0]) * 1000).round().astype(int),
            "rudder_deg": np.degrees(one["trial.steer"]),
            "hdg_deg": np.degrees(one["trial.heading"]),
            "rot_dps": np.degrees(one["trial.yaw_rate"]),
            "sog": one["trial.speed"],
        }
    )
    p = tmp_path / "turn.csv"
    csv.to_csv(p, index=False)
    code = main(
        [
            "identify",
            "first-order",
            str(p),
            "--map",
            "t=time_ms:ms,act.steer=rudder_deg:deg,usv.psi=hdg_deg:deg,usv.r=rot_dps:deg/s,usv.u=sog",
            "--rate",
            "20",
            "--out",
            str(tmp_path / "o"),
        ]
    )
    assert code == 0, capsys.readouterr().err
    rep = json.loads((tmp_path / "o" / "identification.json").read_text())
    (tr,) = rep["trials"]
    assert tr["kind"] == "turn"
    assert tr["K"] == pytest.approx(one["trial.true_k"].iloc[0], rel=0.02)
    assert tr["T"] == pytest.approx(one["trial.true_t"].iloc[0], rel=0.05)
    doc = tomllib.loads((tmp_path / "o" / "identified.toml").read_text())
    assert doc["parameters"]["usv.kr_slope"] == 0.0 and math.isfinite(doc["parameters"]["usv.kr_intercept"])


def test_first_order_reads_an_ardupilot_bin_directly(identified, tmp_path):
    """One turning trial of a rudder boat as an ArduPilot DataFlash log (GPS, ATT, IMU, RCOU with C1
    steering and C3 throttle PWM), identified straight from the .bin (``--servos rudder``): K per unit
    of normalised steer = K_r x rudder limit within 2 %, T_r within 5 %."""
    from log_writers import DataFlashWriter
    from oceangnc.mavlink.geo import ned_to_latlon

    _d, res = identified
    df = res.df
    tid = df.loc[df["trial.kind"] == 1.0, "trial.id"].iloc[2]
    one = df[df["trial.id"] == tid].reset_index(drop=True)
    usv = res.config.usv
    lim = math.radians(usv.rudder_limit_deg)
    w = DataFlashWriter(tmp_path / "turn.bin")
    w.define(130, "GPS", "QBIHLLff", "TimeUS,Status,GMS,GWk,Lat,Lng,Spd,GCrs")
    w.define(131, "ATT", "Qfff", "TimeUS,Roll,Pitch,Yaw")
    w.define(132, "IMU", "Qf", "TimeUS,GyrZ")
    w.define(133, "RCOU", "QHHHH", "TimeUS,C1,C2,C3,C4")
    t0 = one["t"].iloc[0]
    for i in range(len(one)):
        us = round((one["t"].iat[i] - t0) * 1e6) + 2_000_000
        lat, lon = ned_to_latlon(one["usv.x"].iat[i], one["usv.y"].iat[i], 35.0, 129.0)
        psi = one["trial.heading"].iat[i]
        w.write(
            "GPS",
            us,
            3,
            100_000 + us // 1000,
            2390,
            round(lat * 1e7),
            round(lon * 1e7),
            one["trial.speed"].iat[i],
            math.degrees(psi) % 360,
        )
        w.write("ATT", us, 0.0, 0.0, math.degrees(psi) % 360)
        w.write("IMU", us, one["trial.yaw_rate"].iat[i])
        w.write(
            "RCOU",
            us,
            round(1500 + 400 * one["trial.steer"].iat[i] / lim),
            1500,
            round(1500 + 400 * one["trial.thrust"].iat[i] / usv.rpm_max),
            1500,
        )
    w.close()
    assert (
        main(
            [
                "identify",
                "first-order",
                str(tmp_path / "turn.bin"),
                "--servos",
                "rudder",
                "--rate",
                "20",
                "--out",
                str(tmp_path / "o"),
            ]
        )
        == 0
    )
    rep = json.loads((tmp_path / "o" / "identification.json").read_text())
    (tr,) = rep["trials"]
    assert tr["kind"] == "turn" and rep["columns"]["steer"] == "act.steer"
    assert tr["K"] == pytest.approx(one["trial.true_k"].iloc[0] * lim, rel=0.02)
    assert tr["T"] == pytest.approx(one["trial.true_t"].iloc[0], rel=0.05)


def test_ekf_reads_a_field_csv_through_the_importer(tmp_path):
    """``identify ekf`` on a CSV in the user's names and degrees, mapped with ``--map`` onto the model's
    columns and resampled at the log's 100 Hz: from 0.5 x nominal, Mq and Mds within 1 % of the truth."""
    res = oceangnc.run("ekf-zigzag", out=tmp_path / "zz", plots=False, overrides={"sim.duration": 100.0})
    df = res.df
    csv = pd.DataFrame(
        {
            "time_s": df["t"],
            "heave": df["sub.w"],
            "pitch_deg": np.degrees(df["sub.theta"]),
            "q_dps": np.degrees(df["sub.q"]),
            "plane_deg": np.degrees(df["sub.ds"]),
        }
    )
    p = tmp_path / "dive.csv"
    csv.to_csv(p, index=False)
    assert (
        main(
            [
                "identify",
                "ekf",
                str(p),
                "--estimate",
                "Mq,Mds",
                "--rate",
                "100",
                "--out",
                str(tmp_path / "o"),
                "--map",
                "t=time_s,sub.w=heave,sub.theta=pitch_deg:deg,sub.q=q_dps:deg/s,sub.ds=plane_deg:deg",
            ]
        )
        == 0
    )
    est = json.loads((tmp_path / "o" / "ekf_submarine-vertical.json").read_text())["parameters"]
    for k in ("Mq", "Mds"):
        truth = getattr(res.config.vehicle, k)
        assert est[k]["initial"] == pytest.approx(0.5 * truth)
        assert est[k]["estimate"] == pytest.approx(truth, rel=0.01)
