"""Start-up and end-to-end times of ``oceangnc`` commands in fresh processes (issue 19).

    python benchmarks/bench_startup.py [--repeat N] [--cold] [--design]

Each command runs in a new Python process, ``N + 1`` times (default N = 3): the first run, then the
best and median of the others. "starts simulating" is the time from process start to the first
tick of the clock, measured inside the process. The caches are those of the environment
(``$OCEANGNC_CACHE_DIR``, default ``~/.cache/oceangnc``: the package's numba caches, the generated
steppers and fused drivers, the derived values).

``--cold`` adds the compile-once table for ``combined-survey``: a copy of the package is "installed"
into a temporary folder (a fresh copy of ``src/oceangnc``: new mtimes, no numba cache files, its
bytecode compiled, as a non-editable ``pip install`` leaves it) with an empty cache folder; then
the first run (everything compiled), the second run, and the run after a *reinstall* (the copy
replaced by a new one, the cache folder kept), without and with plots.

``--design`` measures what each start-up device kept by issue 25 saves on a cached
``oceangnc run --no-plots`` (the flagship): the column table of ``oceangnc.io.frame`` against pandas
(the same run with the scenario's ``frame`` set to pandas), and ``caches.lean_loads`` against numba's
own loading (its source hash made not to match). The issue keeps a device only if it saves more than
150 ms; each is measured in alternated pairs with its alternative, in the same minutes.
"""

import os
import shutil
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

from record import record

SRC = Path(__file__).resolve().parents[1] / "src"
YARDSTICK = [sys.executable, "-c", "import numpy, pandas"]

PROBE = (
    "import time, sys; t0 = time.perf_counter()\n"
    "import oceangnc.cli as cli\n"  # light: the probe must not import numpy before the drawer forks
    "run_cmd = cli._run\n"
    "def _run(*a, **k):\n"
    "    import oceangnc.core.clock as c\n"
    "    orig = c.Simulation.run\n"
    "    def run(self, *a, **k):\n"
    "        if not getattr(c, '_t', None): c._t = time.perf_counter() - t0; print(f'START {c._t:.3f}', file=sys.stderr)\n"
    "        return orig(self, *a, **k)\n"
    "    c.Simulation.run = run\n"
    "    return run_cmd(*a, **k)\n"
    "cli._run = _run\n"
    "sys.exit(cli.main())\n"
)

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
    r = subprocess.run(
        [sys.executable, "-c", PROBE, *cmd, *(["--out", out, "--overwrite"] if cmd[0] == "run" else [])],
        capture_output=True,
        text=True,
        env=env,
    )
    w = time.perf_counter() - t0
    start = [float(line.split()[1]) for line in r.stderr.splitlines() if line.startswith("START")]
    if r.returncode != 0:
        raise SystemExit(r.stderr)
    return w, (start[0] if start else float("nan"))


def yardstick(env) -> float:
    """Wall seconds of ``python -c "import numpy, pandas"`` (the figures' unit: issue 25)."""
    t0 = time.perf_counter()
    subprocess.run(YARDSTICK, env=env, check=True)
    return time.perf_counter() - t0


def load() -> str:
    return "load average " + ", ".join(f"{x:.2f}" for x in os.getloadavg())


def warm_table(env, tmp, repeat):
    print("| command | first run wall s (starts simulating) | later runs wall s: best / median (starts simulating) |")
    print("|---|---|---|")
    for cmd in COMMANDS:
        runs, yard = [once(cmd, env, os.path.join(tmp, "run"))], []
        for _ in range(repeat):  # alternated with the yardstick, so that both see the same machine
            runs.append(once(cmd, env, os.path.join(tmp, "run")))
            yard.append(yardstick(env))
        later = runs[1:]
        ws = [w for w, _ in later]
        if cmd[:2] == ["run", "combined-survey"]:
            plots = "--no-plots" not in cmd
            record(
                'start-up (ratio to `python -c "import numpy, pandas"`)',
                f"cached `oceangnc run combined-survey --duration 40`{'' if plots else ' --no-plots'}, median",
                statistics.median(ws) / statistics.median(yard),
                "x",
                "" if plots else "about 1.5x (issue 25: not slower than before)",
                f"{statistics.median(ws):.2f} s against {statistics.median(yard):.2f} s, {repeat} alternated pairs",
            )
        print(
            f"| `oceangnc {' '.join(cmd)}` | {runs[0][0]:.2f} ({runs[0][1]:.2f}) | {min(ws):.2f} / "
            f"{statistics.median(ws):.2f} ({min(s for _, s in later):.2f}) |",
            flush=True,
        )


def install(site: Path) -> None:
    """What ``pip install`` leaves: a fresh copy of the package with its bytecode compiled."""
    shutil.rmtree(site / "oceangnc", ignore_errors=True)
    shutil.copytree(SRC / "oceangnc", site / "oceangnc", ignore=shutil.ignore_patterns("__pycache__"))
    subprocess.run([sys.executable, "-m", "compileall", "-q", str(site / "oceangnc")], check=True)


def cold_table(tmp, repeat):
    site, cache = Path(tmp) / "site", Path(tmp) / "cache"
    site.mkdir()
    install(site)
    env = dict(os.environ, PYTHONPATH=str(site), OCEANGNC_CACHE_DIR=str(cache))
    env.pop("NUMBA_CACHE_DIR", None)
    base = ["run", "combined-survey", "--duration", "40", "--quiet"]
    rows = []

    def measure(label, cmd, n):
        runs = [once(cmd, env, os.path.join(tmp, "run")) for _ in range(n)]
        ws = [w for w, _ in runs]
        y = statistics.median(yardstick(env) for _ in range(3))
        rows.append((label, min(ws), statistics.median(ws), min(s for _, s in runs)))
        target = "< 12 s on 2 cores (issue 25)" if "first run" in label else ""
        record("start-up, empty cache (`--cold`)", label + ": seconds", statistics.median(ws), "s", target)
        record(
            "start-up, empty cache (`--cold`)",
            label + ": ratio to `import numpy, pandas`",
            statistics.median(ws) / y,
            "x",
            "",
            f"yardstick {y:.2f} s",
        )
        print(f"| {label} | {min(ws):.2f} / {statistics.median(ws):.2f} | {rows[-1][3]:.2f} |", flush=True)

    print("| `oceangnc run combined-survey --duration 40 --quiet` | wall s: best / median | starts simulating (s) |")
    print("|---|---|---|")
    measure("first run, empty cache, `--no-plots` (compiles everything)", [*base, "--no-plots"], 1)
    measure("second run, `--no-plots`", [*base, "--no-plots"], repeat)
    install(site)  # reinstall of the same version: new files, the cache folder kept
    measure("after a reinstall, `--no-plots`", [*base, "--no-plots"], repeat)
    measure("after a reinstall, with the 6 plots", base, repeat)


DESIGN_ALTERNATIVES = {
    "`io.frame` columns instead of pandas": (
        "from oceangnc.scenarios import combined\n"
        "for c in vars(combined).values():\n"
        "    if isinstance(c, type) and getattr(c, 'frame', None) == 'columns': c.frame = 'pandas'\n"
    ),
    "`caches.lean_loads` instead of numba's cache loading": (
        "from oceangnc.core import caches\ncaches.LOAD_OVERLOAD_SOURCE = 'not this numba'\n"
    ),
}


def design_table(env, tmp, repeat):
    """Each kept start-up device against its alternative: median saving (s) over alternated pairs."""
    run = ["run", "--no-plots", "--quiet", "--out", os.path.join(tmp, "d"), "--overwrite"]
    main = "import sys\nfrom oceangnc.cli import main\nsys.exit(main(sys.argv[1:]))\n"

    def wall(prelude):
        t0 = time.perf_counter()
        subprocess.run([sys.executable, "-c", prelude + main, *run], env=env, check=True, capture_output=True)
        return time.perf_counter() - t0

    wall("")  # warm the caches
    print("| device | cached flagship run with it, s (median) | without, s | saving, s |")
    print("|---|---|---|---|")
    for label, prelude in DESIGN_ALTERNATIVES.items():
        with_, without = [], []
        for _ in range(repeat):
            with_.append(wall(""))
            without.append(wall(prelude))
        a, b = statistics.median(with_), statistics.median(without)
        record(
            "start-up devices kept by issue 25 (saving on a cached `oceangnc run --no-plots`)",
            label,
            b - a,
            "s",
            "> 0.15 s to be kept",
            f"{a:.2f} s with it, {b:.2f} s without; ratio {a / b:.2f}; {repeat} alternated pairs",
        )
        print(f"| {label} | {a:.2f} | {b:.2f} | {b - a:.2f} |", flush=True)


if __name__ == "__main__":
    repeat = int(sys.argv[sys.argv.index("--repeat") + 1]) if "--repeat" in sys.argv else 3
    # an installed package has its bytecode compiled; a source tree under PYTHONDONTWRITEBYTECODE=1 (as
    # in the project's sandbox) would compile ~40 modules in every process (~0.1 s): compile them once
    subprocess.run([sys.executable, "-m", "compileall", "-q", str(SRC / "oceangnc")], check=True)
    print(f"{time.strftime('%Y-%m-%d %H:%M:%S UTC', time.gmtime())}, {os.cpu_count()} cores, {load()}")
    with tempfile.TemporaryDirectory() as tmp:
        warm_table(dict(os.environ), tmp, repeat)
        if "--design" in sys.argv:
            print()
            design_table(dict(os.environ), tmp, max(repeat, 5))
        if "--cold" in sys.argv:
            print()
            cold_table(tmp, repeat)
    print(f"end: {time.strftime('%H:%M:%S UTC', time.gmtime())}, {load()}")
