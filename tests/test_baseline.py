"""Every scenario's summary and log rows are unchanged by refactors (issue 17).

``tests/data/baseline.json`` was recorded by ``tests/data/record_baseline.py`` before the GNC code
moved out of ``scenarios/``; each scenario is re-run for the same short horizon with seed 0 and its
summary and first/middle/last log rows (every column) are compared within :data:`RTOL` relative.
A column set that changed (a signal renamed, added or dropped) fails with the difference listed.
"""

from __future__ import annotations

import importlib.util
import json
import math
from pathlib import Path

import pytest

DATA = Path(__file__).parent / "data"
BASELINE = json.loads((DATA / "baseline.json").read_text())
RTOL = 1e-9
ATOL = 1e-12
#: scenario -> relative tolerance where a merge of duplicate code changed the arithmetic on purpose
LOOSE: dict[str, float] = {}
#: scenario -> log columns added on purpose by the refactor (every recorded column must still match)
ADDED: dict[str, set[str]] = {
    # usv-remote's own GPS block was replaced by the one GPS (sensors/gps.py, white-noise model): same
    # random stream and fixes, and the course/speed over ground every GPS publishes
    "usv-remote": {"gps.cog", "gps.cog_valid", "gps.hdop", "gps.sog"},
}
#: columns added on purpose in every scenario that has the block: usv.pid declares and always writes its
#: yaw-rate setpoint (0 on the autopilot; it was written in the remote mode only)
ADDED_EVERYWHERE = {"usv_ctrl.r_d"}

_spec = importlib.util.spec_from_file_location("record_baseline", DATA / "record_baseline.py")
record_baseline = importlib.util.module_from_spec(_spec)
_spec.loader.exec_module(record_baseline)


def _close(a, b, rtol: float) -> bool:
    if isinstance(a, str) or isinstance(b, str) or isinstance(a, bool) or a is None or b is None:
        return a == b
    if isinstance(a, (int, float)) and isinstance(b, (int, float)):
        if math.isnan(a) and math.isnan(b):
            return True
        return abs(a - b) <= ATOL + rtol * max(abs(a), abs(b))
    return a == b


def _diff(old: dict, new: dict, rtol: float, what: str, added: set[str] = frozenset()) -> list[str]:
    errs = []
    if set(old) - set(added) != set(new) - set(added):  # a re-recorded scenario has the added columns too
        errs.append(f"{what}: keys differ; missing {sorted(set(old) - set(new))}, new {sorted(set(new) - set(old))}")
    for k in sorted(set(old) & set(new)):
        if not _close(old[k], new[k], rtol):
            errs.append(f"{what}[{k}]: baseline {old[k]!r}, now {new[k]!r}")
    return errs


@pytest.mark.parametrize("name", sorted(BASELINE))
def test_scenario_matches_baseline(name, tmp_path, monkeypatch):
    """Same numbers as before the refactor, and every block and plant of the run declares its signals."""
    import oceangnc.core.clock as clock
    from oceangnc.core.signals import check_wiring, undeclared

    seen: list[str] = []

    def checking(parts, external=None):
        parts = list(parts)
        seen.extend(undeclared(parts))
        return check_wiring(parts, external)

    monkeypatch.setattr(clock, "check_wiring", checking)
    old = BASELINE[name]
    new = record_baseline.record_one(name, tmp_path)
    assert not seen, f"{name}: blocks/plants without declared signals: {sorted(set(seen))}"
    rtol = LOOSE.get(name, RTOL)
    errs = []
    if new["n_rows"] != old["n_rows"]:
        errs.append(f"rows: baseline {old['n_rows']}, now {new['n_rows']}")
    errs += _diff(old["summary"], new["summary"], rtol, "summary")
    for label in ("first", "middle", "last"):
        errs += _diff(
            old["rows"][label], new["rows"][label], rtol, f"row {label}", ADDED.get(name, set()) | ADDED_EVERYWHERE
        )
    assert not errs, f"{name} differs from its baseline:\n" + "\n".join(errs[:40])


def test_baseline_covers_every_scenario():
    import oceangnc

    assert sorted(BASELINE) == sorted(oceangnc.list_scenarios())
