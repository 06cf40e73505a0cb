"""The light column table (oceangnc.io.frame) against pandas: the same summaries and the same figure
bytes for every scenario that declares ``frame = "columns"``, Series semantics of a column, and a light
plot module that imports neither numba nor pandas (the drawer forked at start-up relies on it)."""

from __future__ import annotations

import math
import os
import subprocess
import sys
from pathlib import Path

import numpy as np
import pandas as pd
import pyarrow as pa
import pytest

import oceangnc
from oceangnc.api import log_frame
from oceangnc.io.frame import Col, Columns, Plain
from oceangnc.scenarios.base import LIGHT_PLOTS, SCENARIO_INDEX, get_scenario, light_plots, registry

SRC = Path(__file__).resolve().parents[1] / "src"
COLUMN_SCENARIOS = sorted(n for n, sc in registry().items() if sc.frame == "columns")


def test_light_plot_modules_belong_to_column_scenarios():
    assert COLUMN_SCENARIOS, "the flagship family reads columns"
    assert {"combined-survey", "usv-turn"} <= set(COLUMN_SCENARIOS)
    for name, (module, _) in SCENARIO_INDEX.items():
        if module in LIGHT_PLOTS:
            assert get_scenario(name).frame == "columns", name
            assert light_plots(name) == LIGHT_PLOTS[module]
        else:
            assert light_plots(name) is None


def _same(a, b) -> bool:
    if isinstance(a, float) and isinstance(b, float) and math.isnan(a) and math.isnan(b):
        return True
    return a == b and type(a) is type(b)


@pytest.mark.parametrize("name", COLUMN_SCENARIOS)
def test_summary_and_figures_on_columns_equal_those_on_pandas(name, tmp_path):
    res = oceangnc.run(name, duration=6.0, out=tmp_path / "run", plots=False)
    sc, cfg, table = get_scenario(name), res.config, res.log
    on_pandas = sc.summarize(table.to_pandas(), cfg)
    on_columns = sc.summarize(Columns.from_table(table), cfg)
    assert on_pandas.keys() == on_columns.keys()
    assert all(_same(on_pandas[k], on_columns[k]) for k in on_pandas), (on_pandas, on_columns)
    # on columns against a DataFrame; with a light plot module, the drawer's way (the config as plain values)
    a, b = tmp_path / "pandas", tmp_path / "columns"
    a.mkdir(), b.mkdir()
    files_a = sc.plot(table.to_pandas(), cfg, a)
    light = light_plots(name)
    if light is None:
        files_b = sc.plot(Columns.from_table(table), cfg, b)
    else:
        jobs = __import__(light, fromlist=["plot_jobs"]).plot_jobs(
            name, Columns.from_table(table), Plain(cfg.model_dump()), b
        )
        files_b = [p for job in jobs for p in job()]
    assert [p.name for p in files_a] == [p.name for p in files_b] and files_a
    for pa_, pb in zip(files_a, files_b):
        assert pa_.read_bytes() == pb.read_bytes(), pa_.name


def test_log_frame_follows_the_scenario():
    table = pa.Table.from_arrays([pa.array([0.0, 0.1])], names=["t"])
    assert isinstance(log_frame(get_scenario("combined-survey"), table), Columns)
    assert isinstance(log_frame(get_scenario("berthing-dock"), table), pd.DataFrame)


def test_a_column_behaves_as_a_series():
    x = np.array([3.0, np.nan, -1.0, 2.5, 7.0])
    s, c = pd.Series(x), Columns({"x": x})["x"]
    for f in ("max", "min", "sum", "mean", "median", "std", "var"):
        assert getattr(c, f)() == pytest.approx(getattr(s, f)(), rel=1e-15), f  # NaN skipped, ddof = 1
    assert np.mean(c) == pytest.approx(s.mean())
    assert c.iloc[-1] == s.iloc[-1] and c.iloc[0] == s.iloc[0]
    assert isinstance(np.hypot(c, c), Col) and isinstance(c > 0, Col) and isinstance(c[c > 0], Col)
    assert isinstance(np.column_stack([c, c]), np.ndarray) and not isinstance(np.column_stack([c, c]), Col)
    assert np.column_stack([c, c]).mean(axis=1).shape == (5,)  # numpy reductions on 2-D arrays
    np.testing.assert_array_equal(c.abs().to_numpy(), s.abs().to_numpy())
    assert math.isnan(Columns({"y": [np.nan, np.nan]})["y"].max())  # all-NaN: NaN, no warning
    assert Columns({"b": [True, False, True]})["b"].sum() == 2


def test_columns_offer_the_dataframe_subset():
    df = Columns({"t": [0.0, 1.0, 2.0], "a": [1.0, 2.0, 3.0]})
    assert len(df) == 3 and df.columns == ["t", "a"] and "a" in df and "b" not in df and list(df) == ["t", "a"]
    np.testing.assert_array_equal(df[["a", "t"]].to_numpy(), [[1, 0], [2, 1], [3, 2]])
    cp = df.copy()
    cp["a"] = cp["a"] * 2
    cp["k"] = 5.0
    np.testing.assert_array_equal(df["a"], [1.0, 2.0, 3.0])  # a copy is deep, as DataFrame.copy
    np.testing.assert_array_equal(cp["k"], [5.0, 5.0, 5.0])
    with pytest.raises(ValueError, match="column 'z': 2 values for 3 rows"):
        cp["z"] = [1.0, 2.0]
    with pytest.raises(ValueError, match="column 'a': 1 values for 3 rows"):
        cp["a"] = [1.0]
    np.testing.assert_array_equal(cp["a"], [2.0, 4.0, 6.0])  # a refused assignment keeps the column
    late = df[df["t"] >= 1.0]  # rows by a boolean mask
    assert len(late) == 2 and late["a"].iloc[0] == 2.0 and late.columns == df.columns
    with pytest.raises(KeyError):
        df["missing"]
    with pytest.raises(TypeError, match="boolean row mask"):
        df[np.array([True, False])]
    with pytest.raises(ValueError, match="different lengths"):
        Columns({"a": [1.0], "b": [1.0, 2.0]})


def test_from_table_reads_chunks_slices_and_nulls_as_pandas_does():
    a = pa.chunked_array([pa.array([9.0, 1.0, 2.0]).slice(1), pa.array([3.0])])
    b = pa.chunked_array([pa.array([1.0, None]), pa.array([4.0])])
    i = pa.chunked_array([pa.array([1, 2, 3], pa.int32())])
    table = pa.Table.from_arrays([a, b, i], names=["a", "b", "i"])
    cols, df = Columns.from_table(table), table.to_pandas()
    for k in ("a", "b", "i"):
        np.testing.assert_array_equal(cols[k], df[k].to_numpy())
        assert cols[k].dtype == df[k].dtype
    cols["a"][0] = -1.0  # writable (copied out of the Arrow buffers)


def test_plain_config_reads_as_the_config():
    from oceangnc.api import resolve_config

    _, cfg = resolve_config("combined-survey")
    plain = Plain(cfg.model_dump())
    assert plain.guidance.waypoints == cfg.guidance.waypoints
    assert plain.control.uuv.kind == cfg.control.uuv.kind
    assert plain.sim.dt == cfg.sim.dt
    assert plain["sim"]["dt"] == cfg.sim.dt and plain == cfg.model_dump()  # by key too, equal values
    with pytest.raises(AttributeError, match="nope"):
        _ = plain.sim.nope


def test_a_config_that_does_not_pickle_makes_the_parent_draw(tmp_path):
    """The early drawer gets no "go" when the config cannot be sent: it ends, and the parent draws."""
    from oceangnc import postproc

    post = postproc.start_early("combined-survey", LIGHT_PLOTS["combined"])
    if post is None:
        pytest.skip("fork is not safe here (threads in this process)")

    class Unpicklable:
        def model_dump(self):
            return {"lock": __import__("threading").Lock()}

    post.go(tmp_path, Unpicklable())
    assert post.plots() is None  # the drawer ended without drawing; the run falls back to in-process
    post.close()


def test_a_light_plot_module_imports_neither_numba_nor_pandas():
    code = (
        "import sys, oceangnc.api\n"
        f"import {LIGHT_PLOTS['combined']}\n"
        "print([m for m in ('numba', 'pandas', 'oceangnc.models') if m in sys.modules])\n"
    )
    env = dict(os.environ, PYTHONPATH=str(SRC))
    r = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, env=env, timeout=120)
    assert r.returncode == 0, r.stderr
    assert r.stdout.strip() == "[]"
