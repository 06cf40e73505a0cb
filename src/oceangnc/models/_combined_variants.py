"""The combined plant's compiled kernels without the features a plant does not use (issue 25).

The kernels in ``._combined_*`` test each optional feature behind a switch (``SEA``: waves or a heaving
top point; ``BED``: the seabed; ``WINCH``; ``BRIDLE``), True in their modules.
:func:`kernels` gives the group compiled for one plant's features (:class:`oceangnc.core.variants.Variants`):
in calm water without winch, seabed or bridle (the flagship), numba never compiles the wave, contact,
winch and bridle laws, nor links them into the stepper, the output function and the fused driver.
A copy is resolved by name here (``imex_advance__sea0_bed0_winch0_bridle0``), which is how a generated
fused driver imports it.
"""

from __future__ import annotations

import functools
from collections.abc import Mapping

from ..core.variants import Variants
from ._combined_events import track_events
from ._combined_imex import _imex_end_increments, _imex_factor, _imex_solve, imex_advance
from ._combined_kernels import _loads, _loads_sea, bridle_update, cable_state, combined_rhs
from ._combined_layout import _ends, _gather, top_l0
from ._combined_outputs import _fill_outputs, _fill_outputs_var
from ._combined_split import damping_substep, split_advance
from ._combined_winch import _winch_rhs, remesh
from .cable import cable_loads

KERNELS = Variants(
    __name__,
    ("SEA", "BED", "WINCH", "BRIDLE"),
    (
        _ends, _gather, top_l0, cable_loads, _loads, _loads_sea, combined_rhs, cable_state, bridle_update, _imex_factor, _imex_end_increments,
        _imex_solve, imex_advance, damping_substep, split_advance, _fill_outputs, _fill_outputs_var, remesh, _winch_rhs,
        track_events,
    ),
)  # fmt: skip


@functools.cache  # the plant looks its kernels up on every publish (a property: checkpoints hold no dispatcher)
def kernels(sea: bool, bed: bool, winch: bool, bridle: bool) -> Mapping:
    """The kernels by name (``imex_advance``, ``combined_rhs``, ``_fill_outputs``...) for a plant with
    these features: for the plain plant (none of them: the flagship and most scenarios) the copies
    with every switch off, for any other the module functions themselves, which handle every feature.

    Two versions at most, not one per combination of features: a machine running many configurations
    (the test suite, a sweep over sea states) compiles each kernel at most twice; the plain plant, the
    one run most, compiles about a third less (docs/performance.md)."""
    plain = not (sea or bed or winch or bridle)
    return KERNELS.get(SEA=not plain, BED=not plain, WINCH=not plain, BRIDLE=not plain)


def __getattr__(name: str):
    return KERNELS.attribute(name)
