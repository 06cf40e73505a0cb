"""``oceangnc validate`` and ``oceangnc check`` (registered through :data:`oceangnc.cli.PLUGINS`)."""

from __future__ import annotations

import argparse
import sys
import time
from pathlib import Path

from ..cli_options import add_set

FLAGSHIP_MD = """## The flagship result (003 ch. 4): what reproduces and what does not

Backstepping and PID give nearly the same distance in `combined-survey` (0.496 vs 0.506 m) because the cable,
not the controller, holds the UUV: the 12 kgf UUV hangs on a 3 m cable whose pendulum stiffness (about 41 N/m)
equals the controllers' own, the stern thrusters deliver only 1-2 N each of their 75 N during the survey (the cable tows the UUV), and the
formation target (0.5 m astern) is where the towed UUV trails anyway.

The depth is geometry: on a taut 3 m cable a rise from 3 m to 2.77 m needs the tow point at least 1.15 m
(horizontally) from the attachment. With the UUV's thrusters held at zero the UUV is dragged broadside 1.6-1.8 m
behind and rises to 2.65-2.79 m with a pitch of -0.2 to -3.3 deg: 003's depth and pitch. Held at 0.4-0.5 m, it
stays within centimetres of its hanging depth, unless the cable leaves the USV about 1.15 m ahead of the
reference point (its bow): then PID gives 0.47 m and 2.80 m but the UUV pitches -34 to -45 deg, and backstepping
(no integral action) cannot hold the target.

No sensible set of the unprinted parameters gives 0.4 m, 2.77 m and -2..-4 deg together (sweep below: attachment
point, submerged weight, formation offset, gains, drag); the defaults are unchanged and the depth, margin and
field-test pitch cases (and the distance growth in the turn) are documented deviations. Details: docs/combined-vehicle.md, 'The flagship result'.

![flagship sweep](flagship_sweep.png)"""


def _progress(i, n, o):
    val = "–" if o.measured is None else f"{o.measured.value:.4g}"
    print(
        f"[{i:>2}/{n}] {o.status.upper():<9} {o.case.id:<40} {val:>10}  ({o.wall_s:.1f} s)", file=sys.stderr, flush=True
    )


def cmd_validate(args) -> int:
    from ..cli_options import set_overrides
    from . import Runner, run_cases, select
    from .cases import CASES
    from .report import evidence_text, summary_counts, write_report

    cases = select(CASES, args.only)
    if args.list:
        w = max(len(c.id) for c in cases)
        for c in cases:
            print(f"{c.id:<{w}}  {c.class_text()}  [{c.source}]")
        return 0
    overrides = set_overrides(args)
    out = Path(args.out)
    out.mkdir(parents=True, exist_ok=True)
    runner = Runner(overrides)
    t0 = time.perf_counter()
    print(f"oceangnc validate: {len(cases)} cases -> {out}", file=sys.stderr, flush=True)
    try:
        outcomes = run_cases(cases, runner, progress=None if args.quiet else _progress)
    finally:
        runner.close()
    unused = set(overrides) - runner.used
    if unused:
        print(f"warning: --set {', '.join(sorted(unused))} reached no case", file=sys.stderr)
    flag = FLAGSHIP_MD if any(o.case.group == "003 combined" for o in outcomes) else ""
    if flag and not (out / "flagship_sweep.png").exists():
        flag = flag.replace(
            "\n\n![flagship sweep](flagship_sweep.png)",
            "\n\n(The sweep figure is made by "
            "`python -m oceangnc.validation.flagship DIR`; the committed copy is in docs/validation/.)",
        )
    md, html = write_report(
        outcomes, out, overrides, flagship_md=flag, plots=not args.no_plots, wall_s=time.perf_counter() - t0
    )
    c = summary_counts(outcomes)
    print(
        f"{len(outcomes)} cases: {c['pass']} pass, {c['fail']} fail, {c['deviation']} documented deviation(s), "
        f"{c['error']} error(s); wrote {md} and {html}"
    )
    print(evidence_text(outcomes) + ".")
    for o in outcomes:
        if o.status in ("fail", "error"):
            m = o.measured
            got = "–" if m is None else f"{m.value:.4g}"
            print(
                f"  {o.status.upper()} {o.case.id}: {o.case.quantity} = {got} {o.case.unit}, accepted "
                f"{o.lo:.4g} … {o.hi:.4g} (published {o.case.published_text}; {o.case.source})"
                + (f" [{o.error}]" if o.error else "")
            )
    return 1 if (c["fail"] or c["error"]) else 0


def cmd_check(args) -> int:
    from ..cli_options import set_overrides
    from .check import check

    overrides = set_overrides(args)
    rep = check(args.scenario, overrides, horizon=args.horizon)
    print(rep.text())
    return 2 if rep.refused else 0


def register(subparsers) -> None:
    """Add ``validate`` and ``check`` to the ``oceangnc`` command line."""
    p = subparsers.add_parser(
        "validate",
        help="run the validation cases (published figures and physical checks) and write a report",
        description="Run every validation case: each published figure of the seed documents the project "
        "reproduces and the physical checks, with its tolerance. Every case has a class: prediction (no "
        "parameter fitted to it), calibration target, round trip, reference implementation (another program, "
        "same equations), analytic check (code verification) or physical law; only passing "
        "predictions count as reproductions. Writes DIR/report.md and DIR/report.html (one plot per case). "
        "Exit 1 if a case fails.",
        formatter_class=argparse.RawDescriptionHelpFormatter,
        epilog="examples:\n  oceangnc validate --out runs/validation\n  oceangnc validate --only 003-fig2\n"
        "  oceangnc validate --only 'physics-*' --set usv.d11=120",
    )
    p.add_argument(
        "--only", metavar="PATTERN", help="glob or substring of case ids / sources / groups (comma-separated)"
    )
    p.add_argument("--out", default="validation", metavar="DIR", help="output folder (default: validation)")
    add_set(p, "override a config key in every scenario and model that has it (repeatable)")
    p.add_argument(
        "--list",
        action="store_true",
        help="list the selected cases with their class (prediction, calibration target, round trip, analytic "
        "check, physical law) and source, and exit",
    )
    p.add_argument("--no-plots", action="store_true", help="skip the per-case PNGs")
    p.add_argument("--quiet", action="store_true", help="no per-case progress lines")
    p.set_defaults(func=cmd_validate)

    q = subparsers.add_parser(
        "check",
        help="time-step advisor: stability limits, the step in use, its accuracy, loop rates",
        description="For a scenario: each plant's stability limit for each integrator, the physics step the "
        "scenario will use, its expected accuracy from a step-halving run, and the loop rate of every block. "
        "A step above a limit is refused (exit 2) with the step to use.",
    )
    q.add_argument("scenario", help="scenario name (see 'oceangnc list')")
    add_set(q)
    q.add_argument("--horizon", type=float, default=5.0, help="simulated time of the step-halving run, s (default 5)")
    q.set_defaults(func=cmd_check)
