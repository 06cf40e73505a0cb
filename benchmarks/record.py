"""Benchmark figures as data: a benchmark script calls :func:`record` for each headline figure, and
``python benchmarks/run.py`` collects them into ``benchmarks/results.json`` and writes
``benchmarks/RESULTS.md`` (one current table per capability; history lives in git).

Outside ``run.py`` (no ``OCEANGNC_BENCH_RECORD`` in the environment) :func:`record` only prints.
"""

from __future__ import annotations

import json
import os


def record(capability: str, case: str, value: float, unit: str, target: str = "", note: str = "") -> None:
    """One figure: ``capability`` (the table it goes in), ``case`` (its row), ``value`` in ``unit``
    (ratios are written as unit "x"), ``target`` (the issue's, if any), ``note`` (how it was measured)."""
    row = {"capability": capability, "case": case, "value": float(value), "unit": unit, "target": target, "note": note}
    path = os.environ.get("OCEANGNC_BENCH_RECORD")
    if path:
        with open(path, "a") as f:
            f.write(json.dumps(row) + "\n")
    print(f"[record] {capability} | {case}: {value:.4g} {unit}" + (f" (target {target})" if target else ""))
