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
"""

from __future__ import annotations

import importlib
import pkgutil
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np

from ..errors import InputError
from ..io.config import ScenarioConfig
from ..io.logs import LogWriter


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

    def simulate(self, sim, duration: float) -> float:
        """Run a :class:`~oceangnc.core.clock.Simulation` for ``duration`` s into this run's log
        (with checkpoints, or from a restored checkpoint, when the run asks for them)."""
        if self.checkpointer is not None and self.checkpointer.attach(sim):
            duration = duration - sim.t  # restored: run the rest
        t = sim.run(duration, log=self.log, progress=self.progress)
        self.info["t_end"] = t
        return t


class Scenario:
    """Base class; see the module docstring."""

    name: str = ""
    summary: str = ""
    Config: type[ScenarioConfig] = ScenarioConfig
    defaults: dict = {}

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
        return []


_REGISTRY: dict[str, Scenario] | None = None


def registry() -> dict[str, Scenario]:
    """All scenarios by name (modules of :mod:`oceangnc.scenarios` are imported on first call)."""
    global _REGISTRY
    if _REGISTRY is None:
        import oceangnc.scenarios as pkg

        reg: dict[str, Scenario] = {}
        for mod in sorted(pkgutil.iter_modules(pkg.__path__), key=lambda m: m.name):
            if mod.name.startswith("_") or mod.name == "base":
                continue
            m = importlib.import_module(f"{pkg.__name__}.{mod.name}")
            for sc in getattr(m, "SCENARIOS", []):
                if sc.name in reg:
                    raise RuntimeError(f"scenario {sc.name} defined twice")
                reg[sc.name] = sc
        _REGISTRY = dict(sorted(reg.items()))
    return _REGISTRY


def get_scenario(name: str) -> Scenario:
    """Look a scenario up by name; unknown names give an InputError listing the known ones."""
    reg = registry()
    if name not in reg:
        raise InputError(f"unknown scenario '{name}'; known scenarios: {', '.join(reg)}")
    return reg[name]
