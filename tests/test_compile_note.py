"""Issue 41: a first run says what it is compiling instead of a progress bar standing at 0 % for 24-110 s."""

from __future__ import annotations

import importlib.util
import io
import sys
from types import SimpleNamespace

from tqdm import tqdm

from oceangnc.core import compile_note


def _bar():
    return tqdm(total=10.0, desc="compiling", file=io.StringIO(), mininterval=0)


def test_the_driver_is_named_until_numba_has_cached_it(tmp_path):
    src = tmp_path / "gen_driver_mod.py"
    src.write_text("from numba import njit\n\n\n@njit(cache=True)\ndef drive(x):\n    return x + 1.0\n")
    spec = importlib.util.spec_from_file_location("gen_driver_mod", src)
    mod = importlib.util.module_from_spec(spec)
    sys.modules["gen_driver_mod"] = mod
    spec.loader.exec_module(mod)
    sim = SimpleNamespace(blocks=[object(), object()], plants=[object()])
    bar = _bar()
    compile_note.driver_note(bar, sim, SimpleNamespace(drive=mod.drive))
    assert bar.desc == "compiling the closed loop (2 blocks, 1 plant(s)) into one driver (first run, cached afterwards)"
    assert "%" not in bar.__str__()  # no empty bar while nothing is simulated
    assert compile_note.done(bar) and bar.desc == "" and "%" in bar.__str__()
    assert mod.drive(1.0) == 2.0  # compiled and saved in numba's disk cache
    bar = _bar()
    compile_note.driver_note(bar, sim, SimpleNamespace(drive=mod.drive))
    assert bar.desc == "compiling"  # a cached run never claims to compile


def test_the_functions_compiled_ahead_are_named():
    bar = _bar()
    children = [SimpleNamespace(names=["usv_rhs", "rk4_stepper.<locals>.advance", "cable_rhs", "uuv_rhs"])]
    compile_note.ahead_note(bar, children)
    assert bar.desc.startswith("compiling usv_rhs, rk4_stepper.<locals>.advance, cable_rhs and 1 more (first run")
    bar = _bar()
    compile_note.ahead_note(bar, [])
    assert bar.desc == "compiling"
