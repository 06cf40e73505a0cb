"""Validation cases: every published figure the project reproduces and the physical checks, with tolerances.

A :class:`Case` names its source (seed document file name and figure / table / equation, or the
physical law), the quantity, the published or analytic value, the tolerance and why it is that
tolerance. Its ``measure(runner)`` returns a :class:`Measured`: the project's value, the curve the
report plots beside the published value, and (for analytic references computed at run time) the
reference itself. :data:`oceangnc.validation.cases.CASES` is the registry; ``oceangnc validate``
(:mod:`oceangnc.validation.cli`) runs it and writes the report, and ``tests/test_validation.py`` is
parametrised over the same list, so a case cannot pass in the report and be untested.

A case may carry ``deviation``: the text of a documented disagreement with the source that the
physics of the project does not remove (the flagship depth of 003 ch. 4, see
docs/combined-vehicle.md). Such a case is evaluated like any other; its failure is reported as
"deviation" and does not fail the run, and if it starts passing the report says so (the test then
fails, strict, so that the documentation is updated).
"""

from __future__ import annotations

import fnmatch
import json
import math
import tempfile
import time
from collections.abc import Callable, Sequence
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from ..errors import ConfigError, InputError

__all__ = ["Case", "Measured", "Outcome", "Runner", "evaluate", "run_cases", "select"]


@dataclass
class Measured:
    """What a case measured.

    Attributes
    ----------
    value : float
        The project's value of the quantity (SI or the unit the case states).
    series : list of (label, x, y)
        Project curves for the plot (e.g. the time history the value is read from).
    ref_points : list of (label, x, y)
        Published points for the plot (printed numbers or digitised points, label gives the source).
    published : float, optional
        Reference value computed at run time (analytic cases); overrides ``Case.published``.
    xlabel, ylabel : str
        Plot axes; the published value and its tolerance band are drawn on the y axis when
        ``band`` is True.
    note : str
        One line shown in the report under the case (e.g. the companion numbers).
    """

    value: float
    series: list = field(default_factory=list)
    ref_points: list = field(default_factory=list)
    published: float | None = None
    xlabel: str = ""
    ylabel: str = ""
    band: bool = True
    note: str = ""


@dataclass
class Case:
    """One validation case (see the module docstring).

    ``check`` is ``("abs", tol)``, ``("rel", tol)``, ``("max", limit)``, ``("min", limit)`` or
    ``("range", lo, hi)``; for ``abs``/``rel`` the published value is the centre.
    """

    id: str
    title: str
    source: str
    quantity: str
    unit: str
    published: float | None
    published_text: str
    check: tuple
    why: str
    measure: Callable[[Runner], Measured]
    deviation: str = ""
    group: str = ""

    def bounds(self, published: float | None) -> tuple[float, float]:
        kind = self.check[0]
        if kind == "abs":
            return published - self.check[1], published + self.check[1]
        if kind == "rel":
            return published - abs(published) * self.check[1], published + abs(published) * self.check[1]
        if kind == "max":
            return -math.inf, self.check[1]
        if kind == "min":
            return self.check[1], math.inf
        if kind == "range":
            return self.check[1], self.check[2]
        raise ValueError(f"case {self.id}: unknown check {kind!r}")

    def tolerance_text(self) -> str:
        kind, c = self.check[0], self.check
        if kind == "abs":
            return f"± {c[1]:g} {self.unit}"
        if kind == "rel":
            return f"± {100 * c[1]:g} %"
        if kind == "max":
            return f"≤ {c[1]:g} {self.unit}"
        if kind == "min":
            return f"≥ {c[1]:g} {self.unit}"
        return f"{c[1]:g} … {c[2]:g} {self.unit}"


@dataclass
class Outcome:
    """A case's result: ``status`` is "pass", "fail", "deviation" (documented, expected) or "error"."""

    case: Case
    measured: Measured | None
    published: float | None
    lo: float
    hi: float
    passed: bool
    status: str
    wall_s: float
    error: str = ""

    def row(self) -> dict:
        m = self.measured
        return {
            "id": self.case.id,
            "status": self.status,
            "value": None if m is None else m.value,
            "published": self.published,
            "lo": self.lo,
            "hi": self.hi,
            "wall_s": self.wall_s,
            "error": self.error,
        }


def evaluate(case: Case, m: Measured) -> tuple[bool, float | None, float, float]:
    pub = m.published if m.published is not None else case.published
    lo, hi = case.bounds(pub)
    ok = bool(np.isfinite(m.value)) and lo <= m.value <= hi
    return ok, pub, lo, hi


class Runner:
    """Runs scenarios once per distinct (scenario, overrides) and shares the result between cases.

    ``overrides`` (dotted keys, as ``--set``) are applied to every scenario whose config has the
    key's top-level section (``usv.d11`` reaches ``usv-turn`` and ``combined-survey`` but not
    ``ekf-zigzag``), and to the model configs the physical checks build (:meth:`section`).
    """

    def __init__(self, overrides: dict | None = None, workdir: str | Path | None = None):
        self.overrides = dict(overrides or {})
        self._cache: dict[str, tuple[dict, object]] = {}
        self._tmp = tempfile.TemporaryDirectory(prefix="oceangnc-validate-") if workdir is None else None
        self.workdir = Path(workdir) if workdir is not None else Path(self._tmp.name)
        self.used: set[str] = set()

    def _applicable(self, scenario: str) -> dict:
        from ..scenarios.base import get_scenario

        fields = get_scenario(scenario).Config.model_fields
        out = {}
        for k, v in self.overrides.items():
            if k.split(".")[0] in fields:
                out[k] = v
                self.used.add(k)
        return out

    def run(self, scenario: str, **overrides):
        """(summary, df) of the scenario with the case's overrides and the applicable global ones."""
        from ..api import run

        over = {**overrides, **self._applicable(scenario)}
        key = scenario + json.dumps(over, sort_keys=True, default=str)
        if key not in self._cache:
            out = self.workdir / f"run{len(self._cache)}"
            res = run(scenario, overrides=over, out=out, plots=False)
            self._cache[key] = (res.summary, res.df)
        return self._cache[key]

    def section(self, name: str) -> dict:
        """Global overrides for one model config section, e.g. ``{"d11": 100.0}`` for ``usv``."""
        out = {}
        for k, v in self.overrides.items():
            head, _, rest = k.partition(".")
            if head == name and rest and "." not in rest:
                out[rest] = v
                self.used.add(k)
        return out

    def close(self):
        if self._tmp is not None:
            self._tmp.cleanup()


def select(cases: Sequence[Case], pattern: str | None) -> list[Case]:
    """Cases whose id, title or source matches the glob/substring ``pattern`` (case-insensitive)."""
    if not pattern:
        return list(cases)
    pats = [p.strip().lower() for p in pattern.split(",") if p.strip()]
    out = []
    for c in cases:
        hay = [c.id.lower(), c.title.lower(), c.source.lower(), c.group.lower()]
        if any(fnmatch.fnmatch(h, p) or (p in h) for p in pats for h in hay):
            out.append(c)
    if not out:
        raise InputError(f"--only {pattern!r} matches no validation case (see 'oceangnc validate --list')")
    return out


def run_case(case: Case, runner: Runner) -> Outcome:
    t0 = time.perf_counter()
    try:
        m = case.measure(runner)
    except (ConfigError, InputError):
        raise
    except Exception as e:  # a case that crashes is reported, not hidden
        return Outcome(
            case,
            None,
            case.published,
            math.nan,
            math.nan,
            False,
            "error",
            time.perf_counter() - t0,
            f"{type(e).__name__}: {e}",
        )
    ok, pub, lo, hi = evaluate(case, m)
    if ok:
        status = "pass"
    else:
        status = "deviation" if case.deviation else "fail"
    return Outcome(case, m, pub, lo, hi, ok, status, time.perf_counter() - t0)


def run_cases(
    cases: Sequence[Case], runner: Runner | None = None, progress: Callable[[int, int, Outcome], None] | None = None
) -> list[Outcome]:
    """Run the cases in order (runs shared through ``runner``); ``progress(i, n, outcome)`` after each."""
    own = runner is None
    runner = runner or Runner()
    out = []
    try:
        for i, c in enumerate(cases):
            o = run_case(c, runner)
            out.append(o)
            if progress:
                progress(i + 1, len(cases), o)
    finally:
        if own:
            runner.close()
    return out
