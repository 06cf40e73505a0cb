"""Record the regression baseline of every scenario (``tests/test_baseline.py`` compares against it).

Each scenario of ``oceangnc list`` runs for a short horizon (:data:`DURATION` simulated seconds,
seed 0, no plots); the summary (minus wall time) and three log rows (first, middle, last; every
column) are stored in ``tests/data/baseline.json``. Re-record only when a scenario's numbers change
on purpose (a new default), and say so in the commit::

    python tests/data/record_baseline.py            # every scenario
    python tests/data/record_baseline.py usv-turn   # re-record some
"""

from __future__ import annotations

import json
import math
import sys
import tempfile
import time
from pathlib import Path

HERE = Path(__file__).resolve().parent
BASELINE = HERE / "baseline.json"
DURATION = 3.0  # s of simulated time per scenario
#: scenarios whose run needs a longer horizon to produce a meaningful (non-empty) summary
DURATIONS = {"ekf-zigzag": 20.0, "trials": 3.0, "rov-station-keeping": 35.0, "otter-waypoints": 25.0}
#: summary keys that measure the machine, not the simulation
SKIP_SUMMARY = ("wall_time",)


def _clean(v):
    if isinstance(v, float) and not math.isfinite(v):
        return repr(v)
    return v


def record_one(name: str, out_root: Path) -> dict:
    """Run ``name`` briefly and return ``{"summary": ..., "rows": {"first"|"middle"|"last": {...}}}``."""
    import oceangnc

    res = oceangnc.run(
        name, duration=DURATIONS.get(name, DURATION), overrides={"sim.seed": 0}, out=out_root / name, plots=False
    )
    df = res.df
    summary = {k: _clean(v) for k, v in res.summary.items() if not any(w in k for w in SKIP_SUMMARY)}
    rows = {}
    for label, i in (("first", 0), ("middle", len(df) // 2), ("last", len(df) - 1)):
        rows[label] = {c: _clean(float(df[c].iloc[i])) for c in df.columns}
    return {"duration": DURATIONS.get(name, DURATION), "n_rows": len(df), "summary": summary, "rows": rows}


def main(names: list[str]) -> int:
    import oceangnc

    data = json.loads(BASELINE.read_text()) if BASELINE.exists() and names else {}
    names = names or list(oceangnc.list_scenarios())
    with tempfile.TemporaryDirectory() as tmp:
        for n in names:
            t0 = time.perf_counter()
            data[n] = record_one(n, Path(tmp))
            print(f"{n}: {data[n]['n_rows']} rows, {time.perf_counter() - t0:.1f} s", flush=True)
    BASELINE.write_text(json.dumps(dict(sorted(data.items())), indent=1, sort_keys=True) + "\n")
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
