"""Subcommands ``oceangnc sweep`` and ``oceangnc sweep-report`` (registered by :mod:`oceangnc.cli`)."""

from __future__ import annotations

import argparse
import sys

from ..cli_options import add_set


def _cmd_sweep(args) -> int:
    from ..api import new_run_dir
    from ..errors import InputError
    from ..cli_options import set_overrides
    from . import build_design
    from .execute import run_sweep

    if not args.grid and not args.random and args.seeds == 1:
        raise InputError("nothing to sweep: give --grid key=v1,v2,..., --random key=dist(...) --samples N or --seeds K")
    if args.resume and not args.out:
        raise InputError("--resume needs --out DIR (the folder of the sweep to continue)")
    design = build_design(
        args.scenario,
        grid=args.grid,
        random=args.random,
        samples=args.samples,
        seeds=args.seeds,
        base_seed=args.base_seed,
        design_seed=args.design_seed,
        overrides=set_overrides(args),
        duration=args.duration,
        config=args.config,
    )
    out = args.out or new_run_dir("runs", f"sweep-{design.scenario}")
    try:
        res = run_sweep(
            design,
            out,
            workers=args.workers,
            scheduler=args.scheduler,
            resume=args.resume,
            retry_failed=args.retry_failed,
            plots=args.plots,
            keep=not args.no_keep,
            progress=not args.quiet,
            batch=args.batch,
        )
    except KeyboardInterrupt:
        from pathlib import Path

        from .table import ResultsTable

        n = len(ResultsTable(Path(out))) if Path(out).is_dir() else 0
        print(
            f"interrupted: {n} finished run(s) are in {Path(out) / 'results.parquet'}; "
            f"continue with the same command plus --resume --out {out}",
            file=sys.stderr,
        )
        return 130
    df = res.table
    n_ok = int((df["status"] == "ok").sum())
    n_bad = len(df) - n_ok
    print(
        f"sweep {design.scenario}: {len(res.executed)} run(s) done now, {res.skipped} already in the table; "
        f"{len(df)} total ({n_ok} ok, {n_bad} failed or diverged) in {res.wall_time_s:.1f} s "
        f"-> {res.out_dir / 'results.parquet'}"
    )
    if n_bad:
        first = df[df["status"] != "ok"].iloc[0]
        print(f"  first failure: {first['status']} seed {first['seed']}: {first['error']}")
    return 0


def _cmd_report(args) -> int:
    from .report import make_report

    rep = make_report(args.dir, metrics=args.metric or None, plots=not args.no_plots)
    text = (rep.files[1]).read_text() if len(rep.files) > 1 else ""
    if not args.quiet:
        sys.stdout.write(text)
    for f in rep.files:
        print(f)
    return 0


def register(subparsers) -> None:
    """Add ``sweep`` and ``sweep-report`` to the ``oceangnc`` command line."""
    p = subparsers.add_parser(
        "sweep",
        help="Monte Carlo / parameter sweep of a scenario on a Dask cluster",
        description="Run every combination of config overrides (or N random draws) of a scenario, each an "
        "ordinary run, on dask.distributed; one row per run goes to DIR/results.parquet as runs finish. "
        "Run k of a point uses sim.seed = base_seed + k.",
        formatter_class=argparse.RawDescriptionHelpFormatter,
        epilog="examples:\n"
        "  oceangnc sweep usv-turn --grid command.thrust_stbd_kgf=10,15,20 --seeds 3 --duration 30\n"
        "  oceangnc sweep usv-turn-current --grid 'environment.current.speed=linspace(0,0.3,4)' \\\n"
        "      --random environment.current.direction_deg='uniform(0,360)' --samples 5 --workers 2\n"
        "  oceangnc sweep usv-turn --grid command.thrust_stbd_kgf=10,20 --out runs/s1 --resume\n"
        "  oceangnc sweep-report runs/s1",
    )
    p.add_argument("scenario", help="scenario name (see 'oceangnc list')")
    p.add_argument(
        "--grid",
        action="append",
        metavar="KEY=V1,V2,...",
        help="swept config key and its values (repeatable; every combination is run); "
        "values are TOML, or linspace(start,stop,n)",
    )
    p.add_argument(
        "--random",
        action="append",
        metavar="KEY=DIST(...)",
        help="randomly drawn key (repeatable): uniform(a,b), loguniform(a,b), normal(mu,sigma), "
        "randint(a,b), choice(v1,v2,...)",
    )
    p.add_argument("--samples", type=int, default=0, metavar="N", help="number of random draws")
    p.add_argument(
        "--seeds",
        type=int,
        default=1,
        metavar="K",
        help="runs per point; run k uses sim.seed = base_seed + k (default 1)",
    )
    p.add_argument("--base-seed", type=int, metavar="S", help="base seed (default: the config's sim.seed)")
    p.add_argument("--design-seed", type=int, metavar="S", help="seed of the random draws (default: base seed)")
    add_set(p, "fixed override for every run (repeatable)")
    p.add_argument("--config", help="TOML config file merged over the scenario defaults")
    p.add_argument("--duration", type=float, help="simulated time of every run, s")
    where = p.add_mutually_exclusive_group()
    where.add_argument(
        "--workers",
        type=int,
        default=2,
        metavar="N",
        help="worker processes of a local Dask cluster (default 2; 0 = in this process, no Dask)",
    )
    where.add_argument("--scheduler", metavar="tcp://HOST:PORT", help="run on an existing Dask cluster")
    p.add_argument("--out", help="sweep folder (default runs/sweep-<scenario>-<time>)")
    p.add_argument("--resume", action="store_true", help="continue the sweep in --out, skipping runs already recorded")
    p.add_argument("--retry-failed", action="store_true", help="with --resume, run failed/diverged runs again")
    p.add_argument("--plots", action="store_true", help="draw each run's PNG plots (off by default)")
    p.add_argument("--no-keep", action="store_true", help="delete each run's folder once its row is recorded")
    p.add_argument("--quiet", action="store_true", help="no progress bar")
    p.add_argument(
        "--batch",
        type=int,
        default=1,
        metavar="K",
        help="runs per task, run as one compiled batch (oceangnc.run_batch; default 1)",
    )
    p.set_defaults(func=_cmd_sweep)

    q = subparsers.add_parser("sweep-report", help="statistics per sweep point and plots of a sweep folder")
    q.add_argument("dir", help="sweep folder holding results.parquet")
    q.add_argument("--metric", action="append", help="metric column to report (repeatable; default all numeric)")
    q.add_argument("--no-plots", action="store_true", help="statistics only")
    q.add_argument("--quiet", action="store_true", help="do not print the table")
    q.set_defaults(func=_cmd_report)
