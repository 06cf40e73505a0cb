"""Monte Carlo and parameter sweeps of scenarios, on this machine or on a Dask cluster.

``oceangnc sweep SCENARIO --grid key=v1,v2 [--random key=dist(...) --samples N] [--seeds K]``
runs every combination of config overrides as ordinary scenario runs (:func:`oceangnc.api.run`) on
``dask.distributed`` and records one row per run in ``DIR/results.parquet`` as runs finish;
``oceangnc sweep-report DIR`` gives statistics per point and plots. From Python::

    from oceangnc.sweep import sweep, make_report
    res = sweep("usv-turn", grid={"command.thrust_stbd_kgf": [10, 15, 20]}, seeds=3, workers=2,
                out="runs/my-sweep", duration=30)
    res.table            # pandas DataFrame, one row per run
    make_report(res.out_dir)

Modules: :mod:`~oceangnc.sweep.design` (grid/random designs, run identity and seeds),
:mod:`~oceangnc.sweep.execute` (validation, Dask execution), :mod:`~oceangnc.sweep.table` (the
Parquet table), :mod:`~oceangnc.sweep.report` (statistics and plots), :mod:`~oceangnc.sweep.cli`.
"""

from __future__ import annotations

from pathlib import Path

from .design import Design, Distribution, RunSpec, parse_distribution, parse_grid, parse_random
from .execute import SweepResult, run_one, run_sweep, validate_design
from .report import Report, make_report
from .table import read_results

__all__ = [
    "Design",
    "Distribution",
    "RunSpec",
    "SweepResult",
    "Report",
    "build_design",
    "sweep",
    "run_sweep",
    "run_one",
    "validate_design",
    "make_report",
    "read_results",
    "parse_grid",
    "parse_random",
    "parse_distribution",
]


def build_design(
    scenario: str | None,
    grid=None,
    random=None,
    samples: int = 0,
    seeds: int = 1,
    base_seed: int | None = None,
    design_seed: int | None = None,
    overrides: dict | None = None,
    duration: float | None = None,
    config: str | Path | dict | None = None,
) -> Design:
    """A :class:`Design` from user-level arguments.

    ``grid``: dict key -> list of values, or ``["key=v1,v2", ...]``; ``random``: dict key ->
    ``"uniform(a,b)"`` etc., or ``["key=uniform(a,b)", ...]``; ``overrides``: fixed dotted overrides
    for every run (``sim.seed`` there is taken as the base seed); ``duration``: ``sim.duration``.
    ``base_seed`` defaults to the resolved config's ``sim.seed``; ``design_seed`` (random draws)
    defaults to ``base_seed``.
    """
    from ..api import resolve_config
    from ..io.config import flatten, load_toml

    cfg_dict = load_toml(config) if isinstance(config, (str, Path)) else (dict(config) if config else None)
    fixed = flatten(overrides or {})
    if duration is not None:
        fixed["sim.duration"] = duration
    seed_fixed = fixed.pop("sim.seed", None)
    sc, cfg = resolve_config(
        scenario, cfg_dict, {**fixed, **({"sim.seed": seed_fixed} if seed_fixed is not None else {})}
    )
    if base_seed is None:
        base_seed = int(cfg.sim.seed)
    if cfg_dict and "sim" in cfg_dict and isinstance(cfg_dict["sim"], dict) and "seed" in cfg_dict["sim"]:
        cfg_dict = {**cfg_dict, "sim": {k: v for k, v in cfg_dict["sim"].items() if k != "seed"}}
    return Design(
        scenario=sc.name,
        grid=parse_grid(grid),
        random=parse_random(random),
        samples=int(samples or 0),
        seeds=int(seeds),
        base_seed=int(base_seed),
        design_seed=int(base_seed if design_seed is None else design_seed),
        fixed=fixed,
        config=cfg_dict,
    )


def sweep(
    scenario: str | None,
    grid=None,
    random=None,
    samples: int = 0,
    seeds: int = 1,
    base_seed: int | None = None,
    design_seed: int | None = None,
    overrides: dict | None = None,
    duration: float | None = None,
    config=None,
    workers: int = 2,
    scheduler: str | None = None,
    out: str | Path | None = None,
    resume: bool = False,
    retry_failed: bool = False,
    plots: bool = False,
    keep: bool = True,
    progress: bool = False,
) -> SweepResult:
    """Build the design (:func:`build_design`) and run it (:func:`~oceangnc.sweep.execute.run_sweep`).

    ``out`` defaults to a new ``runs/sweep-<scenario>-<time>``. Bad keys or values raise a one-line
    ConfigError naming the key before any run starts.
    """
    from ..api import new_run_dir

    design = build_design(scenario, grid, random, samples, seeds, base_seed, design_seed, overrides, duration, config)
    if out is None:
        out = new_run_dir("runs", f"sweep-{design.scenario}")
    return run_sweep(
        design,
        out,
        workers=workers,
        scheduler=scheduler,
        resume=resume,
        retry_failed=retry_failed,
        plots=plots,
        keep=keep,
        progress=progress,
    )
