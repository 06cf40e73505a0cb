"""One law per block (issue 25): every registered block kind writes its arithmetic once, as a compiled
law in its own module that its Python step and its fused form both call (oceangnc.core.law)."""

from __future__ import annotations

import numpy as np
import pytest

from oceangnc.api import resolve_config
from oceangnc.core.law import LawBlock
from oceangnc.core.registry import _KINDS, kinds

#: kinds not yet moved onto LawBlock, each with the reason; the list may only shrink (the test
#: below fails when a kind listed here has become a LawBlock, or a kind is missing from both)
PENDING: dict[str, str] = {}


def _law_kinds():
    kinds()  # loads the built-in blocks and the entry points
    return sorted(_KINDS)


@pytest.mark.parametrize("kind", _law_kinds())
def test_every_kind_has_one_law_in_its_own_module_or_a_stated_reason(kind):
    cls = _KINDS[kind]
    if kind in PENDING:
        assert not issubclass(cls, LawBlock), f"{kind} is a LawBlock now: remove it from PENDING"
        return
    reason = getattr(cls, "no_fused_reason", None)
    if reason is not None:
        assert isinstance(reason, str) and len(reason) > 20, f"{kind}: a reason in words"
        assert getattr(cls, "compiled", None) is None, f"{kind} states no fused form but has one"
        return
    assert issubclass(cls, LawBlock), f"{kind} ({cls.__module__}) has neither a law nor a stated reason"
    owner = next(c for c in cls.__mro__ if "law" in c.__dict__)  # the class that names the law
    law = owner.__dict__["law"]
    fn = law.__func__ if isinstance(law, staticmethod) else law
    assert hasattr(fn, "py_func"), f"{kind}: the law is a compiled (numba) function"
    assert fn.py_func.__module__ == owner.__module__, f"{kind}: the law lives in its block's own module"
    own = [c for c in cls.__mro__ if not c.__module__.startswith("oceangnc.core")]  # the block's classes
    assert all("compiled" not in c.__dict__ for c in own), f"{kind}: the fused form is LawBlock's (the same law)"
    assert all("step" not in c.__dict__ for c in own), f"{kind}: the Python step is LawBlock's (the same law)"


#: scenarios whose blocks, built, cover the fused kinds (sensors on in field-test)
SCENARIOS = [
    ("combined-survey", {}),
    ("combined-survey", {"control.uuv.kind": "pid"}),
    ("field-test", {}),
    ("berthing-dock", {"control.mode": "nonlinear"}),
    ("usv-turn", {}),
    ("tow-deploy", {}),
    ("combined-survey", {"winch.enabled": True}),  # ArduSub's depth reference + the winch (oceangnc.control.ardusub)
    ("rov-station-keeping", {"control.pilot": "ardusub"}),  # the ROV's ArduSub pilot
]


@pytest.mark.parametrize("name,over", SCENARIOS, ids=[f"{n}-{'-'.join(map(str, o.values()))}" for n, o in SCENARIOS])
def test_the_python_step_and_the_fused_form_call_the_same_law(name, over, monkeypatch):
    """Built blocks: the fused form's kernel *is* the class's law, and the Python step calls it (a spy
    standing in for the law sees the call and passes it on)."""
    sc, cfg = resolve_config(name, overrides=over)
    sim = sc.build(cfg, np.random.default_rng(cfg.sim.seed))
    sim.run(0.0)  # first tick: every block has fired once and the bus holds its signals
    laws = [b for b in sim.blocks if isinstance(b, LawBlock)]
    assert laws or name != "field-test", "field-test has law blocks (the depth sensor at least)"
    for b in laws:
        law = type(b).law
        assert b.compiled().kernel is law
        calls = []

        def spy(*args, _law=law, _calls=calls):
            _calls.append(1)
            return _law(*args)

        monkeypatch.setattr(type(b), "law", staticmethod(spy))
        b.step(sim.t, sim.bus)
        monkeypatch.undo()
        assert calls == [1], f"{b.name}: the Python step calls the law once"
