"""Sweeps: designs and seeds, validation before any run, failure recording, report statistics.

Runs here use ``workers=0`` (in this process) and short durations; the Dask and kill/resume tests are
in ``test_sweep_dask.py``.
"""

from __future__ import annotations

import json
import math

import numpy as np
import pandas as pd
import pytest

from oceangnc.cli import main
from oceangnc.errors import ConfigError, DivergenceError
from oceangnc.io.config import ScenarioConfig
from oceangnc.scenarios.base import Scenario, registry
from oceangnc.sweep import build_design, make_report, read_results, sweep
from oceangnc.sweep.design import parse_grid, split_top

GUSTY = {"environment.wind.gust_sigma": 0.5}


def test_grid_design_order_seeds_and_stable_ids():
    """Every combination once, last key fastest; run k of a point has sim.seed = base + k; ids stable."""
    d = build_design(
        "usv-turn",
        grid=["command.thrust_stbd_kgf=10,20", "environment.current.speed=0,0.1,0.2"],
        seeds=3,
        base_seed=7,
        duration=2.0,
    )
    runs = d.runs()
    assert len(runs) == 2 * 3 * 3
    assert [r.params["environment.current.speed"] for r in runs[:9:3]] == [0, 0.1, 0.2]
    assert [r.seed for r in runs[:3]] == [7, 8, 9]
    assert len({r.run_id for r in runs}) == 18 and len({r.point_id for r in runs}) == 6
    again = build_design(
        "usv-turn",
        grid={"command.thrust_stbd_kgf": [10, 20], "environment.current.speed": [0, 0.1, 0.2]},
        seeds=3,
        base_seed=7,
        duration=2.0,
    ).runs()
    assert [r.run_id for r in again] == [r.run_id for r in runs]
    # another fixed override is another run
    other = build_design(
        "usv-turn",
        grid=["command.thrust_stbd_kgf=10,20", "environment.current.speed=0,0.1,0.2"],
        seeds=3,
        base_seed=7,
        duration=3.0,
    ).runs()
    assert not {r.run_id for r in other} & {r.run_id for r in runs}
    # the base seed defaults to the config's sim.seed (--set sim.seed=S)
    assert [
        r.seed
        for r in build_design(
            "usv-turn", grid=["command.thrust_stbd_kgf=10"], seeds=2, overrides={"sim.seed": 40}
        ).runs()
    ] == [40, 41]


def test_grid_value_parsing():
    assert split_top("[1,2],3,'a,b'") == ["[1,2]", "3", "'a,b'"]
    g = parse_grid(["a.b=linspace(0, 1, 5)", 'c.d=1,2.5,true,"x"'])
    assert g["a.b"] == pytest.approx([0, 0.25, 0.5, 0.75, 1.0])
    assert g["c.d"] == [1, 2.5, True, "x"]


def test_random_design_reproducible_in_bounds_and_independent_per_key():
    """Draws are seeded, inside their bounds, and a key's draws do not depend on the other keys."""
    a = build_design(
        "usv-turn-current",
        random=["environment.current.speed=uniform(0.05,0.3)", "environment.current.direction_deg=randint(0,359)"],
        samples=200,
        design_seed=3,
    )
    b = build_design(
        "usv-turn-current", random=["environment.current.speed=uniform(0.05,0.3)"], samples=200, design_seed=3
    )
    pa_, pb = a.points(), b.points()
    v = np.array([p["environment.current.speed"] for p in pa_])
    assert np.all((v >= 0.05) & (v <= 0.3)) and v.std() > 0.05
    assert [p["environment.current.speed"] for p in pb] == list(v)
    dirs = [p["environment.current.direction_deg"] for p in pa_]
    assert all(isinstance(x, int) and 0 <= x <= 359 for x in dirs)
    assert a.points() == pa_  # same command, same draws
    c = build_design(
        "usv-turn-current", random=["environment.current.speed=uniform(0.05,0.3)"], samples=200, design_seed=4
    )
    assert [p["environment.current.speed"] for p in c.points()] != list(v)


@pytest.mark.parametrize(
    "args, key",
    [
        (["--grid", "command.thrust_stbd_kgf=10,20", "--grid", "command.no_such_key=1,2"], "command.no_such_key"),
        (["--grid", "command.thrust_stbd_kgf=10,20,75"], "command.thrust_stbd_kgf"),
        (["--random", "environment.current.speed=normal(0.1,1.0)", "--samples", "50"], "environment.current.speed"),
        (["--grid", "sim.seed=1,2"], "sim.seed"),
    ],
)
def test_bad_grid_rejected_before_any_run(tmp_path, capsys, args, key):
    """A bad key or out-of-range value anywhere in the sweep: exit 2, one line naming the key, no run."""
    out = tmp_path / "s"
    rc = main(["sweep", "usv-turn-current", *args, "--duration", "1", "--workers", "0", "--out", str(out)])
    err = capsys.readouterr().err.strip()
    assert rc == 2
    assert "\n" not in err and key in err and "Traceback" not in err
    assert not out.exists()  # nothing was started or written


def test_bad_value_out_of_range_api_message():
    from oceangnc.sweep import run_sweep

    d = build_design("usv-turn", grid={"command.thrust_port_kgf": [30, 60]}, duration=1.0)
    with pytest.raises(ConfigError, match=r"command\.thrust_port_kgf = 60.*-50 <= value <= 50"):
        run_sweep(d, "/nonexistent/never-created", workers=0)


class _Diverging(Scenario):
    """A scenario that blows up after a chosen time (to test that divergence is recorded)."""

    name = "test-sweep-diverge"
    summary = "raises DivergenceError"
    Config = ScenarioConfig
    defaults = {"sim": {"duration": 1.0}}

    def run(self, cfg, ctx):
        for i in range(5):
            ctx.log.append(0.1 * i, {"x.a": float(i)})
        raise DivergenceError(0.4, "x", {"a": math.inf})


def test_failed_and_diverged_runs_are_recorded_and_the_sweep_goes_on(tmp_path, monkeypatch):
    monkeypatch.setitem(registry(), _Diverging.name, _Diverging())
    res = sweep(_Diverging.name, seeds=2, out=tmp_path / "d", workers=0)
    assert list(res.table["status"]) == ["diverged", "diverged"]
    assert res.table["error"].str.contains("diverged at t=0.400 s in block 'x'").all()
    assert (res.table["duration_s"] == 0.4).all()
    # a run that fails at run time (dt not dividing the control period) is recorded, the other runs
    res = sweep("usv-turn", grid={"sim.dt": [0.001, 0.1]}, duration=1.0, out=tmp_path / "f", workers=0)
    t = res.table.set_index("param.sim.dt")
    assert t.loc[0.001, "status"] == "ok" and t.loc[0.1, "status"] == "failed"
    assert t.loc[0.1, "error"].startswith("ConfigError:") and "sim.dt = 0.1" in t.loc[0.1, "error"]
    assert math.isfinite(t.loc[0.001, "usv.turn_radius_m"]) and math.isnan(t.loc[0.1, "usv.turn_radius_m"])
    on_disk = read_results(tmp_path / "f")
    assert list(on_disk["run_id"]) == list(res.table["run_id"])


@pytest.fixture(scope="module")
def gusty_sweep(tmp_path_factory):
    out = tmp_path_factory.mktemp("sweep") / "gusty"
    return sweep(
        "usv-turn-wind",
        grid={"command.thrust_stbd_kgf": [10, 20]},
        seeds=3,
        duration=6.0,
        overrides=GUSTY,
        out=out,
        workers=0,
    )


def test_seeds_change_the_noise_and_nothing_else(gusty_sweep):
    """Gusty wind: the three seeds of a point give three different results; the swept key matters."""
    t = gusty_sweep.table
    assert (t["status"] == "ok").all() and len(t) == 6
    for _, g in t.groupby("point_id"):
        assert sorted(g["seed"]) == [0, 1, 2]
        assert g["usv.steady_speed_mps"].nunique() == 3
    cfg = json.loads((gusty_sweep.out_dir / "runs" / t["run_id"][2] / "summary.json").read_text())
    assert cfg["usv.steady_speed_mps"] == t["usv.steady_speed_mps"][2]
    assert "seed = 2" in (gusty_sweep.out_dir / "runs" / t["run_id"][2] / "config.toml").read_text()


def test_report_statistics_per_point(gusty_sweep, capsys):
    """points.csv holds the mean and sample std over seeds of each point; one plot per metric."""
    rc = main(["sweep-report", str(gusty_sweep.out_dir)])
    out = capsys.readouterr().out
    assert rc == 0 and "| command.thrust_stbd_kgf |" in out and "3/3" in out
    pts = pd.read_csv(gusty_sweep.out_dir / "report" / "points.csv")
    t = gusty_sweep.table
    for _, p in pts.iterrows():
        g = t[t["param.command.thrust_stbd_kgf"] == p["param.command.thrust_stbd_kgf"]]["usv.turn_radius_m"]
        assert p["usv.turn_radius_m.mean"] == pytest.approx(g.mean(), rel=1e-12)
        assert p["usv.turn_radius_m.std"] == pytest.approx(g.std(ddof=1), rel=1e-9)
        assert p["runs"] == 3 and p["failed"] == 0
    # a stiffer starboard thruster (20 vs 10 kgf, port 30) turns wider
    r = pts.set_index("param.command.thrust_stbd_kgf")["usv.turn_radius_m.mean"]
    assert r[20] > r[10]
    assert (gusty_sweep.out_dir / "report" / "usv.turn_radius_m.png").stat().st_size > 5000
    rep = make_report(gusty_sweep.out_dir, metrics=["usv.yaw_rate_degps"], plots=False)
    assert rep.metrics == ["usv.yaw_rate_degps"] and rep.keys == ["command.thrust_stbd_kgf"]


def test_existing_folder_needs_resume(gusty_sweep, capsys):
    rc = main(
        [
            "sweep",
            "usv-turn-wind",
            "--grid",
            "command.thrust_stbd_kgf=10,20",
            "--seeds",
            "3",
            "--duration",
            "6",
            "--set",
            "environment.wind.gust_sigma=0.5",
            "--workers",
            "0",
            "--out",
            str(gusty_sweep.out_dir),
            "--quiet",
        ]
    )
    assert rc == 2 and "--resume" in capsys.readouterr().err
    # with --resume and the same command nothing is run again; one more seed runs only the new runs
    rc = main(
        [
            "sweep",
            "usv-turn-wind",
            "--grid",
            "command.thrust_stbd_kgf=10,20",
            "--seeds",
            "4",
            "--duration",
            "6",
            "--set",
            "environment.wind.gust_sigma=0.5",
            "--workers",
            "0",
            "--out",
            str(gusty_sweep.out_dir),
            "--quiet",
            "--resume",
        ]
    )
    out = capsys.readouterr().out
    assert rc == 0 and "2 run(s) done now, 6 already in the table" in out
    t = read_results(gusty_sweep.out_dir)
    assert len(t) == 8 and t["run_id"].is_unique and sorted(t["seed"].unique()) == [0, 1, 2, 3]


@pytest.mark.parametrize(
    "dist", ["uniform(0,1)", "loguniform(0.01,1)", "normal(0,1)", "randint(0,9)", 'choice("a","b","c")']
)
def test_fewer_samples_are_the_first_draws_of_more(dist):
    """N draws are the first N of a longer series (a sweep can be extended with --samples)."""
    from oceangnc.sweep.design import Design, parse_random

    def draws(n):
        return [p["k.x"] for p in Design("usv-turn", random=parse_random({"k.x": dist}), samples=n).points()]

    assert draws(7) == draws(50)[:7]


def test_random_sweep_report_and_resume_guard(tmp_path, capsys):
    """Monte Carlo: 24 draws, in-process; the report bins the draws; --resume refuses another config."""
    out = tmp_path / "mc"
    base = [
        "sweep",
        "usv-turn-current",
        "--random",
        "environment.current.direction_deg=uniform(0,360)",
        "--random",
        'command.mode=choice("thrust")',
        "--samples",
        "24",
        "--duration",
        "2",
        "--workers",
        "0",
        "--quiet",
        "--out",
        str(out),
    ]
    assert main(base) == 0
    t = read_results(out)
    assert len(t) == 24 and t["point_id"].nunique() == 24 and (t["param.command.mode"] == "thrust").all()
    assert main(["sweep-report", str(out), "--quiet"]) == 0
    pts = pd.read_csv(out / "report" / "points.csv")
    assert len(pts) == 24 and (pts["usv.turn_radius_m.n"] == 1).all() and pts["usv.turn_radius_m.std"].isna().all()
    assert (out / "report" / "usv.turn_radius_m.png").exists()
    capsys.readouterr()
    assert main([*base[:-2], "--out", str(out), "--resume", "--duration", "3"]) == 2
    assert "--resume needs the same command" in capsys.readouterr().err
    assert main(["sweep-report", str(tmp_path / "nothing")]) == 2
    assert "no sweep results table" in capsys.readouterr().err
