"""Start-up and end-to-end times of ``oceangnc`` commands in fresh processes (issue 19).

    python benchmarks/bench_startup.py [--cold]

Each command runs in a new Python process, three times (best and median wall time reported).
``--cold`` first empties the generated-module cache (``$OCEANGNC_CACHE_DIR``, a temporary folder
here) to show a first run's cost (numba caches of the package itself stay warm: their cold cost is
the compile time of every model, 15-50 s on this machine). "starts simulating" is the time from
process start to the first tick of the clock, measured inside the process.
"""

import os
import statistics
import subprocess
import sys
import tempfile
import time

PROBE = ("import time, sys; t0 = time.perf_counter()\n"
         "import oceangnc.core.clock as c\n"
         "orig = c.Simulation.run\n"
         "def run(self, *a, **k):\n"
         "    if not getattr(c, '_t', None): c._t = time.perf_counter() - t0; print(f'START {c._t:.3f}', file=sys.stderr)\n"
         "    return orig(self, *a, **k)\n"
         "c.Simulation.run = run\n"
         "from oceangnc.cli import main\n"
         "sys.exit(main(sys.argv[1:]))\n")

COMMANDS = [
    ["list"],
    ["run", "combined-survey", "--duration", "40", "--quiet", "--no-plots"],
    ["run", "combined-survey", "--duration", "40", "--quiet"],
    ["run", "usv-turn", "--quiet", "--no-plots"],
    ["run", "field-test", "--quiet", "--no-plots", "--duration", "30"],
    ["run", "berthing-channel", "--quiet", "--no-plots"],
]


def once(cmd, env, out):
    t0 = time.perf_counter()
    r = subprocess.run([sys.executable, "-c", PROBE, *cmd, *(["--out", out] if cmd[0] == "run" else [])],
                       capture_output=True, text=True, env=env)
    w = time.perf_counter() - t0
    start = [float(line.split()[1]) for line in r.stderr.splitlines() if line.startswith("START")]
    if r.returncode != 0:
        raise SystemExit(r.stderr)
    return w, (start[0] if start else float("nan"))


if __name__ == "__main__":
    cold = "--cold" in sys.argv
    env = dict(os.environ)
    tmp = tempfile.mkdtemp()
    if cold:
        env["OCEANGNC_CACHE_DIR"] = tmp
    print("| command | first run wall s (starts simulating) | later runs wall s: best / median (starts simulating) |")
    print("|---|---|---|")
    for cmd in COMMANDS:
        runs = [once(cmd, env, os.path.join(tmp, "run")) for _ in range(4)]
        later = runs[1:]
        ws = [w for w, _ in later]
        print(f"| `oceangnc {' '.join(cmd)}` | {runs[0][0]:.2f} ({runs[0][1]:.2f}) | {min(ws):.2f} / "
              f"{statistics.median(ws):.2f} ({min(s for _, s in later):.2f}) |", flush=True)
