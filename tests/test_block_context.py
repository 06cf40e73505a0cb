"""Blocks take only their own parameters and declared inputs (issue 42): no block reads its scenario's
config or scenario facts. Every registered kind with a ``from_context`` is built through
``build_block`` with a context that offers nothing but the period and the wiring, and the source of
every block constructor is scanned for ``ctx.cfg`` / ``ctx.info``."""

from __future__ import annotations

import ast
import dataclasses
import math
from pathlib import Path

import pytest

import oceangnc
from oceangnc.core.registry import _KINDS, BlockChoice, BlockContext, build_block, kinds
from oceangnc.errors import ConfigError
from oceangnc.models.usv import USVConfig
from oceangnc.models.uuv import UUVConfig

ROOTS = [Path(oceangnc.__file__).parent, Path(__file__).parents[1] / "examples"]


class _OnlyOwn(BlockContext):
    """A context any read of a scenario's config or facts fails on, whatever a future field is called."""

    def __getattr__(self, name):  # reached only for attributes the context does not have
        raise AssertionError(f"a block read ctx.{name}: take it as a parameter or a declared input")


def _given():
    """What a scenario may offer its controllers, with values unlike the defaults (to see them used)."""
    usv = USVConfig().model_copy(update={"max_thrust_kgf": 7.0, "d11": 12.5})
    geometry = {"l_d": 2.5, "lambda_d": math.radians(150.0), "mode": "relative-angle"}
    return {"usv": usv, "uuv": UUVConfig(), "u_d": 0.9, **geometry}


def _built_in_context_kinds():
    kinds()  # the built-in blocks and the entry points
    return sorted(k for k, c in _KINDS.items() if hasattr(c, "from_context") and c.__module__.startswith("oceangnc."))


def _choice(kind: str, **params) -> BlockChoice:
    return BlockChoice.model_validate({"kind": kind, **params})


def test_the_context_offers_only_the_period_and_the_wiring():
    assert {f.name for f in dataclasses.fields(BlockContext)} == {"period", "signals"}


@pytest.mark.parametrize("kind", _built_in_context_kinds())
def test_every_built_in_kind_builds_from_its_parameters_alone(kind):
    ctx = _OnlyOwn(period=0.05, signals={"usv.psi": "usv_ahrs.psi", "uuv.psi": "uuv_ahrs.psi"})
    block = build_block(_choice(kind), ctx, "control.x", given=_given())
    assert block.period == pytest.approx(0.05)
    assert "usv_ahrs.psi" in block.inputs or "uuv_ahrs.psi" in block.inputs  # the wiring reached it


def test_the_given_values_reach_the_law():
    ctx = BlockContext(period=0.05)
    usv = build_block(_choice("usv.pid"), ctx, "control.usv", given=_given())
    assert usv.u_d == pytest.approx(0.9)
    assert usv.t_max == pytest.approx(7.0 * 9.80665)
    assert usv.d11 == pytest.approx(12.5)
    bs = build_block(_choice("uuv.backstepping"), ctx, "control.uuv", given=_given())
    assert bs.cx == pytest.approx(2.5 * math.cos(math.radians(150.0)) + bs.cfg.h)
    assert bs.cy == pytest.approx(2.5 * math.sin(math.radians(150.0)))
    pid = build_block(_choice("uuv.pid"), ctx, "control.uuv", given=_given())
    assert pid.mode == "relative-angle"


def test_a_slot_may_not_set_what_its_scenario_gives():
    with pytest.raises(ConfigError, match=r"control\.usv\.u_d is set by the scenario"):
        build_block(_choice("usv.pid", u_d=2.0), BlockContext(period=0.05), "control.usv", given=_given())


def test_a_block_missing_what_it_takes_names_it():
    with pytest.raises(ConfigError, match=r"control\.uuv\.(uuv|l_d|lambda_d)"):
        build_block(_choice("uuv.backstepping"), BlockContext(period=0.05), "control.uuv", given={"mode": "x"})


def _reads_of_context(path: Path):
    """``ctx.cfg`` / ``ctx.info`` (or ``getattr(ctx, "cfg")``) in any function taking a ``ctx``."""
    tree = ast.parse(path.read_text(encoding="utf-8"))
    for fn in ast.walk(tree):
        if not isinstance(fn, ast.FunctionDef) or "ctx" not in [a.arg for a in fn.args.args]:
            continue
        for node in ast.walk(fn):
            if isinstance(node, ast.Attribute) and isinstance(node.value, ast.Name) and node.value.id == "ctx":
                if node.attr in ("cfg", "info"):
                    yield f"{path.name}:{node.lineno} {fn.name} reads ctx.{node.attr}"
            if isinstance(node, ast.Call) and getattr(node.func, "id", None) == "getattr" and len(node.args) >= 2:
                obj, name = node.args[0], node.args[1]
                if getattr(obj, "id", None) == "ctx" and getattr(name, "value", None) in ("cfg", "info"):
                    yield f"{path.name}:{node.lineno} {fn.name} reads getattr(ctx, {name.value!r})"


def _block_sources():
    """Modules defining blocks (a ``register_block`` or a ``from_context``); scenarios' run contexts excluded."""
    for root in ROOTS:
        for p in sorted(root.rglob("*.py")):
            text = p.read_text(encoding="utf-8")
            if "register_block(" in text or "from_context" in text:
                yield p


def test_no_block_constructor_reads_the_scenarios_config_or_facts():
    sources = list(_block_sources())
    assert len(sources) > 10  # the scan sees the package's blocks
    found = [hit for p in sources for hit in _reads_of_context(p)]
    assert not found, found


def test_the_scan_catches_a_read(tmp_path):
    p = tmp_path / "bad.py"
    p.write_text("class B:\n    @classmethod\n    def from_context(cls, params, ctx):\n        return ctx.info['x']\n")
    assert list(_reads_of_context(p)) == ["bad.py:4 from_context reads ctx.info"]
