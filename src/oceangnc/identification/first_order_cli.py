"""``oceangnc identify first-order LOG``: integral-method and zig-zag identification from a log.

Reads a Parquet or CSV log whose column names are given by options (defaults: the columns that
``oceangnc run trials`` writes), or a field log (ArduPilot .bin / .tlog, PX4 .ulg, ROS 2 bag, CSV with
``--map``) imported on the fly by :mod:`oceangnc.io.importers` (then the defaults are the standard
signals ``act.steer``, ``act.throttle``, ``usv.u``, ``usv.psi``, ``usv.r``), identifies each trial (split
by ``--trial``), fits the coefficients against speed, prints the tables and writes, into the run folder
``--out`` (default ``runs/identify-first-order-<time>``), ``identification.json`` and the model file
``identified.toml`` (coefficients with standard errors and 95 % intervals) that
``oceangnc run SCENARIO --model identified.toml`` takes as the vehicle's parameters.

The integral method is closed-form and the zig-zag fit starts from a grid search over T: neither starts
from a guess of the answer, and the output says so. A log with zero rows, or without a manoeuvre
(no input step), is refused with exit 2 and a one-line error naming the file; so is a fit that fails
one of the checks of :mod:`oceangnc.identification.first_order_checks` (a time constant at its bound, a
near-singular information matrix, a poor fit, residuals that are not white), the line naming the
trial, the check and its value (``--skip-check CHECK`` accepts it with a warning).
"""

from __future__ import annotations

import json
import math
from pathlib import Path

from ..errors import InputError
from .first_order_checks import CHECKS
from .first_order_results import Columns

#: the log's column options (``--yaw-rate`` for ``Columns.yaw_rate``); their defaults are :class:`Columns`' own
_COLUMN_HELP = {
    "time": "time column, s (default t)",
    "steer": "steer (rudder) column, rad unless --steer-deg",
    "thrust": "thrust column (rpm for the first-order USV)",
    "speed": "speed column, m/s",
    "heading": "heading column, rad unless --heading-deg",
    "yaw_rate": "yaw-rate column, rad/s unless --heading-deg",
    "trial": "trial id column splitting the log (absent: one trial)",
    "kind": "trial kind column, 0 straight 1 turn 2 zig-zag (absent: detected from the inputs)",
}
_OPTS = {k: "--" + k.replace("_", "-") for k in _COLUMN_HELP if k != "kind"}


def _finite(v):
    """NaN/inf -> None so that identification.json is valid JSON."""
    if isinstance(v, dict):
        return {k: _finite(x) for k, x in v.items()}
    if isinstance(v, (list, tuple)):
        return [_finite(x) for x in v]
    if isinstance(v, float) and not math.isfinite(v):
        return None
    return v


def register(methods) -> None:
    p = methods.add_parser(
        "first-order", help="first-order speed/Nomoto models by the integral method (000 eq. 8-21)", description=__doc__
    )
    p.add_argument("log", help="Parquet or CSV log (or a run folder holding log.parquet)")
    for name, text in _COLUMN_HELP.items():
        p.add_argument("--" + name.replace("_", "-"), default=getattr(Columns, name), help=text)
    p.add_argument("--select-trial", type=int, metavar="ID", help="identify only the trial with this id")
    p.add_argument("--steer-deg", action="store_true", help="the steer column is in degrees")
    p.add_argument("--heading-deg", action="store_true", help="heading in deg and yaw rate in deg/s")
    p.add_argument(
        "--points",
        nargs=3,
        type=float,
        metavar=("T1", "T2", "T3"),
        help="override the detected transient (T1-T2) and steady (T2-T3) intervals, s "
        "(log time; one trial: use with --select-trial on multi-trial logs)",
    )
    p.add_argument("--settle-tol", type=float, default=0.01, help="settling band, fraction of the step (default 0.01)")
    p.add_argument("--min-steady", type=float, default=3.0, help="shortest steady interval accepted, s (default 3)")
    p.add_argument(
        "--method",
        choices=("joint", "paper"),
        default="joint",
        help="joint: eq. 11+13 solved together (exact); paper: eq. 12/14 and 19/21 as printed",
    )
    p.add_argument(
        "--out",
        help="run folder for identification.json and identified.toml (default: runs/identify-first-order-<time>)",
    )
    p.add_argument("--seed", type=int, default=0, help="seed of the uncertainty replicas")
    p.add_argument(
        "--force-vehicle",
        action="store_true",
        help="identify a field log whose vehicle is not a boat or submarine (e.g. a multirotor), refused otherwise",
    )
    p.add_argument(
        "--skip-check",
        action="append",
        choices=CHECKS,
        default=[],
        metavar="CHECK",
        help="accept a fit that fails this check (bound, condition, fit, whiteness; repeatable) with a "
        "warning instead of exit 2",
    )
    from ..io.importers.cli import add_source_options

    add_source_options(p)
    p.set_defaults(func=_handler)


#: standard signals of an imported field log (oceangnc.io.importers) used when the trial columns are absent
STANDARD = {"steer": "act.steer", "thrust": "act.throttle", "speed": "usv.u", "heading": "usv.psi", "yaw_rate": "usv.r"}
_DEFAULTS = {k: getattr(Columns, k) for k in STANDARD}


def model_parameters(rep, cols) -> tuple[dict, dict, list[str]]:
    """``[parameters]`` and ``[uncertainty]`` of the first-order USV (000 eq. 8, 15, table 2) from a report.

    With trials at two or more speeds the linear laws ``coef = a u + b`` (t-quantile with n - 2 dof) and
    the trial speed ranges; with one speed the constant coefficients (slope 0) of that trial.
    """
    from .model_file import entry

    params: dict = {}
    unc: dict = {}
    notes: list[str] = []
    keys = {"K_v": ("kv", "(m/s) per thrust unit"), "T_v": ("tv", "s"), "K_r": ("kr", "1/s"), "T_r": ("tr", "s")}
    for name, (stem, unit) in keys.items():
        f = rep.fits.get(name)
        if f is not None:
            dof = max(0, f.n - 2)
            for part, val, se, u in (
                ("slope", f.slope, f.slope_std, unit + " per m/s"),
                ("intercept", f.intercept, f.intercept_std, unit),
            ):
                k = f"usv.{stem}_{part}"
                params[k] = val
                unc[k] = entry(val, se, dof, u)
    for kind, lo, hi, coefs in (
        ("straight", "straight_lo_mps", "straight_hi_mps", ("K_v", "T_v")),
        ("turn", "turn_lo_mps", "turn_hi_mps", ("K_r", "T_r")),
    ):
        st = [s for s in rep.steps if s.kind == kind]
        if kind == "turn" and not st and rep.zigzags:
            st = rep.zigzags
        if not st:
            continue
        sp = [s.speed for s in st if math.isfinite(s.speed)]
        if sp:
            params[f"usv.{lo}"] = float(min(sp))
            params[f"usv.{hi}"] = float(max(sp))
        if coefs[0] not in rep.fits:  # one speed: constant coefficients
            for c, attr in zip(coefs, ("K", "T")):
                vals = [getattr(s, attr) for s in st]
                ses = [getattr(s, attr + "_std") for s in st]
                stem, unit = keys[c]
                v = float(sum(vals) / len(vals))
                se = float(math.sqrt(sum(x * x for x in ses if math.isfinite(x))) / len(ses))
                params[f"usv.{stem}_slope"] = 0.0
                params[f"usv.{stem}_intercept"] = v
                unc[f"usv.{stem}_intercept"] = entry(v, se, 0, unit)
            notes.append(f"{kind}: one speed; constant {coefs[0]}, {coefs[1]} (slope 0)")
    if any(k.startswith("usv.kv") for k in params) and cols.thrust != "trial.thrust":
        notes.append(f"K_v is per unit of the thrust column '{cols.thrust}' (the first-order USV expects rpm)")
    return params, unc, notes


def _handler(args) -> int:
    from ..io.importers.core import trim_rows
    from .first_order import identify_log, trim_nan_edges

    if not (0 < args.settle_tol < 0.5):
        raise InputError(f"--settle-tol {args.settle_tol}: allowed range 0 < value < 0.5")
    if not (args.min_steady >= 0 and math.isfinite(args.min_steady)):
        raise InputError(f"--min-steady {args.min_steady}: must be >= 0 s")
    from ..io.importers import read_any
    from ..io.importers.cli import source_options

    src = Path(args.log)
    df = read_any(args.log, require_marine=not args.force_vehicle, **source_options(args))
    if len(df) == 0:
        raise InputError(f"{src}: the log has 0 rows; nothing to identify")
    imp = df.attrs.get("import") or {}
    if imp.get("vehicle"):
        v = imp["vehicle"]
        print(f"vehicle: {v.get('type')} ({v.get('from')})")
    for n in imp.get("notes") or []:
        print(f"note: {n}")
    std = [k for k, v in _DEFAULTS.items() if getattr(args, k) == v and v not in df.columns and STANDARD[k] in df]
    for k in std:  # an imported field log: its standard signal names
        setattr(args, k, STANDARD[k])
    if args.time != "t":  # read_any trims on t; a log with another time column is trimmed here
        df = trim_rows(df, args.time, args.start, args.end, str(src))
    df, note = trim_nan_edges(df, Columns(**{k: getattr(args, k) for k in _COLUMN_HELP}))
    if note:
        print(f"note: {note}")
    if args.trial in df.columns:
        if args.select_trial is not None:
            df = df[df[args.trial] == args.select_trial]
            if df.empty:
                raise InputError(f"--select-trial {args.select_trial}: no rows with {args.trial} = {args.select_trial}")
        elif args.points is not None and df[args.trial].nunique() > 1:
            raise InputError(
                f"--points sets the intervals of one trial but the log holds "
                f"{df[args.trial].nunique()} trials; pick one with --select-trial ID"
            )
    elif args.select_trial is not None:
        raise InputError(f"--select-trial needs the trial column '{args.trial}' (--trial)")
    cols = Columns(**{k: getattr(args, k) for k in _COLUMN_HELP})
    try:
        rep = identify_log(
            df,
            cols,
            points=args.points,
            steer_deg=args.steer_deg,
            heading_deg=args.heading_deg,
            settle_tol=args.settle_tol,
            min_steady_s=args.min_steady,
            seed=args.seed,
            options=_OPTS,
            method=args.method,
            skip_checks=tuple(args.skip_check),
        )
    except InputError as e:
        raise InputError(f"{src}: {e}") from None
    if not (rep.steps or rep.zigzags):
        raise InputError(f"{src}: no usable manoeuvre (no input step or zig-zag found)")
    refused = [f for f in rep.failures if not f["skipped"]]
    if refused:
        f = refused[0]
        more = (
            f"; also {', '.join(g['label'] + ' ' + g['check'] for g in refused[1:4])}"
            + (f" and {len(refused) - 4} more" if len(refused) > 4 else "")
            if len(refused) > 1
            else ""
        )
        raise InputError(
            f"{src}: {f['label']}: {f['check']} check failed: {f['message']}{more}; "
            f"not identified (--skip-check {f['check']} to accept it)"
        )
    print(
        "starting point: none needed - the integral method is closed-form (000 eq. 11-21) and the zig-zag fit "
        "starts from a grid search over T, not from a guess of the answer"
    )
    print(rep.table())
    n_fit = len(rep.steps) + len(rep.zigzags)
    for f in rep.failures:
        print(f"warning: {f['label']}: {f['check']} check failed (skipped by --skip-check): {f['message']}")
    if not rep.failures:
        print(f"checks: all {n_fit} fit(s) pass {', '.join(CHECKS)} (docs/mavlink-and-logs.md)")
    from ..api import new_run_dir
    from .model_file import write_model

    out = Path(args.out) if args.out else new_run_dir("runs", "identify-first-order")
    out.mkdir(parents=True, exist_ok=True)
    data = rep.to_dict()
    data["log"] = str(src)
    data["columns"] = vars(cols)
    path = out / "identification.json"
    path.write_text(json.dumps(_finite(data), indent=2))
    print(f"wrote {path}")
    params, unc, notes = model_parameters(rep, cols)
    notes += [f"accepted by --skip-check: {f['label']} {f['check']}: {f['message']}" for f in rep.failures]
    if params:
        mp = write_model(out / "identified.toml", "usv-first-order", "identify first-order", src, params, unc, notes)
        print(f"wrote {mp} (oceangnc run SCENARIO --model {mp})")
        for k, u in unc.items():
            print(
                f"  {k:<22} {u['estimate']:12.6g} +- {u['std_error']:9.3g}  95% [{u['ci95'][0]:.6g}, "
                f"{u['ci95'][1]:.6g}]"
            )
    return 0
