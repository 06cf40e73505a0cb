"""The registry: every published figure the project reproduces and the physical checks (:data:`CASES`).

One module per capability: :mod:`.usv` (003 ch. 2.1), :mod:`.cable` (003 ch. 2.3 and the quasi-static
solution), :mod:`.checks` (physical laws), :mod:`.combined` (003 ch. 4, 6.2), :mod:`.first_order` (000),
:mod:`.berthing` (001), :mod:`.identification` (002). The published values are the numbers the documents
print (quoted in ``published_text``); no figure is copied. Runs are shared between cases through
:class:`oceangnc.validation.Runner` (e.g. one ``combined-survey`` run per controller feeds seven cases), and
horizons are the scenarios' own (the survey ends at its last waypoint, ~40 s).
"""

from __future__ import annotations

from .. import Case
from . import berthing, bluerov2_heavy, cable, checks, combined, first_order, identification, otter_pvs, usv, vehicles
from ._common import D000, D001, D002, D003
from .berthing import CHANNEL_SHORT
from .first_order import TABLE2, TRIALS_SHORT

__all__ = ["CASES", "CHANNEL_SHORT", "D000", "D001", "D002", "D003", "TABLE2", "TRIALS_SHORT"]

CASES: list[Case] = [
    *usv.CASES,
    *vehicles.CASES,
    *otter_pvs.CASES,
    *bluerov2_heavy.CASES,
    *cable.CASES,
    *checks.CASES,
    *combined.CASES,
    *first_order.CASES,
    *berthing.CASES,
    *identification.CASES,
]


def _unique():
    ids = [c.id for c in CASES]
    dup = {i for i in ids if ids.count(i) > 1}
    assert not dup, dup


_unique()
