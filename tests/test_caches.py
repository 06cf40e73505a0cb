"""Caches that cannot go stale (issue 25): every compiled function, generated driver and derived value
is cached under a key of the content of every source file it may call (oceangnc.core.caches)."""

from __future__ import annotations

import json
import os
import shutil
import subprocess
import sys
from pathlib import Path

import pyarrow.parquet as pq

SRC = Path(__file__).resolve().parents[1] / "src"
MYLAW = Path(__file__).resolve().parent / "data" / "mylaw"

PROBE = (
    "import json, oceangnc\n"
    "from oceangnc.sensors.filters import angle_lowpass_step as f\n"
    "v = f(0.0, 0.5, 3.0)\n"
    "s = f.stats\n"
    "print(json.dumps([oceangnc.__file__, sum(s.cache_hits.values()), sum(s.cache_misses.values()), v,\n"
    "                  f._cache.cache_path]))\n"
)


def _install(site: Path) -> None:
    """A non-editable install of the package's files: a fresh copy (new mtimes, no __pycache__)."""
    shutil.rmtree(site / "oceangnc", ignore_errors=True)
    shutil.copytree(SRC / "oceangnc", site / "oceangnc", ignore=shutil.ignore_patterns("__pycache__"))


def _env(**kw) -> dict:
    env = {k: v for k, v in os.environ.items() if not k.startswith(("NUMBA_CACHE_DIR", "OCEANGNC_NUMBA"))}
    env.update(kw)
    return env


def _probe(site: Path, cache: Path, code: str = PROBE):
    env = _env(PYTHONPATH=str(site), OCEANGNC_CACHE_DIR=str(cache))
    r = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, env=env, timeout=300, cwd=site)
    assert r.returncode == 0, r.stderr
    return json.loads(r.stdout.strip().splitlines()[-1])


def test_a_reinstall_keeps_the_cache_and_an_edit_of_a_callee_in_another_file_recompiles(tmp_path):
    """``angle_lowpass_step`` (sensors/filters.py) calls ``wrap`` (core/rotations.py): numba alone
    would keep the caller's machine code after an edit of the callee's file."""
    site, cache = tmp_path / "site", tmp_path / "cache"
    site.mkdir()
    _install(site)
    f0, hits0, miss0, v0, path0 = _probe(site, cache)
    assert f0.startswith(str(site))  # the copy is what runs
    assert (hits0, miss0) == (0, 1)  # empty cache: compiled
    assert Path(path0).is_relative_to(cache) and Path(path0).parts[len(cache.parts)].startswith("numba-0.1.0-")
    _install(site)  # reinstall of the same files: new mtimes, same content, same key
    _, hits1, miss1, v1, path1 = _probe(site, cache)
    assert (hits1, miss1) == (1, 0) and v1 == v0 and path1 == path0
    # the callee's file is edited: wrap now returns its argument doubled
    rot = site / "oceangnc" / "core" / "rotations.py"
    src = rot.read_text()
    rot.write_text(src + "\n\n@njit(cache=True)\ndef wrap(a):\n    return 2.0 * a\n")
    _, hits2, miss2, v2, path2 = _probe(site, cache)
    assert (hits2, miss2) == (0, 1) and path2 != path0  # a new key: compiled with the new callee
    assert v0 == 1.5 and v2 == 6.0  # wrap(0 + 0.5 wrap(3)) before, 2 (0 + 0.5 * 2 * 3) after
    rot.write_text(src)  # undone: the old key, the old machine code, the old value
    _, hits3, miss3, v3, path3 = _probe(site, cache)
    assert (hits3, miss3) == (1, 0) and v3 == v0 and path3 == path0


def test_a_numba_cache_dir_of_the_user_is_the_base(tmp_path):
    code = (
        "import json, oceangnc\nfrom oceangnc.core.rotations import wrap\nprint(json.dumps(wrap._cache.cache_path))\n"
    )
    env = _env(PYTHONPATH=str(SRC), NUMBA_CACHE_DIR=str(tmp_path / "nb"))
    r = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, env=env, timeout=300)
    assert r.returncode == 0, r.stderr
    path = Path(json.loads(r.stdout.strip().splitlines()[-1]))
    assert path.is_relative_to(tmp_path / "nb") and path.parts[len((tmp_path / "nb").parts)].startswith("oceangnc-")


def _run_plugin(pkg: Path, out: Path, gain: float) -> None:
    gains = pkg / "mylaw" / "gains.py"
    gains.write_text(
        gains.read_text().replace("return 20.0", f"return {gain}").replace("return 35.0", f"return {gain}")
    )
    env = dict(os.environ, PYTHONPATH=os.pathsep.join([str(pkg), str(SRC), os.environ.get("PYTHONPATH", "")]))
    args = [
        "run",
        "combined-survey",
        "--plugin",
        str(pkg / "mylaw" / "blocks.py"),
        "--set",
        "control.uuv.kind=mylaw.hold",
    ]
    args += ["--duration", "3", "--no-plots", "--verbose", "--out", str(out)]
    r = subprocess.run([sys.executable, "-m", "oceangnc", *args], capture_output=True, text=True, env=env, timeout=600)
    assert r.returncode == 0, r.stderr
    assert "fused compiled loop" in r.stderr + r.stdout  # the fused driver ran (the path that could go stale)
    t = pq.read_table(out / "log.parquet").to_pydict()
    law = [gain * e for e in t["lf.e_x"]]
    assert max(abs(a - b) for a, b in zip(t["uuv.thrust_port_cmd"], law)) == 0.0
    assert max(abs(e) for e in t["lf.e_x"]) > 0.1  # the law was exercised


def test_an_edited_user_law_runs_its_new_version_with_the_same_cache_folder(tmp_path):
    """A user's controller (tests/data/mylaw: its compiled law calls a gain in another file of its
    package) is run, the gain's file edited, run again with the same cache folder: the log shows the
    new law; the edit undone, the old law again (issue 25's stale-cache defect)."""
    pkg = tmp_path / "pkg"
    shutil.copytree(MYLAW, pkg / "mylaw", ignore=shutil.ignore_patterns("__pycache__"))
    _run_plugin(pkg, tmp_path / "r20", 20.0)
    _run_plugin(pkg, tmp_path / "r35", 35.0)
    _run_plugin(pkg, tmp_path / "r20b", 20.0)


def test_the_numba_loading_patch_is_for_this_numba_only(monkeypatch):
    """``lean_loads`` replaces numba's ``Cache.load_overload`` only when its source is the one it was
    written for (saves ~0.3 s of a cached flagship run, benchmarks/RESULTS.md). Any other numba (the
    newest release, checked by ``.ci/run --latest``) runs with numba's own loading: this test holds on
    both, and checks that fallback explicitly by presenting a changed source."""
    from numba.core import caching

    from oceangnc.core import caches

    orig = caching.Cache.load_overload
    same = caches._load_overload_source_hash() == caches.LOAD_OVERLOAD_SOURCE
    with caches.lean_loads():
        assert (caching.Cache.load_overload is caches._lean_load_overload) == same
    assert caching.Cache.load_overload is orig
    # a numba whose load_overload differs from the one the patch was written for: left untouched
    monkeypatch.setattr(caches, "_load_overload_source_hash", lambda: "0000000000000000")
    with caches.lean_loads():
        assert caching.Cache.load_overload is orig
    assert caching.Cache.load_overload is orig
    # and the one it was written for: patched within the block only
    monkeypatch.setattr(caches, "_load_overload_source_hash", lambda: caches.LOAD_OVERLOAD_SOURCE)
    with caches.lean_loads():
        assert caching.Cache.load_overload is caches._lean_load_overload
    assert caching.Cache.load_overload is orig


def test_derived_values_are_computed_once_per_code_key(tmp_path, monkeypatch):
    from oceangnc.core import caches

    monkeypatch.setenv("OCEANGNC_CACHE_DIR", str(tmp_path))
    calls = []

    def compute():
        calls.append(1)
        return [0.1 + 0.2, 1.0 / 3.0]

    a = caches.cached("x", {"speed": 0.6}, compute)
    b = caches.cached("x", {"speed": 0.6}, compute)
    assert a == b == [0.1 + 0.2, 1.0 / 3.0] and len(calls) == 1  # exact floats from the disk
    caches.cached("x", {"speed": 0.7}, compute)
    assert len(calls) == 2  # other inputs: computed
    monkeypatch.setattr(caches, "package_key", lambda: "0123456789abcdef")
    caches.cached("x", {"speed": 0.6}, compute)
    assert len(calls) == 3  # other code: computed


def test_old_key_folders_are_pruned(tmp_path, monkeypatch):
    from oceangnc.core import caches

    monkeypatch.setenv("OCEANGNC_CACHE_DIR", str(tmp_path))
    for i in range(caches.KEEP + 3):
        d = tmp_path / f"steppers-0.1.0-{i:016x}"
        d.mkdir()
        os.utime(d, (1000 + i, 1000 + i))
    caches.prune()
    left = sorted(p.name for p in tmp_path.iterdir())
    assert left == [f"steppers-0.1.0-{i:016x}" for i in range(3, caches.KEEP + 3)]


def test_cli_run_loads_lean_and_gives_the_same_log_as_the_api(tmp_path):
    """``oceangnc run`` loads cached kernels without numba's full refresh (no numba.np.arraymath, no
    SciPy, no pandas in the process) and its log is bit-identical to an API run's."""
    import oceangnc

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


AHEAD = """
import json, os, sys
import numpy as np
sys.path.insert(0, sys.argv[1])
from oceangnc.core import caches
import kern
out = {"outside": caches.compile_ahead([(kern.f, (np.zeros(3), 2))]) is not None}
with caches.ahead_of_time():
    jobs = [(kern.f, (np.zeros(3), 2))] + ([(kern.bad, ("text",))] if sys.argv[2] == "1" else [])
    h = caches.compile_ahead(jobs)
    out["forked"] = h is not None
    out["again"] = caches.compile_ahead([(kern.f, (np.zeros(3), 2))]) is not None
    if h is not None:
        out["names"] = h.names
        h.wait()
out["value"] = float(kern.f(np.ones(3), 2))
out["hits"] = sum(kern.f.stats.cache_hits.values())
out["misses"] = sum(kern.f.stats.cache_misses.values())
print(json.dumps(out))
"""


def test_compile_ahead_compiles_in_a_child_that_this_process_loads_from_and_forks_no_more_once_cached(tmp_path):
    """A first run's child (``caches.compile_ahead``) compiles into numba's disk cache: the parent then
    loads the function instead of compiling it; a job that cannot compile leaves no trace (the child
    prints nothing); a cached function, or a second request, or a call outside ``ahead_of_time``
    forks nothing."""
    (tmp_path / "kern.py").write_text(
        "from numba import njit\n\n\n"
        "@njit(cache=True)\n"
        "def f(x, n):\n"
        "    return x.sum() * n\n\n\n"
        "@njit(cache=True)\n"
        "def bad(s):\n"
        "    return s + 1\n"
    )
    env = _env(PYTHONPATH=str(SRC), OCEANGNC_CACHE_DIR=str(tmp_path / "cache"))
    runs = []
    for bad in ("1", "0"):
        r = subprocess.run(
            [sys.executable, "-c", AHEAD, str(tmp_path), bad], capture_output=True, text=True, env=env, timeout=300
        )
        assert r.returncode == 0 and r.stderr == "", r.stderr
        runs.append(json.loads(r.stdout.strip().splitlines()[-1]))
    first, second = runs
    assert first["forked"] and not first["outside"] and not first["again"]
    assert first["names"] == ["f", "bad"]
    assert first["value"] == 6.0 and first["hits"] == 1 and first["misses"] == 0  # loaded: the child compiled it
    assert not second["forked"] and second["hits"] == 1 and second["misses"] == 0


def test_python_body_runs_a_compiled_function_and_its_compiled_callees_in_python_compiling_nothing():
    """``caches.cheapest``'s first-run form (a build-time call before the compiling child is forked):
    the function's own code and its callees', interpreted; no callee is compiled by the call, and the
    module's globals still name the compiled functions."""
    import numpy as np

    from oceangnc.core import caches

    ns: dict = {}
    exec(
        "from numba import njit\n"
        "@njit\n"
        "def inner(a, b):\n"
        "    return a * b + 1.0\n"
        "@njit\n"
        "def outer(x):\n"
        "    return inner(x[0], x[1]) - inner(x[1], 2.0)\n",
        ns,
    )
    body = caches.python_body(ns["outer"])
    assert body(np.array([3.0, 4.0])) == (3.0 * 4.0 + 1.0) - (4.0 * 2.0 + 1.0)
    assert ns["outer"].signatures == [] and ns["inner"].signatures == []  # nothing compiled
    assert hasattr(ns["inner"], "py_func")  # the module still names the compiled function
    # a closure over a compiled function (a Jacobian closed over its model): the cell's function too
    exec(
        "def make(g):\n"
        "    @njit\n"
        "    def twice(a):\n"
        "        return 2.0 * g(a, a)\n"
        "    return twice\n"
        "closed = make(inner)\n",
        ns,
    )
    assert caches.python_body(ns["closed"])(3.0) == 2.0 * (3.0 * 3.0 + 1.0)
    assert ns["closed"].signatures == [] and ns["inner"].signatures == []
    assert ns["closed"].py_func.__closure__[0].cell_contents is ns["inner"]  # the closure itself unchanged
