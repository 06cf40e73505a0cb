"""Run benchmark scripts and write ``benchmarks/RESULTS.md`` from their recorded figures (issue 25).

    python benchmarks/run.py [NAME ...] [--list] [--markdown]

NAME is a benchmark of :data:`BENCHMARKS` (default: all). Each runs as its own process with its
arguments; the figures it records (:func:`record.record`) replace those of the same capability and
case in ``benchmarks/results.json``, each stamped with the date, the machine and the load average
at its start and end. ``RESULTS.md`` is then written from ``results.json``: one table per
capability, newest figures only. Take figures on a quiet machine (load average under 1).
"""

from __future__ import annotations

import json
import os
import platform
import subprocess
import sys
import tempfile
import time
from pathlib import Path

HERE = Path(__file__).resolve().parent
RESULTS = HERE / "results.json"

#: name -> (script, arguments, environment): what each benchmark runs
BENCHMARKS = {
    "startup": ("bench_startup.py", ["--repeat", "5", "--cold", "--design"], {}),
    "fused": (
        "bench_combined.py",
        ["combined-survey", "usv-turn", "field-test", "berthing-channel"],
        {"NUMBA_NUM_THREADS": "1"},
    ),
    "vehicles": ("bench_combined.py", ["rov-station-keeping", "otter-waypoints"], {"NUMBA_NUM_THREADS": "1"}),
    "usv": ("bench_usv.py", ["--duration", "300", "--repeat", "3"], {}),
    "rl": ("bench_rl.py", ["--steps", "20000", "--repeat", "3"], {"NUMBA_NUM_THREADS": "1"}),
    "ekf": ("bench_ekf.py", ["--seeds", "10"], {"NUMBA_NUM_THREADS": "1"}),
    "berthing": ("bench_berthing.py", [], {}),
    "tow": ("bench_tow.py", [], {}),
    "sea": ("bench_sea.py", [], {"NUMBA_NUM_THREADS": "1"}),
    "sea-sweep": ("bench_sea.py", ["--sweep"], {"NUMBA_NUM_THREADS": "1"}),
    "cable": ("bench_cable.py", [], {"NUMBA_NUM_THREADS": "1"}),
    "compile": ("bench_compile.py", ["combined-survey", "--repeat", "3"], {}),
    "batch": ("bench_batch.py", ["1000", "40"], {}),
    "console-soak": ("bench_console_soak.py", ["--seconds", "60", "--viewers", "20"], {}),
    "view": ("bench_view.py", ["--duration", "600", "--seconds", "10", "--repeat", "3"], {}),
    "view-waves": ("bench_view.py", ["--duration", "600", "--seconds", "10", "--repeat", "3", "--waves"], {}),
}


def machine() -> str:
    cpu = platform.processor() or platform.machine()
    try:
        for line in Path("/proc/cpuinfo").read_text().splitlines():
            if line.startswith("model name"):
                cpu = line.split(":", 1)[1].strip()
                break
    except OSError:
        pass
    return f"{cpu}, {os.cpu_count()} cores, Python {platform.python_version()}"


def load() -> float:
    return os.getloadavg()[0]


def run(names: list[str]) -> list[dict]:
    rows: list[dict] = []
    for name in names:
        script, args, env = BENCHMARKS[name]
        with tempfile.NamedTemporaryFile("r", suffix=".jsonl") as rec:
            e = dict(os.environ, OCEANGNC_BENCH_RECORD=rec.name, **env)
            e["PYTHONPATH"] = os.pathsep.join([str(HERE.parent / "src"), str(HERE), e.get("PYTHONPATH", "")])
            l0, t0 = load(), time.strftime("%Y-%m-%d %H:%M UTC", time.gmtime())
            print(f"== {name}: {script} {' '.join(args)} (load {l0:.2f})", flush=True)
            subprocess.run([sys.executable, str(HERE / script), *args], env=e, check=True)
            stamp = {
                "benchmark": name,
                "command": f"python benchmarks/{script} {' '.join(args)}".strip(),
                "date": t0,
                "machine": machine(),
                "load": f"{l0:.2f}-{load():.2f}",
            }
            rows += [{**json.loads(line), **stamp} for line in rec.read().splitlines() if line.strip()]
    return rows


def merge(new: list[dict]) -> list[dict]:
    old = json.loads(RESULTS.read_text()) if RESULTS.exists() else []
    keys = {(r["capability"], r["case"]) for r in new}
    return [r for r in old if (r["capability"], r["case"]) not in keys] + new


def write_markdown(rows: list[dict]) -> str:
    out = [
        "# Benchmark results",
        "",
        "Written by `python benchmarks/run.py` from `benchmarks/results.json` (the figures each benchmark",
        "script records); each table holds the newest figure of each case, with the date, the machine and",
        "the load average (start-end) of its run. History: `git log -p benchmarks/results.json`.",
        "",
    ]
    for cap in sorted({r["capability"] for r in rows}):
        group = [r for r in rows if r["capability"] == cap]
        out += [f"## {cap}", "", "| case | value | target | measured | note |", "|---|---|---|---|---|"]
        for r in group:
            num = f"{r['value']:.0f}" if abs(r["value"]) >= 100 else f"{r['value']:.3g}"
            v = f"{num} {r['unit']}".replace(" x", "x")
            when = f"{r['date']}, load {r['load']}"
            out.append(f"| {r['case']} | **{v}** | {r['target']} | {when} | {r['note']} |")
        cmds = sorted({r["command"] for r in group})
        machines = sorted({r["machine"] for r in group})
        out += ["", "Command: " + "; ".join(f"`{c}`" for c in cmds) + ". Machine: " + "; ".join(machines) + ".", ""]
    return "\n".join(out)


def main(argv: list[str]) -> int:
    if "--markdown" in argv:  # only rewrite RESULTS.md from results.json
        (HERE / "RESULTS.md").write_text(write_markdown(json.loads(RESULTS.read_text())))
        return 0
    if "--list" in argv:
        for k, (s, a, _) in BENCHMARKS.items():
            print(f"{k:10s} {s} {' '.join(a)}")
        return 0
    names = [a for a in argv if not a.startswith("-")] or list(BENCHMARKS)
    unknown = [n for n in names if n not in BENCHMARKS]
    if unknown:
        print(f"error: unknown benchmark(s) {unknown}; known: {', '.join(BENCHMARKS)}", file=sys.stderr)
        return 2
    rows = merge(run(names))
    RESULTS.write_text(json.dumps(rows, indent=1) + "\n")
    (HERE / "RESULTS.md").write_text(write_markdown(rows))
    print(f"wrote {RESULTS} and {HERE / 'RESULTS.md'}")
    return 0


if __name__ == "__main__":
    raise SystemExit(main(sys.argv[1:]))
