"""Scenarios: a named, configurable, runnable experiment.

A scenario is a small object with

* ``name`` and ``summary`` (one line for ``oceangnc list``),
* ``Config``: its pydantic config model (a :class:`~oceangnc.io.config.ScenarioConfig` subclass),
* ``defaults``: a nested dict of overrides on top of the model's defaults (e.g. the duration),
* ``run(cfg, ctx) -> dict``: runs it, writing log rows through ``ctx.log``; returns the metrics
  known only while running (often ``{}``),
* ``summarize(df, cfg) -> dict``: the flat summary metrics (SI units, keys as the issues list them)
  computed from the finished log, so a summary can always be recomputed from a log,
* ``plot(df, cfg, out_dir) -> list[Path]``: draws PNG plots from the log (used by ``run`` and ``plot``).

Scenario modules live in :mod:`oceangnc.scenarios`; each defines a module-level list ``SCENARIOS``,
and the registry collects them all, so adding a scenario is adding one module.

The registry is lazy: :data:`SCENARIO_INDEX` maps each shipped scenario's name to its module and its
one-line summary, so ``oceangnc list`` imports no scenario module and ``oceangnc run X`` imports only
X's module (importing them all costs about a second). A module of this package missing from the
index is still found (it is imported when a name is not in the index, and by ``list``); a test
checks that the index matches what the modules define.
"""

from __future__ import annotations

import functools
import importlib
from collections.abc import Callable
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np

from ..errors import InputError
from ..io.config import ScenarioConfig
from ..io.logs import LogWriter
from ..scenario_index import (  # noqa: F401  (re-exported)
    LIGHT_PLOTS,
    SCENARIO_INDEX,
    light_plots,
    scenario_modules,
    unindexed_modules,
)


@dataclass
class RunContext:
    """What a running scenario gets: its output folder, log writer, random generator and flags."""

    out_dir: Path
    log: LogWriter
    rng: np.random.Generator
    progress: bool = False
    info: dict[str, Any] = field(default_factory=dict)
    #: :class:`oceangnc.core.checkpoint.Checkpointer` when the run saves checkpoints or resumes
    checkpointer: Any = None
    verbose: bool = False
    fused: bool = True  # run the compiled fused loop when every block has a compiled form

    def simulate(self, sim, duration: float) -> float:
        """Run a :class:`~oceangnc.core.clock.Simulation` for ``duration`` s into this run's log
        (with checkpoints, or from a restored checkpoint, when the run asks for them)."""
        if self.checkpointer is not None and self.checkpointer.attach(sim):
            duration = duration - sim.t  # restored: run the rest
        # the clock keeps the Python path under a checkpoint hook; a resumed run stays on the path of the
        # run that saved the checkpoint (the Python one), so its log is bit-identical
        sim.use_fused = self.fused and self.checkpointer is None
        if self.verbose:
            sim.verbose = True
        t = sim.run(duration, log=self.log, progress=self.progress)
        self.info["t_end"] = t
        return t


class Scenario:
    """Base class; see the module docstring."""

    def single_simulation(self, cfg) -> bool:
        """True when a run of ``cfg`` is one simulation (it can save checkpoints and be resumed)."""
        return True

    name: str = ""
    summary: str = ""
    Config: type[ScenarioConfig] = ScenarioConfig
    defaults: dict = {}
    #: ``"columns"``: :meth:`summarize` and :meth:`plot_jobs` also take an
    #: :class:`oceangnc.io.frame.Columns` for ``df``, and ``oceangnc run`` gives them one (no pandas
    #: import, 0.3-0.5 s of start-up); ``"pandas"``: always a DataFrame
    frame: str = "pandas"

    def build(self, cfg, rng: np.random.Generator):
        """The scenario's :class:`~oceangnc.core.clock.Simulation`, ready to run (if it is one).

        Scenarios built from one simulation implement this; the console steps it live, and the
        default :meth:`run` simply runs it for ``cfg.sim.duration``.
        """
        raise NotImplementedError(f"scenario {self.name} has no single live simulation")

    def run(self, cfg, ctx: RunContext) -> dict:
        ctx.simulate(self.build(cfg, ctx.rng), cfg.sim.duration)
        return {}

    def summarize(self, df, cfg) -> dict:
        return {}

    def plot(self, df, cfg, out_dir: Path) -> list[Path]:
        """Draw the plots (default: every job of :meth:`plot_jobs`, in order)."""
        return [p for job in self.plot_jobs(df, cfg, out_dir) for p in job()]

    def plot_jobs(self, df, cfg, out_dir: Path) -> list[Callable[[], list[Path]]]:
        """The plots as independent jobs, each drawing its file(s) and returning their paths.

        :mod:`oceangnc.postproc` shares the jobs between two processes. The default is one job, the
        scenario's own :meth:`plot`; a scenario with several costly figures overrides this (and
        leaves :meth:`plot` to run the jobs). Jobs must not depend on each other.
        """
        if type(self).plot is Scenario.plot:
            return []
        return [functools.partial(self.plot, df, cfg, out_dir)]


_REGISTRY: dict[str, Scenario] | None = None
_LOADED: dict[str, Scenario] = {}


def _load_module(modname: str) -> list[Scenario]:
    m = importlib.import_module(f"oceangnc.scenarios.{modname}")
    scs = list(getattr(m, "SCENARIOS", []))
    for sc in scs:
        _LOADED.setdefault(sc.name, sc)
    return scs


def scenario_summaries() -> dict[str, str]:
    """Name -> one-line summary of every scenario, importing only modules missing from the index."""
    out = {n: s for n, (_, s) in SCENARIO_INDEX.items()}
    for modname in unindexed_modules():
        for sc in _load_module(modname):
            out.setdefault(sc.name, sc.summary)
    return dict(sorted(out.items()))


def scenario_names() -> list[str]:
    """Every scenario's name (cheap: see :func:`scenario_summaries`)."""
    return list(scenario_summaries())


def registry() -> dict[str, Scenario]:
    """All scenarios by name (imports every scenario module on first call; prefer :func:`get_scenario`)."""
    global _REGISTRY
    if _REGISTRY is None:
        reg: dict[str, Scenario] = {}
        for modname in scenario_modules():
            for sc in _load_module(modname):
                if sc.name in reg:
                    raise RuntimeError(f"scenario {sc.name} defined twice")
                reg[sc.name] = _LOADED[sc.name]
        _REGISTRY = dict(sorted(reg.items()))
    return _REGISTRY


def get_scenario(name: str) -> Scenario:
    """Look a scenario up by name, importing only its module; unknown names give an InputError."""
    if name in _LOADED:
        return _LOADED[name]
    if name in SCENARIO_INDEX:
        _load_module(SCENARIO_INDEX[name][0])
        if name in _LOADED:
            return _LOADED[name]
    for modname in unindexed_modules():
        _load_module(modname)
        if name in _LOADED:
            return _LOADED[name]
    reg = registry()
    if name not in reg:
        raise InputError(f"unknown scenario '{name}'; known scenarios: {', '.join(reg)}")
    return reg[name]
