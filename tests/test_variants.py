"""Compiled functions without the features a configuration does not use (oceangnc.core.variants, issue 25).

A switch is a module constant tested before a runtime flag; a copy of a group of compiled functions with
the switch False never compiles the code behind it. Checked on a small group defined here (what is
compiled, what is computed, the group's closure) and on the combined plant's kernels (the plain
plant's copies name no wave, seabed, winch or bridle law once numba has pruned its branches).
"""

from __future__ import annotations

import numpy as np
import pytest
from numba import njit

from oceangnc.core.variants import Variants

FEAT = True
OTHER = True


@njit
def _extra(a):
    return 100.0 * a


@njit(inline="always")
def _inner(a, on):
    r = a + 1.0
    if FEAT and on:
        r += _extra(a)
    return r


@njit
def _outer(a, on):
    return 2.0 * _inner(a, on)


@njit
def _reads_feat(a):
    return a if FEAT else -a


@njit
def _calls_reader(a):
    return _reads_feat(a)


def test_a_copy_without_the_feature_compiles_none_of_its_code_and_computes_the_rest():
    group = Variants(__name__, ("FEAT",), (_inner, _outer))
    off = group.get(FEAT=False)
    assert off["_outer"].py_func.__name__ == "_outer__feat0"
    assert group.get(FEAT=True)["_outer"] is _outer  # every switch on: the functions as written
    assert off["_outer"](1.5, True) == 2.0 * 2.5  # the runtime flag asks for the feature: switched off
    assert _extra.signatures == []  # not compiled (nor linked) for the copy
    assert "_extra" not in _named_after_pruning(off["_inner"].py_func)
    assert off["_outer"].py_func.__globals__["_inner"] is off["_inner"]  # the copy calls its group's copy
    assert off["_inner"].targetoptions["inline"] == "always"  # the member's compile options kept
    assert _outer(1.5, True) == 2.0 * (2.5 + 150.0) and _outer(1.5, False) == 2.0 * 2.5
    assert group.get(FEAT=False) is off  # made once per process
    assert group.attribute("_outer__feat0") is off["_outer"]
    with pytest.raises(AttributeError):
        group.attribute("_outer__feat2")


def test_the_group_must_be_closed_and_its_switches_set_in_their_modules():
    with pytest.raises(TypeError, match="calls _reads_feat"):
        Variants(__name__, ("FEAT",), (_calls_reader,))
    Variants(__name__, ("FEAT",), (_calls_reader, _reads_feat))  # closed: accepted
    with pytest.raises(TypeError, match="switch NOPE"):
        Variants(__name__, ("NOPE",), (_reads_nope,))
    with pytest.raises(TypeError, match="exactly the switches"):
        Variants(__name__, ("FEAT", "OTHER"), (_inner,)).get(FEAT=False)


@njit
def _reads_nope(a):
    return a if NOPE else -a  # noqa: F821  (a switch its module does not define)


def _named_after_pruning(fn) -> set[str]:
    """The global names a function's code refers to once numba's dead-branch pruning has run."""
    from numba.core import ir, types
    from numba.core.analysis import dead_branch_prune
    from numba.core.compiler import run_frontend

    f_ir = run_frontend(fn)
    dead_branch_prune(f_ir, called_args=[types.float64] * fn.__code__.co_argcount)
    return {
        inst.value.name
        for blk in f_ir.blocks.values()
        for inst in blk.find_insts(ir.Assign)
        if isinstance(inst.value, (ir.Global, ir.FreeVar))
    }


def test_the_plain_combined_plant_compiles_no_wave_seabed_winch_or_bridle_law():
    from oceangnc.models import _combined_imex as imex
    from oceangnc.models import _combined_kernels as ck
    from oceangnc.models._combined_variants import kernels

    plain = kernels(False, False, False, False)
    features = {"_loads_sea", "bridle_update", "_contact", "wf_rhs", "uuv_deriv_flow", "_winch_rhs", "remesh"}
    full_names = _named_after_pruning(ck.combined_rhs.py_func)
    assert features - {"remesh"} <= full_names  # the law as written reaches them all
    assert not (features & _named_after_pruning(plain["combined_rhs"].py_func))
    assert "remesh" in _named_after_pruning(imex.imex_advance.py_func)
    adv = _named_after_pruning(plain["imex_advance"].py_func)
    assert "remesh" not in adv and "combined_rhs" in adv
    assert plain["imex_advance"].py_func.__globals__["combined_rhs"] is plain["combined_rhs"]
    # any feature: the functions as written (two versions of each kernel at most on a machine)
    assert kernels(True, False, False, False)["combined_rhs"] is ck.combined_rhs
    assert kernels(False, False, True, False)["combined_rhs"] is ck.combined_rhs


def test_plants_use_their_kernels_and_the_fused_driver_imports_them_by_name():
    from oceangnc.core.fused import _kernel_ref
    from oceangnc.models.cable import CableConfig
    from oceangnc.models.combined import CombinedPlant
    from oceangnc.models.usv import USVConfig
    from oceangnc.models.uuv import UUVConfig

    plant = CombinedPlant(USVConfig(), UUVConfig(), CableConfig(), integrator="imex")
    assert plant._advance.py_func.__name__ == "imex_advance__sea0_bed0_winch0_bridle0"
    assert plant.rhs is plant._kernels["combined_rhs"]
    mod, name = _kernel_ref(plant._advance)
    import importlib

    assert getattr(importlib.import_module(mod), name) is plant._advance
    x0 = plant.x.copy()
    plant.advance(0.0, 0.01, 3)  # the copy runs and moves the state
    assert np.all(np.isfinite(plant.x)) and not np.array_equal(plant.x, x0)
