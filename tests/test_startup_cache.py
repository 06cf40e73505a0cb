"""Compile once per machine (issue 19): the package's numba caches live in the user cache folder and
survive a reinstall of the same version; a cached ``oceangnc run`` loads them without numba's full
target refresh and gives the same log; derived values are computed once."""

from __future__ import annotations

import json
import os
import shutil
import subprocess
import sys
from pathlib import Path

import pyarrow.parquet as pq

SRC = Path(__file__).resolve().parents[1] / "src"

PROBE = (
    "import json, oceangnc\n"
    "from oceangnc.core.rotations import wrap\n"
    "v = wrap(7.0)\n"
    "s = wrap.stats\n"
    "print(json.dumps([oceangnc.__file__, sum(s.cache_hits.values()), sum(s.cache_misses.values()), v,\n"
    "                  wrap._cache.cache_path]))\n"
)


def _install(site: Path) -> None:
    """A non-editable install of the package's files: a fresh copy (new mtimes, no __pycache__)."""
    shutil.rmtree(site / "oceangnc", ignore_errors=True)
    shutil.copytree(SRC / "oceangnc", site / "oceangnc", ignore=shutil.ignore_patterns("__pycache__"))


def _probe(site: Path, cache: Path, code: str = PROBE):
    env = dict(os.environ, PYTHONPATH=str(site), OCEANGNC_CACHE_DIR=str(cache))
    env.pop("NUMBA_CACHE_DIR", None)
    r = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, env=env, timeout=300, cwd=site)
    assert r.returncode == 0, r.stderr
    return json.loads(r.stdout.strip().splitlines()[-1])


def test_package_numba_cache_survives_a_reinstall_and_an_edit_recompiles(tmp_path):
    site, cache = tmp_path / "site", tmp_path / "cache"
    site.mkdir()
    _install(site)
    f0, hits0, miss0, v0, path0 = _probe(site, cache)
    assert f0.startswith(str(site))  # the copy is what runs
    assert (hits0, miss0) == (0, 1)  # empty cache: compiled
    assert Path(path0) == cache / "numba-0.1.0" / "core"  # in the user cache folder, not __pycache__
    assert not list((site / "oceangnc" / "core").glob("__pycache__/rotations.wrap*"))
    _install(site)  # reinstall of the same version: the package folder is replaced
    f1, hits1, miss1, v1, _ = _probe(site, cache)
    assert (hits1, miss1) == (1, 0) and v1 == v0  # loaded from disk, not compiled again
    # an edited source file (same version) is compiled again: the stamp is the file's content
    rot = site / "oceangnc" / "core" / "rotations.py"
    rot.write_text(rot.read_text() + "\n# edited\n")
    _, hits2, miss2, v2, _ = _probe(site, cache)
    assert (hits2, miss2) == (0, 1) and v2 == v0


def test_numba_cache_dir_of_the_user_wins(tmp_path):
    code = (
        "import json, oceangnc\nfrom oceangnc.core.rotations import wrap\nprint(json.dumps(wrap._cache.cache_path))\n"
    )
    env = dict(os.environ, PYTHONPATH=str(SRC), NUMBA_CACHE_DIR=str(tmp_path / "nb"))
    r = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, env=env, timeout=300)
    assert r.returncode == 0, r.stderr
    assert json.loads(r.stdout.strip().splitlines()[-1]).startswith(str(tmp_path / "nb"))


def test_cli_run_loads_lean_and_gives_the_same_log_as_the_api(tmp_path):
    """``oceangnc run`` loads cached kernels without numba's full refresh (no numba.np.arraymath, no
    SciPy, no pandas in the process) and its log is bit-identical to an API run's."""
    import oceangnc

    # first the API run in this process: it also fills the caches (numba, derived values) the CLI loads
    api = oceangnc.run("combined-survey", duration=3, out=tmp_path / "api", plots=False)
    code = (
        "import sys, json\n"
        "from oceangnc.cli import main\n"
        f"rc = main(['run', 'combined-survey', '--duration', '3', '--quiet', '--no-plots', '--out', {str(tmp_path / 'cli')!r}])\n"  # noqa: E501
        "print(json.dumps([rc] + [m in sys.modules for m in ('numba.np.arraymath', 'scipy.linalg', 'pandas')]))\n"
    )
    env = dict(os.environ, PYTHONPATH=str(SRC) + os.pathsep + os.environ.get("PYTHONPATH", ""))
    r = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, env=env, timeout=600)
    assert r.returncode == 0, r.stderr
    rc, arraymath, scipy_linalg, pandas = json.loads(r.stdout.strip().splitlines()[-1])
    assert rc == 0 and not arraymath and not scipy_linalg and not pandas
    cli = pq.read_table(tmp_path / "cli" / "log.parquet")
    assert cli.column_names == api.log.column_names
    assert cli.equals(api.log)
    s_cli = json.loads((tmp_path / "cli" / "summary.json").read_text())
    assert {k: v for k, v in s_cli.items() if k != "wall_time_s"} == {
        k: v for k, v in api.summary.items() if k != "wall_time_s"
    }


def test_derived_value_is_computed_once_and_again_after_an_edit(tmp_path, monkeypatch):
    from oceangnc import derived

    monkeypatch.setenv("OCEANGNC_CACHE_DIR", str(tmp_path))
    calls = []

    def compute():
        calls.append(1)
        return [0.1 + 0.2, 1.0 / 3.0]

    a = derived.cached("x", {"speed": 0.6}, compute, ("guidance",))
    b = derived.cached("x", {"speed": 0.6}, compute, ("guidance",))
    assert a == b == [0.1 + 0.2, 1.0 / 3.0] and len(calls) == 1  # exact floats from the disk
    derived.cached("x", {"speed": 0.7}, compute, ("guidance",))
    assert len(calls) == 2  # other inputs: computed
    monkeypatch.setattr(derived, "sources_digest", lambda subs: "edited")
    derived.cached("x", {"speed": 0.6}, compute, ("guidance",))
    assert len(calls) == 3  # other source: computed


def test_fast_exit_keeps_every_output(tmp_path):
    """``oceangnc run`` ends without the interpreter's teardown: its output (a pipe here) is flushed,
    the exit code kept, and an atexit handler of the process still runs."""
    code = (
        "import atexit, sys\n"
        f"atexit.register(lambda: open({str(tmp_path / 'atexit')!r}, 'w').write('ran'))\n"
        "from oceangnc.cli import main\n"
        "sys.exit(main())\n"
    )
    env = dict(os.environ, PYTHONPATH=str(SRC) + os.pathsep + os.environ.get("PYTHONPATH", ""))
    args = ["run", "usv-turn", "--duration", "1", "--quiet", "--no-plots", "--json", "--out", str(tmp_path / "r")]
    r = subprocess.run([sys.executable, "-c", code, *args], capture_output=True, text=True, env=env, timeout=300)
    assert r.returncode == 0, r.stderr
    assert json.loads(r.stdout.strip().splitlines()[-1])["status"] == "ok"
    assert (tmp_path / "atexit").read_text() == "ran"
    bad = subprocess.run(
        [sys.executable, "-c", code, "run", "usv-turn", "--set", "sim.dt=-1", "--out", str(tmp_path / "b")],
        capture_output=True,
        text=True,
        env=env,
        timeout=300,
    )
    assert bad.returncode == 2 and bad.stderr.startswith("error: ") and "sim.dt" in bad.stderr
