"""Start-up cost: lazy scenario registry, no heavy import or numba call where none is needed,
and the per-rhs RK4 stepper cached on disk across processes (issue 19, "what a user waits for")."""

from __future__ import annotations

import json
import os
import subprocess
import sys
from pathlib import Path

SRC = str(Path(__file__).resolve().parents[1] / "src")


def _py(code: str, env_extra: dict | None = None) -> str:
    env = dict(os.environ, PYTHONPATH=SRC + os.pathsep + os.environ.get("PYTHONPATH", ""))
    env.update(env_extra or {})
    r = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, env=env, timeout=300)
    assert r.returncode == 0, r.stderr
    return r.stdout.strip().splitlines()[-1]


def test_scenario_index_matches_the_modules():
    from oceangnc.scenarios.base import SCENARIO_INDEX, registry

    reg = registry()
    assert set(SCENARIO_INDEX) == set(reg)
    for name, (mod, summary) in SCENARIO_INDEX.items():
        assert type(reg[name]).__module__ == f"oceangnc.scenarios.{mod}" or reg[name].__class__.__module__.endswith(
            mod
        ), name
        assert reg[name].summary == summary, name


def test_list_imports_no_scenario_module_and_no_heavy_library():
    out = _py(
        "import sys, io, contextlib\n"
        "from oceangnc.cli import main\n"
        "with contextlib.redirect_stdout(io.StringIO()) as f: main(['list'])\n"
        "heavy = [m for m in ('numba', 'scipy', 'matplotlib', 'pandas', 'dask', 'fastapi', 'numpy', 'pydantic', "
        "'pyarrow') if m in sys.modules]\n"
        "scen = sorted(m for m in sys.modules if m.startswith('oceangnc.scenarios.') and m != 'oceangnc.scenarios.base')\n"  # noqa: E501
        "import json; print(json.dumps([heavy, scen, f.getvalue().count(chr(10))]))"
    )
    heavy, scen, lines = json.loads(out)
    assert heavy == [] and scen == []
    from oceangnc.scenarios.base import SCENARIO_INDEX

    assert lines == len(SCENARIO_INDEX)  # every shipped scenario, one line each


def test_run_imports_only_its_scenario_module_and_no_scipy_optimize():
    out = _py(
        "import sys\n"
        "from oceangnc.api import resolve_config\n"
        "import numpy as np\n"
        "sc, cfg = resolve_config('combined-survey', duration=0.1)\n"
        "sc.build(cfg, np.random.default_rng(0))\n"
        "scen = sorted(m for m in sys.modules if m.startswith('oceangnc.scenarios.') and m != 'oceangnc.scenarios.base')\n"  # noqa: E501
        "import json; print(json.dumps([scen, 'scipy.optimize' in sys.modules, 'matplotlib' in sys.modules]))"
    )
    scen, scipy_loaded, mpl_loaded = json.loads(out)
    assert scen == ["oceangnc.scenarios._combined_plots", "oceangnc.scenarios._common", "oceangnc.scenarios.combined"]
    assert not scipy_loaded and not mpl_loaded


def test_rk4_stepper_is_loaded_from_the_disk_cache_in_a_new_process(tmp_path):
    code = (
        "from oceangnc.models.usv import USVConfig, USVPlant\n"
        "pl = USVPlant(USVConfig()); pl.u[:2] = 100.0\n"
        "pl.advance(0.0, 0.001, 10)\n"
        "s = pl._advance.stats\n"
        "print(sum(s.cache_hits.values()), sum(s.cache_misses.values()), float(pl.x[3]))"
    )
    env = {"OCEANGNC_CACHE_DIR": str(tmp_path)}
    first = _py(code, env).split()
    second = _py(code, env).split()
    assert int(second[0]) == 1 and int(second[1]) == 0  # second process: a cache hit, no compilation
    assert first[2] == second[2] and float(first[2]) > 0.0  # same numbers, and the boat moved ahead
    assert list(tmp_path.glob("steppers-*/rk4__oceangnc_models_usv__usv_rhs.py"))


def test_bracket_root_and_newton_solve_what_they_claim():
    import numpy as np

    from oceangnc.core.roots import bracket_root, newton

    r = bracket_root(lambda x: x**3 - 2.0, 0.0, 2.0)
    assert abs(r - 2.0 ** (1 / 3)) < 1e-11
    x, ok = newton(lambda z: np.array([z[0] ** 2 + z[1] ** 2 - 4.0, z[0] - z[1]]), [1.0, 0.5])
    assert ok and np.allclose(x, [2**0.5, 2**0.5], atol=1e-12)
