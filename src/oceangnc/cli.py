"""Command line ``oceangnc``: a thin layer over :mod:`oceangnc.api`.

Exit codes: 0 success, 2 bad input (config, file, name), 1 diverged simulation; errors are one line.

Subcommands of later capabilities live in their own packages and are registered here through a
``register(subparsers)`` function in each module of :data:`PLUGINS` (``identify``, ``console``,
``sweep``, ``validate``/``check``, ``hydro``); a module that is absent or whose optional dependencies are
missing is skipped.
"""

from __future__ import annotations

import argparse
import functools
import importlib
import json
import os
import sys

from .core.interrupts import terminate_like_ctrl_c
from .errors import OceanGNCError, Terminated

PLUGINS = (
    "oceangnc.identification.cli",
    "oceangnc.console.cli",
    "oceangnc.sweep.cli",
    "oceangnc.mavlink.cli",
    "oceangnc.io.importers.cli",
    "oceangnc.validation.cli",
    "oceangnc.view.cli",
    "oceangnc.hydro.cli",
)


def _cmd_list(args) -> int:
    from .scenario_index import DEFAULT_SCENARIO, FALLBACK_SCENARIO, SCENARIO_INDEX, unindexed_modules

    if unindexed_modules():  # a scenario module the index does not name: import it for its summary
        from .api import default_scenario, list_scenarios

        default, scen = default_scenario(), list_scenarios()
    else:  # the index alone: nothing heavy imported
        scen = {name: summary for name, (_, summary) in sorted(SCENARIO_INDEX.items())}
        default = DEFAULT_SCENARIO if DEFAULT_SCENARIO in scen else FALLBACK_SCENARIO
    w = max(len(n) for n in scen)
    for name, summary in scen.items():
        star = " (default)" if name == default else ""
        print(f"{name:<{w}}  {summary}{star}")
    return 0


def _cmd_run(args) -> int:
    from . import postproc

    if args.mcap:  # fail before the run, not after it
        from .view.mcap_export import MissingMcap, require_mcap

        try:
            require_mcap()
        except MissingMcap:
            from .view.cli import MCAP_HINT

            print(MCAP_HINT, file=sys.stderr)
            return 2

    post = None
    light = postproc.light_plots_for(args.scenario, args.config) if args.resume is None else None
    try:
        if light is not None and not args.no_plots:
            # a scenario with a light plot module: its drawer forked first thing, before numpy, pydantic
            # and numba are imported here, so that it imports matplotlib meanwhile (oceangnc.postproc)
            post = postproc.start_early(*light)
        from .io.config import flatten, parse_sets

        overrides = flatten(parse_sets(args.set))
        for path in args.plugin or []:  # before the helper: it resolves the config with the plugins' blocks
            from .core.registry import load_plugin

            load_plugin(path)
        if args.resume is None and light is None:
            from .api import resolve_run_config

            # fork the summary/plot helper first, so that its imports overlap this process's
            post = postproc.start(
                functools.partial(resolve_run_config, args.scenario, args.config, overrides, args.duration, args.model),
                plots=not args.no_plots,
            )
        from .core.caches import ahead_of_time, lean_loads

        # cached kernels loaded without numba's full target refresh; on a first run, the plants' kernels
        # compiled by a second process meanwhile (oceangnc.core.caches)
        with lean_loads(), ahead_of_time():
            return _run(args, overrides, post)
    except BaseException:
        postproc.cancel(post)
        raise


def _run(args, overrides: dict, post) -> int:
    from .api import run
    from .errors import InputError

    if args.scenario and args.scenario.lower().endswith(".toml"):
        from .scenarios.base import registry

        if args.scenario not in registry():
            raise InputError(
                f"unknown scenario '{args.scenario}': to run a config file use 'oceangnc run --config {args.scenario}'"
            )
    if args.resume is not None:
        res = run(
            resume=args.resume,
            checkpoint_every=args.checkpoint_every,
            plots=not args.no_plots,
            progress=not args.quiet,
            scenario=args.scenario,
            config=args.config,
            overrides=overrides or None,
            duration=args.duration,
        )
    else:
        res = run(
            args.scenario,
            overrides=overrides,
            duration=args.duration,
            config=args.config,
            out=args.out,
            plots=not args.no_plots,
            progress=not args.quiet,
            verbose=args.verbose,
            checkpoint_every=args.checkpoint_every,
            model=args.model,
            overwrite=args.overwrite,
            _post=post,
        )
    if not args.quiet and not args.json:  # --json: the one JSON line only
        keys = [k for k in res.summary if k not in ("scenario",)]
        w = max(len(k) for k in keys)
        print(f"scenario {res.summary['scenario']}: wrote {res.out_dir}")
        for k in keys:
            v = res.summary[k]
            print(f"  {k:<{w}}  {v:.4g}" if isinstance(v, float) else f"  {k:<{w}}  {v}")
    if args.mcap:  # the run's log as RUN/run.mcap (oceangnc.view.mcap_export)
        from .view.mcap_export import export_mcap

        path = export_mcap(res.out_dir)
        if not args.json:
            print(f"wrote {path}")
    if args.json:
        print(json.dumps(res.summary))
    return 0


def _cmd_plot(args) -> int:
    from .api import replot

    for p in replot(args.dir):
        print(p)
    return 0


def _cmd_log_repair(args) -> int:
    from .io.logs import repair_log, repair_summary

    print(repair_summary(repair_log(args.dir)))  # counts, not names: a long run leaves thousands of parts
    return 0


CORE_COMMANDS = ("list", "run", "plot")


def build_parser(plugins: bool = True) -> argparse.ArgumentParser:
    """The argument parser; ``plugins=False`` leaves out the plugin subcommands (their imports cost ~0.5 s)."""
    ap = argparse.ArgumentParser(
        prog="oceangnc", description="Guidance, navigation, control and identification of unmanned marine vehicles."
    )
    sub = ap.add_subparsers(dest="command", metavar="COMMAND")

    p = sub.add_parser("list", help="list the scenarios, one line each")
    p.set_defaults(func=_cmd_list)

    p = sub.add_parser("run", help="run a scenario (default: the flagship combined survey)")
    p.add_argument("scenario", nargs="?", help="scenario name (see 'oceangnc list')")
    p.add_argument("--config", help="TOML config file")
    p.add_argument(
        "--set",
        action="append",
        metavar="KEY=VALUE",
        help="override a config key, dotted path (repeatable), e.g. environment.current.speed=0.5",
    )
    p.add_argument("--out", help="output folder (default: runs/<scenario>-<time>)")
    p.add_argument("--overwrite", action="store_true", help="replace the run already in the --out folder")
    p.add_argument("--duration", type=float, help="simulated time, s")
    p.add_argument(
        "--model",
        help="identified model file (identified.toml from 'oceangnc identify'): its "
        "[parameters] are the vehicle's parameters (--set still wins)",
    )
    p.add_argument(
        "--plugin",
        action="append",
        metavar="PATH",
        help="a Python file registering blocks (@register_block), loaded before the config is "
        "read, so a --set ...kind= can pick them (repeatable)",
    )
    p.add_argument("--no-plots", action="store_true", help="skip the PNG plots")
    p.add_argument("--mcap", action="store_true", help="also write RUN/run.mcap (Foxglove; needs oceangnc[view])")
    p.add_argument(
        "--verbose",
        action="store_true",
        help="say which clock path runs (fused compiled loop or the Python fallback) and why",
    )
    p.add_argument("--quiet", action="store_true", help="no progress bar and no summary print")
    p.add_argument("--json", action="store_true", help="print the summary as one JSON line")
    p.add_argument(
        "--checkpoint-every",
        type=float,
        metavar="S",
        help="save a checkpoint every S simulated seconds (resume with --resume DIR)",
    )
    p.add_argument("--resume", metavar="DIR", help="continue the run in DIR from its last checkpoint")
    p.set_defaults(func=_cmd_run)

    p = sub.add_parser("log", help="log utilities: 'oceangnc log repair DIR'")
    lsub = p.add_subparsers(dest="log_command", metavar="ACTION", required=True)
    q = lsub.add_parser("repair", help="make a crashed run's log.parquet whole (drop half-written parts)")
    q.add_argument("dir", help="run folder or its log.parquet folder")
    q.set_defaults(func=_cmd_log_repair)

    p = sub.add_parser("plot", help="re-draw the plots of a run folder from its log")
    p.add_argument("dir", help="run folder holding log.parquet and config.toml")
    p.set_defaults(func=_cmd_plot)

    for modname in PLUGINS if plugins else ():
        try:
            mod = importlib.import_module(modname)
        except ModuleNotFoundError as e:
            if e.name and (modname.startswith(e.name) or e.name == modname):
                continue  # capability not present
            missing = e.name
            q = sub.add_parser(modname.split(".")[1], help=f"(unavailable: missing package {missing})")
            q.set_defaults(func=lambda a, m=missing: _missing(m))
            continue
        mod.register(sub)
    return ap


def _missing(name: str) -> int:
    print(
        f"error: this command needs the optional package '{name}'; install with pip install 'oceangnc[all]'",
        file=sys.stderr,
    )
    return 2


def main(argv: list[str] | None = None) -> int:
    """Run the command line; ``argv`` None means the program's own (``sys.argv``), as the script does."""
    program = argv is None
    argv = list(sys.argv[1:] if argv is None else argv)
    first = next((a for a in argv if not a.startswith("-")), None)
    # a core command needs no plugin subcommand: skip importing them (start-up time)
    ap = build_parser(plugins=first not in CORE_COMMANDS or "-h" in argv[:1] or "--help" in argv[:1])
    args = ap.parse_args(argv)
    if not getattr(args, "func", None):
        ap.print_help()
        return 2
    # a terminated run ends like Ctrl-C (its summary.json says interrupted); other commands keep the
    # default SIGTERM (a server or bridge blocked in its own threads must not outlive the signal)
    restore = terminate_like_ctrl_c() if args.command == "run" else None
    try:
        rc = _run_command(args)
    except OceanGNCError as e:
        print("error: " + str(e).replace("\n", " "), file=sys.stderr)
        rc = e.exit_code
    except KeyboardInterrupt as e:
        term = isinstance(e, Terminated)
        kept = getattr(e, "kept", None)  # oceangnc.run_stop: what the interrupted run kept
        if kept is None:
            kept = "no summary written: stopped before the run started" if args.command == "run" else "stopped"
        print(f"{'terminated (SIGTERM)' if term else 'interrupted'}: {kept}", file=sys.stderr)
        rc = 143 if term else 130
    except BrokenPipeError:  # the reader of the output went away (``oceangnc list | head``): end quietly
        try:  # so that the interpreter's final flush of stdout does not fail again
            os.dup2(os.open(os.devnull, os.O_WRONLY), sys.stdout.fileno())
        except (OSError, ValueError):
            pass
        rc = 0
    finally:
        if restore is not None:
            restore()
    if program and args.command == "run" and not args.plugin and os.environ.get("OCEANGNC_FAST_EXIT", "1") != "0":
        _fast_exit(rc)
    return rc


def _run_command(args) -> int:
    """Run the chosen command; a warning reaches the user as one line ``warning: ...`` (no source path
    or code line, as Python's default format prints), once per message."""
    import warnings

    def show(message, category, filename, lineno, file=None, line=None):
        print(f"warning: {message}", file=sys.stderr)

    with warnings.catch_warnings():
        warnings.simplefilter("default")
        warnings.showwarning = show
        return int(args.func(args) or 0)


def _fast_exit(rc: int) -> None:
    """End the process at once, skipping only the interpreter's teardown.

    With numba's machine code loaded, freeing every module and LLVM object at exit costs about 0.3 s
    (a fifth of a cached flagship run). The ``run`` command has closed and synced its files and
    reaped its helpers by now; the atexit handlers still run and the standard streams are flushed.
    Not used when ``main`` is called from Python, with ``--plugin`` (a user's module may rely on
    finalisers), or with ``OCEANGNC_FAST_EXIT=0``.
    """
    import atexit

    atexit._run_exitfuncs()
    for stream in (sys.stdout, sys.stderr):
        try:
            stream.flush()
        except (OSError, ValueError):
            pass
    os._exit(rc)


if __name__ == "__main__":
    sys.exit(main())
