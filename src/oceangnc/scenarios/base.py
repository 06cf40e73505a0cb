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
import pkgutil
from collections.abc import Callable
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


#: name -> (module under oceangnc.scenarios, one-line summary); kept equal to the modules by a test
SCENARIO_INDEX: dict[str, tuple[str, str]] = {
    "autopilot-heading": ("first_order", "Pole-placed heading PD on the first-order USV: 0 -> 100 deg (000 fig. 17)"),
    "autopilot-speed": (
        "first_order",
        "Pole-placed speed P on the first-order USV: 0 -> 5 m/s, steady error of P control (000 fig. 18)",
    ),
    "berthing-channel": (
        "berthing",
        "S-175 container ship through a Z channel with 30 deg bends by joystick (001 figs 6-10)",
    ),
    "berthing-dock": ("berthing", "S-175 container ship: joystick approach and stop alongside a berth (001)"),
    "cable-current": (
        "cable",
        "Cable with fixed top, UUV hanging in a uniform current: equilibrium tension and angle (003 fig 2-10)",
    ),
    "combined-survey": (
        "combined",
        "USV-cable-UUV through (0,0) (10,10) (20,5) at 0.6 m/s; UUV by PID or backstepping (003 figs 4-7..4-15)",
    ),
    "ekf-zigzag": (
        "ekf_zigzag",
        "submarine heave-pitch coefficients by augmented EKF from a 5-5/10-5 zig-zag (002 tables 5.2/5.3)",
    ),
    "field-test": (
        "combined",
        "sea trial of 003 ch. 6.2: (50,0) (50,-50) (0,-50) (0,0) at 1.3 m/s target, PID, sensors on",
    ),
    "tow-straight": (
        "cable",
        "USV tows the UUV straight at 0.5 m/s, UUV at its own speed: depth change (003 figs 4-2 to 4-5)",
    ),
    "tow-deploy": ("tow", "USV holding station, UUV lowered by the winch from the surface to 30 m and recovered"),
    "tow-survey-depth": ("tow", "Towing at 1 m/s on a lawnmower over a sloping seabed, 5 m altitude held by the winch"),
    "trials": (
        "trials",
        "Straight/turning/zig-zag trials from a model, logged for 'oceangnc identify first-order' (000 sec. 2.2)",
    ),
    "usv-remote": (
        "usv_remote",
        "USV for the operator console: stick (speed / yaw-rate PIDs) or pure-pursuit waypoint autopilot",
    ),
    "usv-straight": ("usv_open_loop", "USV, 30 kgf on both thrusters: steady speed (003 fig 2-7, ~0.8 m/s)"),
    "usv-turn": ("usv_open_loop", "USV, 30/15 kgf: turning circle (003 fig 2-8, R ~1.75 m, ~16 deg/s)"),
    "usv-turn-current": ("usv_open_loop", "USV turning in a 0.1 m/s current toward 45 deg (003 fig 2-10)"),
    "usv-turn-wind": ("usv_open_loop", "USV turning in 1 m/s wind, direction settable (003 fig 2-9)"),
    "usv-waypoints-7": (
        "first_order",
        "First-order USV through seven waypoints from heading 90 deg, rest; hybrid/LOS guidance (000 fig. 21)",
    ),
    "uuv-profile-plan": (
        "first_order",
        "USV planned from the towed UUV's plan (000 table 3, eq. 32-34), LOS or hybrid guidance (figs. 22-26)",
    ),
    "waypoints-square": (
        "combined",
        "combined vehicle round a 50 m square; UUV on relative angle (+ heading to USV) (003 fig 4-6)",
    ),
}

_REGISTRY: dict[str, Scenario] | None = None
_LOADED: dict[str, Scenario] = {}


#: scenario module -> a module with ``plot_jobs(name, df, cfg, out_dir)`` that draws the figures of
#: that module's scenarios from a :class:`~oceangnc.io.frame.Columns` log and a config read by
#: attribute (the scenario's config or a :class:`~oceangnc.io.frame.Plain` of it), importing neither
#: the models nor numba. ``oceangnc run`` forks their drawer first thing, so it imports matplotlib while
#: this process simulates (:func:`oceangnc.postproc.start_early`). Their scenarios have
#: ``frame = "columns"``; tests/test_frame.py checks both and that the figures are the same bytes.
LIGHT_PLOTS: dict[str, str] = {"combined": "oceangnc.scenarios._combined_plots"}


def light_plots(name: str) -> str | None:
    """The light plot module of scenario ``name`` (see :data:`LIGHT_PLOTS`), None if it has none."""
    entry = SCENARIO_INDEX.get(name)
    return LIGHT_PLOTS.get(entry[0]) if entry else None


def _scenario_modules() -> list[str]:
    import oceangnc.scenarios as pkg

    return sorted(m.name for m in pkgutil.iter_modules(pkg.__path__) if not m.name.startswith("_") and m.name != "base")


def _load_module(modname: str) -> list[Scenario]:
    m = importlib.import_module(f"oceangnc.scenarios.{modname}")
    scs = list(getattr(m, "SCENARIOS", []))
    for sc in scs:
        _LOADED.setdefault(sc.name, sc)
    return scs


def _unindexed_modules() -> list[str]:
    known = {mod for mod, _ in SCENARIO_INDEX.values()}
    return [m for m in _scenario_modules() if m not in known]


def scenario_summaries() -> dict[str, str]:
    """Name -> one-line summary of every scenario, importing only modules missing from the index."""
    out = {n: s for n, (_, s) in SCENARIO_INDEX.items()}
    for modname in _unindexed_modules():
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
        for modname in _scenario_modules():
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
    for modname in _unindexed_modules():
        _load_module(modname)
        if name in _LOADED:
            return _LOADED[name]
    reg = registry()
    if name not in reg:
        raise InputError(f"unknown scenario '{name}'; known scenarios: {', '.join(reg)}")
    return reg[name]
