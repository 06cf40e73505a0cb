"""Where a first run's time goes: numba compile time per function, empty cache (issue 25).

    python benchmarks/bench_compile.py [SCENARIO]

Runs the scenario (default ``combined-survey``, 40 s, fused) in a fresh process with an empty cache
folder and listens to numba's ``numba:compile`` events: each function's exclusive compile time (its
own typing and lowering, callees excluded). Records the total and the costliest functions.
"""

from __future__ import annotations

import json
import os
import subprocess
import sys
import tempfile

from record import record

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
    name = sys.argv[1] if len(sys.argv) > 1 else "combined-survey"
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
