"""Reinforcement learning over oceangnc's compiled closed loop (issue 44; docs/rl.md).

``oceangnc.rl.make(scenario, task=..., seed=None, **overrides)`` gives a :class:`gymnasium.Env` (the
optional extra ``pip install 'oceangnc[rl]'``: Gymnasium only, no learning library). The tasks are in
:mod:`oceangnc.rl.tasks`; the environment in :mod:`oceangnc.rl.env`.
"""

from __future__ import annotations

import math

import numpy as np

from ..core.config import validate
from ..errors import ConfigError, InputError

try:
    import gymnasium  # noqa: F401
except ImportError as e:  # pragma: no cover - the extra is missing
    raise ImportError("oceangnc.rl needs Gymnasium: pip install 'oceangnc[rl]'") from e

from .env import ScenarioEnv
from .tasks import TASKS, Task, TaskParams


def task_names() -> dict[str, str]:
    """Task name -> the scenario it runs over."""
    return {n: t.scenario for n, t in TASKS.items()}


def _task_class(scenario: str, task: str | None) -> type[Task]:
    if task is None:
        found = [t for t in TASKS.values() if t.scenario == scenario]
        if not found:
            known = ", ".join(f"{n} ({s})" for n, s in task_names().items())
            raise InputError(f"rl: no task over scenario '{scenario}'; tasks (scenario): {known}")
        return found[0]
    if task not in TASKS:
        raise InputError(f"rl: unknown task '{task}'; known tasks: {', '.join(TASKS)}")
    cls = TASKS[task]
    if cls.scenario != scenario:
        raise InputError(f"rl: task '{task}' runs over scenario '{cls.scenario}', not '{scenario}'")
    return cls


def make(scenario: str, task: str | None = None, seed: int | None = None, **overrides) -> ScenarioEnv:
    """A Gymnasium environment of ``task`` over ``scenario`` (docs/rl.md).

    ``overrides``: a task parameter by its name (``e_max=5.0``, ``time_limit=30.0``: the fields of the
    task's ``Params``), anything else a scenario config override as for :func:`oceangnc.run`, dotted keys
    allowed (``**{"route.speed": 1.0}``). ``seed``: the seed of the first :meth:`reset` when that call
    gives none. Bad names and values raise one :class:`~oceangnc.errors.ConfigError` /
    :class:`~oceangnc.errors.InputError` naming the key and the allowed range.
    """
    from ..api import resolve_config
    from ..core.clock import Simulation
    from ..models.vehicle import load_vehicle

    cls = _task_class(scenario, task)
    fields = cls.Params.model_fields
    params = validate(cls.Params, {k: v for k, v in overrides.items() if k in fields})
    sc, cfg = resolve_config(scenario, overrides={k: v for k, v in overrides.items() if k not in fields})
    n = params.control_period / cfg.sim.dt
    if abs(n - round(n)) > 1e-9 * n or round(n) < 1:
        raise ConfigError(
            f"config error: control_period = {params.control_period:g}: must be a whole number of physics steps "
            f"(sim.dt = {cfg.sim.dt:g} s)"
        )
    vf = load_vehicle(cfg.vehicle)
    t = cls(params, vf, cfg)
    _check(t)
    built = sc.build(cfg, np.random.default_rng(0))
    built._wait_ahead()
    blocks = [b for b in built.blocks if t.keep(b)]
    rng = np.random.default_rng(0)  # the blocks' generators are reseeded from the episode's seed at each reset
    sim = Simulation(built.plants, blocks, built.dt, params.control_period, rng, external=t.externals)
    return ScenarioEnv(t, sim, seed)


def _check(t: Task) -> None:
    """Cross-parameter rules of a task (a start band wider than its channel ends every episode at once)."""
    p = t.params
    e_max, cross = getattr(p, "e_max", math.inf), getattr(p, "start_cross_max", 0.0)
    if cross >= e_max:
        raise ConfigError(f"config error: start_cross_max = {cross:g}: must be below e_max = {e_max:g} m")
    d_max, band = getattr(p, "d_max", math.inf), getattr(p, "start_band", 0.0)
    deep = getattr(p, "start_depth_band", 0.0)
    if math.sqrt(2 * band**2 + deep**2) >= d_max:  # the farthest corner of the start box
        raise ConfigError(
            f"config error: start_band = {band:g}, start_depth_band = {deep:g}: the start box's corner must lie "
            f"within d_max = {d_max:g} m"
        )


__all__ = ["make", "task_names", "ScenarioEnv", "Task", "TaskParams", "TASKS"]
