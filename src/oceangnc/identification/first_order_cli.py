"""``oceangnc identify first-order LOG``: integral-method and zig-zag identification from a log.

Reads a Parquet or CSV log whose column names are given by options (defaults: the columns that
``oceangnc run trials`` writes), identifies each trial (split by ``--trial``), fits the coefficients
against speed, prints the tables and writes ``identification.json`` (default: next to the log).
"""

from __future__ import annotations

import json
import math
from pathlib import Path

from ..errors import InputError

_OPTS = {"time": "--time", "steer": "--steer", "thrust": "--thrust", "speed": "--speed", "heading": "--heading",
         "yaw_rate": "--yaw-rate", "trial": "--trial"}


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
    p = methods.add_parser("first-order", help="first-order speed/Nomoto models by the integral method (000 eq. 8-21)",
                           description=__doc__)
    p.add_argument("log", help="Parquet or CSV log (or a run folder holding log.parquet)")
    p.add_argument("--time", default="t", help="time column, s (default t)")
    p.add_argument("--steer", default="trial.steer", help="steer (rudder) column, rad unless --steer-deg")
    p.add_argument("--thrust", default="trial.thrust", help="thrust column (rpm for the first-order USV)")
    p.add_argument("--speed", default="trial.speed", help="speed column, m/s")
    p.add_argument("--heading", default="trial.heading", help="heading column, rad unless --heading-deg")
    p.add_argument("--yaw-rate", default="trial.yaw_rate", help="yaw-rate column, rad/s unless --heading-deg")
    p.add_argument("--trial", default="trial.id", help="trial id column splitting the log (absent: one trial)")
    p.add_argument("--kind", default="trial.kind", help="trial kind column, 0 straight 1 turn 2 zig-zag "
                                                        "(absent: detected from the inputs)")
    p.add_argument("--select-trial", type=int, metavar="ID", help="identify only the trial with this id")
    p.add_argument("--steer-deg", action="store_true", help="the steer column is in degrees")
    p.add_argument("--heading-deg", action="store_true", help="heading in deg and yaw rate in deg/s")
    p.add_argument("--points", nargs=3, type=float, metavar=("T1", "T2", "T3"),
                   help="override the detected transient (T1-T2) and steady (T2-T3) intervals, s "
                        "(log time; one trial: use with --select-trial on multi-trial logs)")
    p.add_argument("--settle-tol", type=float, default=0.01, help="settling band, fraction of the step (default 0.01)")
    p.add_argument("--min-steady", type=float, default=3.0, help="shortest steady interval accepted, s (default 3)")
    p.add_argument("--method", choices=("joint", "paper"), default="joint",
                   help="joint: eq. 11+13 solved together (exact); paper: eq. 12/14 and 19/21 as printed")
    p.add_argument("--out", help="folder for identification.json (default: the log's folder)")
    p.add_argument("--seed", type=int, default=0, help="seed of the uncertainty replicas")
    p.set_defaults(func=_handler)


def _handler(args) -> int:
    from ..io.logs import read_log
    from .first_order import Columns, identify_log

    if not (0 < args.settle_tol < 0.5):
        raise InputError(f"--settle-tol {args.settle_tol}: allowed range 0 < value < 0.5")
    if not (args.min_steady >= 0 and math.isfinite(args.min_steady)):
        raise InputError(f"--min-steady {args.min_steady}: must be >= 0 s")
    df = read_log(args.log)
    if args.trial in df.columns:
        if args.select_trial is not None:
            df = df[df[args.trial] == args.select_trial]
            if df.empty:
                raise InputError(f"--select-trial {args.select_trial}: no rows with {args.trial} = {args.select_trial}")
        elif args.points is not None and df[args.trial].nunique() > 1:
            raise InputError(f"--points sets the intervals of one trial but the log holds "
                             f"{df[args.trial].nunique()} trials; pick one with --select-trial ID")
    elif args.select_trial is not None:
        raise InputError(f"--select-trial needs the trial column '{args.trial}' (--trial)")
    cols = Columns(time=args.time, steer=args.steer, thrust=args.thrust, speed=args.speed, heading=args.heading,
                   yaw_rate=args.yaw_rate, trial=args.trial, kind=args.kind)
    rep = identify_log(df, cols, points=args.points, steer_deg=args.steer_deg, heading_deg=args.heading_deg,
                       settle_tol=args.settle_tol, min_steady_s=args.min_steady, seed=args.seed, options=_OPTS,
                       method=args.method)
    print(rep.table())
    src = Path(args.log)
    out = Path(args.out) if args.out else (src if src.is_dir() else src.parent)
    out.mkdir(parents=True, exist_ok=True)
    data = rep.to_dict()
    data["log"] = str(src)
    data["columns"] = vars(cols)
    path = out / "identification.json"
    path.write_text(json.dumps(_finite(data), indent=2))
    print(f"wrote {path}")
    return 0
