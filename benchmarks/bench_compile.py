"""A first run from an empty cache: end to end, and where its compile time goes (issue 25).

    python benchmarks/bench_compile.py [SCENARIO] [--repeat N]

1. ``oceangnc run SCENARIO --duration 40 --quiet --no-plots`` (default ``combined-survey``) from an
   empty cache folder, as shipped (a first run compiles the plant's kernels in a second process,
   ``oceangnc.core.caches.compile_ahead``) and with ``OCEANGNC_COMPILE_AHEAD=0`` (one process),
   alternated, each followed by the cached run in the same folder and by ``python -c "import numpy,
   pandas"`` (the yardstick of issue 25), in the same minutes: wall seconds, CPU seconds (the run's
   processes together) and ratios to the yardstick. Wall time needs a quiet machine (the second
   process needs the second core); the load average is recorded with the figures.
2. The same scenario in one process with an empty cache, listening to numba's ``numba:compile``
   events: each function's exclusive compile time (its own typing and lowering, callees excluded);
   the total and the costliest functions.
"""

from __future__ import annotations

import json
import os
import resource
import statistics
import subprocess
import sys
import tempfile
import time

from record import record

YARDSTICK = [sys.executable, "-c", "import numpy, pandas"]
CAP = 'first run, empty cache (ratio to `python -c "import numpy, pandas"`)'


def timed(cmd, env) -> tuple[float, float]:
    """(wall s, CPU s of the process and the children it waited for) of one command."""
    r0 = resource.getrusage(resource.RUSAGE_CHILDREN)
    t0 = time.perf_counter()
    subprocess.run(cmd, env=env, check=True, stdout=subprocess.DEVNULL)
    w = time.perf_counter() - t0
    r1 = resource.getrusage(resource.RUSAGE_CHILDREN)
    return w, (r1.ru_utime - r0.ru_utime) + (r1.ru_stime - r0.ru_stime)


def end_to_end(name: str, repeat: int) -> None:
    base = {k: v for k, v in os.environ.items() if not k.startswith(("NUMBA_CACHE_DIR", "OCEANGNC_NUMBA"))}
    res: dict[str, list] = {}
    print(f"| `oceangnc run {name} --no-plots` | first run wall s (CPU s) | cached run wall s | yardstick s |")
    print("|---|---|---|---|")
    for _ in range(repeat):
        for label, ahead in (("one process", "0"), ("compiling ahead in a second process", "1")):
            with tempfile.TemporaryDirectory() as tmp:
                env = dict(base, OCEANGNC_CACHE_DIR=os.path.join(tmp, "cache"), OCEANGNC_COMPILE_AHEAD=ahead)
                cmd = [sys.executable, "-m", "oceangnc.cli", "run", name, "--duration", "40", "--quiet"]
                cmd += ["--no-plots", "--out", os.path.join(tmp, "run"), "--overwrite"]
                load0 = os.getloadavg()[0]
                first = timed(cmd, env)
                cached = timed(cmd, env)
                yard = timed(YARDSTICK, env)[0]
                res.setdefault(label, []).append((first, cached[0], yard, load0))
                print(f"| {label} | {first[0]:.1f} ({first[1]:.1f}) | {cached[0]:.2f} | {yard:.2f} |", flush=True)
    for label, rows in res.items():
        w = statistics.median(r[0][0] for r in rows)
        c = statistics.median(r[0][1] for r in rows)
        cw = statistics.median(r[1] for r in rows)
        y = statistics.median(r[2] for r in rows)
        ld = max(r[3] for r in rows)
        note = f"{w:.1f} s wall, {c:.1f} s CPU; yardstick {y:.2f} s; load {ld:.2f}; {len(rows)} run(s)"
        target = "< 12 s on 2 cores (issue 25)" if "ahead" in label else ""
        record(CAP, f"`{name}` first run, {label}: wall", w / y, "x", target, note)
        record(CAP, f"`{name}` first run, {label}: CPU seconds", c, "s", "", note)
        record(CAP, f"`{name}` the run after it (cached), {label}", cw / y, "x", "", f"{cw:.2f} s; yardstick {y:.2f} s")


CHILD = r"""
import json, sys, time
import numpy as np
from numba.core import event as ev
stack, excl = [], {}
class L(ev.Listener):
    def on_start(self, e):
        f = e.data["dispatcher"].py_func
        stack.append([f"{f.__module__}.{f.__qualname__}", time.perf_counter(), 0.0])
    def on_end(self, e):
        name, t0, child = stack.pop()
        d = time.perf_counter() - t0
        excl[name] = excl.get(name, 0.0) + d - child
        if stack:
            stack[-1][2] += d
ev.register("numba:compile", L())
t0 = time.perf_counter()
from oceangnc.api import resolve_config
sc, cfg = resolve_config(sys.argv[1], duration=40)
sim = sc.build(cfg, np.random.default_rng(cfg.sim.seed))
t1 = time.perf_counter()
sim.use_fused = True
sim.run(40.0)
t2 = time.perf_counter()
print(json.dumps({"build": t1 - t0, "run": t2 - t1, "excl": excl}))
"""

if __name__ == "__main__":
    argv = sys.argv[1:]
    repeat = 1
    if "--repeat" in argv:
        i = argv.index("--repeat")
        repeat = int(argv[i + 1])
        del argv[i : i + 2]
    name = argv[0] if argv else "combined-survey"
    end_to_end(name, repeat)
    with tempfile.TemporaryDirectory() as cache:
        env = {k: v for k, v in os.environ.items() if not k.startswith(("NUMBA_CACHE_DIR", "OCEANGNC_NUMBA"))}
        env["OCEANGNC_CACHE_DIR"] = cache
        out = subprocess.run([sys.executable, "-c", CHILD, name], env=env, capture_output=True, text=True, check=True)
    r = json.loads(out.stdout.strip().splitlines()[-1])
    total = sum(r["excl"].values())
    print(
        f"{name}: build {r['build']:.1f} s, run (first tick, compiles, 40 s simulated) {r['run']:.1f} s; "
        f"numba compile {total:.1f} s in {len(r['excl'])} functions"
    )
    record(
        "first run: compile time (empty cache)",
        f"`{name}`: numba compile, all functions",
        total,
        "s",
        "",
        f"build {r['build']:.1f} s + run {r['run']:.1f} s in all; {len(r['excl'])} functions compiled",
    )
    for fn, t in sorted(r["excl"].items(), key=lambda kv: -kv[1])[:8]:
        print(f"{t:6.2f} s  {fn}")
        record("first run: compile time (empty cache)", f"`{name}`: `{fn}` (its own typing and lowering)", t, "s")
