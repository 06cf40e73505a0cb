"""``oceangnc identify ekf LOG --model submarine-vertical --estimate Zw,Zwdot,...``.

Reads a Parquet (or CSV) log with a time column ``t``, the model's measurement columns
``<prefix>.<name>`` (for ``submarine-vertical``: ``sub.w`` m/s, ``sub.theta`` rad, ``sub.q`` rad/s)
and input columns (``sub.ds`` rad, held over each sample interval), runs the augmented-state EKF
(:mod:`oceangnc.identification.ekf`) and prints a table of the estimates with their 1-sigma; writes,
into the run folder ``--out`` (default ``runs/identify-ekf-<time>``), the same as JSON
(``ekf_<model>.json``) and the model file ``identified.toml`` (estimates, standard errors = the
posterior 1-sigma, 95 % intervals) for ``oceangnc run --model``. Field logs (.bin, .tlog, .ulg, ROS 2
bags, CSV with ``--map``) are imported on the fly (:mod:`oceangnc.io.importers`).

Identification that cannot cheat: by default the initial guesses are *half* the model's nominal values
(``--initial-scale 0.5``), because the nominal values are the ones the example data (``ekf-zigzag``)
were made with; starting there, the filter "converges" without moving. The output says where it
started, and warns for every coefficient whose estimate never left its initial value (moved by less
than 0.1 of its initial 1-sigma and its sigma shrank by less than 10 %): such a coefficient is not
identified by the log.

A log that cannot identify the parameters is refused before the filter runs (one line, exit 2;
``--skip-check excitation|condition`` runs it anyway, with a warning): the Cramer-Rao bound of each
parameter from the open-loop sensitivity of the measurements along the log, and the conditioning of the
information matrix (:mod:`oceangnc.identification.ekf_checks`).

Tuning defaults: measurement sigma estimated from the log (second differences: for white noise
e_k, Var(e_k+1 - 2 e_k + e_k-1) = 6 sigma^2; floor 1e-5 x the channel's RMS), initial state = first
sample with 2-sigma uncertainty, initial guesses = 0.5 x the model's nominal values (``--initial``,
``--initial-scale`` to change), P0 = (``--p0-rel`` x |guess|)^2, Q = ``--q-rel`` x R per second on the states, 0 on the
parameters.
"""

from __future__ import annotations

import json
import time
from pathlib import Path

import numpy as np

from ..errors import ConfigError, InputError
from .ekf import get_model, resolve_estimate, run_ekf
from .ekf_checks import identifiability


def _parse_kv(text: str | None, what: str) -> dict[str, float]:
    out: dict[str, float] = {}
    for item in (text or "").split(","):
        item = item.strip()
        if not item:
            continue
        if "=" not in item:
            raise InputError(f"{what}: expected name=value pairs, got {item!r}")
        k, v = item.split("=", 1)
        try:
            out[k.strip()] = float(v)
        except ValueError:
            raise InputError(f"{what}: {item!r} is not a number") from None
    return out


def noise_sigma_from_data(z: np.ndarray) -> np.ndarray:
    """White-noise sigma of each column of ``z`` from second differences (floor 1e-5 x RMS)."""
    out = np.zeros(z.shape[1])
    for i in range(z.shape[1]):
        c = z[:, i]
        c = c[np.isfinite(c)]
        if c.size < 5:
            raise InputError(f"measurement column {i} has fewer than 5 finite samples")
        d2 = c[2:] - 2.0 * c[1:-1] + c[:-2]
        rms = float(np.sqrt(np.mean(c * c)))
        out[i] = max(float(np.std(d2)) / np.sqrt(6.0), 1e-5 * rms, 1e-12)
    return out


DEFAULT_INITIAL_SCALE = 0.5


def identify_log(
    path,
    model_name: str,
    estimate,
    prefix: str = "sub",
    initial: dict | None = None,
    initial_scale: float = DEFAULT_INITIAL_SCALE,
    p0_rel: float = 0.3,
    r_sigma=None,
    q_rel: float = 2.5e-5,
    passes: int = 1,
    substeps: int = 1,
    jacobian: str | None = None,
    source: dict | None = None,
    skip_checks=(),
) -> dict:
    """Identify ``estimate`` from a log; returns a JSON-able dict (see module docstring).

    ``source``: options of :func:`oceangnc.io.importers.read_any` for field logs. Before the filter runs the
    log is checked for excitation and identifiability (:mod:`oceangnc.identification.ekf_checks`); a failed
    check is an InputError (one line) unless its name is in ``skip_checks`` (then a warning).
    """
    from ..io.importers import read_any

    model = get_model(model_name)
    idx = resolve_estimate(model, estimate)
    names = [model.param_names[i] for i in idx]
    zcols = [f"{prefix}.{k}" for k in model.measurement_names]
    ucols = [f"{prefix}.{k}" for k in model.input_names]
    df = read_any(path, **dict(source or {}))
    if len(df) == 0:
        raise InputError(f"{path}: the log has 0 rows; nothing to identify")
    missing = [c for c in ["t", *zcols, *ucols] if c not in df.columns]
    if missing:
        raise InputError(
            f"log {path} has no column(s) {', '.join(missing)} needed by model {model.name} "
            f"(prefix '{prefix}'); it has: {', '.join(map(str, df.columns[:12]))}"
            f"{' ...' if len(df.columns) > 12 else ''}"
        )
    if len(df) < 3:
        raise InputError(f"log {path} has {len(df)} rows; need at least 3")
    t = df["t"].to_numpy(dtype=float)
    Z = df[zcols].to_numpy(dtype=float)
    U = df[ucols].to_numpy(dtype=float)
    if not np.all(np.isfinite(Z[0])):
        raise InputError("the first sample must hold every measurement (it is the initial state)")
    if not (initial_scale > 0):
        raise ConfigError("--initial-scale must be positive")
    if not (p0_rel > 0):
        raise ConfigError("--p0-rel must be positive")
    if q_rel < 0:
        raise ConfigError("--q-rel must be >= 0")
    if passes < 1 or substeps < 1:
        raise ConfigError("--passes and --substeps must be >= 1")
    init = dict(initial or {})
    bad = [k for k in init if k not in names]
    if bad:
        raise InputError(f"--initial names {', '.join(bad)} are not estimated (estimating {', '.join(names)})")
    a0 = np.array([init.get(k, model.params[i] * initial_scale) for k, i in zip(names, idx)])
    if r_sigma is None:
        sd = noise_sigma_from_data(Z)
    else:
        sd = np.asarray(r_sigma, dtype=float)
        if sd.size != len(zcols):
            raise InputError(f"--r-sigma needs {len(zcols)} values ({', '.join(zcols)})")
        if not np.all(sd > 0):
            raise ConfigError("R is not positive definite: every --r-sigma value must be > 0")
    R = sd**2
    P0 = np.concatenate([(2.0 * sd) ** 2, (p0_rel * np.abs(a0)) ** 2])
    Q = np.concatenate([q_rel * R, np.zeros(len(names))])
    if np.any(a0 == 0):
        zero = [k for k, v in zip(names, a0) if v == 0]
        raise ConfigError(
            f"P0 is not positive definite: initial guess 0 for {', '.join(zero)} gives a zero "
            "variance; give a non-zero --initial"
        )
    checks, fails = identifiability(model, t, Z, U, idx, names, a0, sd)
    kept = [f for f in fails if f.split(":", 1)[0] not in skip_checks]
    if kept:
        raise InputError(f"log {path}: {kept[0]} (--skip-check {kept[0].split(':', 1)[0]} to run anyway)")
    x0 = Z[0]
    t0 = time.perf_counter()
    a = a0
    res = None
    for _ in range(passes):
        res = run_ekf(model, t, Z, U, names, x0, a, P0, Q, R, substeps=substeps, jacobian=jacobian)
        a = res.X[-1, len(model.state_names) :]
    wall = time.perf_counter() - t0
    fin = res.final()
    sig0 = p0_rel * np.abs(a0)
    stuck = [k for i, k in enumerate(names) if abs(fin[k][0] - a0[i]) < 0.1 * sig0[i] and fin[k][1] > 0.9 * sig0[i]]
    nominal = [float(model.params[i]) for i in idx]
    at_nominal = [k for k, a, nom in zip(names, a0, nominal) if nom != 0 and abs(a - nom) <= 1e-12 * abs(nom)]
    return {
        "initial_guess": {
            "rule": "explicit --initial"
            if init and len(init) == len(names)
            else f"{initial_scale:g} x the model's nominal values"
            + (" (with --initial for " + ", ".join(init) + ")" if init else ""),
            "at_nominal": at_nominal,
        },
        "warnings": [
            f"{k} never left its initial value {a0[names.index(k)]:.6g} (not identified by this log)" for k in stuck
        ]
        + [f"check skipped by --skip-check: {f}" for f in fails]
        + ([f"identifiability not checked: {checks['skipped']}"] if "skipped" in checks else [])
        + checks.get("warnings", []),
        "checks": checks,
        "model": model.name,
        "log": str(path),
        "samples": int(t.size),
        "duration_s": float(t[-1] - t[0]),
        "measurement_sigma": {c: float(s) for c, s in zip(zcols, sd)},
        "passes": passes,
        "wall_time_s": wall,
        "mean_nis": float(np.nanmean(res.nis)),
        "nis_dof": len(zcols),
        "parameters": {
            k: {"initial": float(a0[i]), "estimate": fin[k][0], "sigma": fin[k][1]} for i, k in enumerate(names)
        },
    }


def _cmd(args) -> int:
    r_sigma = None
    if args.r_sigma:
        try:
            r_sigma = [float(v) for v in args.r_sigma.split(",")]
        except ValueError:
            raise InputError(f"--r-sigma {args.r_sigma!r}: expected comma-separated numbers") from None
    from ..io.importers.cli import source_options

    out = identify_log(
        args.log,
        args.model,
        args.estimate,
        prefix=args.prefix,
        initial=_parse_kv(args.initial, "--initial"),
        initial_scale=args.initial_scale,
        p0_rel=args.p0_rel,
        r_sigma=r_sigma,
        q_rel=args.q_rel,
        passes=args.passes,
        substeps=args.substeps,
        jacobian=args.jacobian,
        source=source_options(args),
        skip_checks=tuple(args.skip_check or ()),
    )
    ig = out["initial_guess"]
    print(
        f"initial guesses: {ig['rule']}"
        + ("" if ig["at_nominal"] else " - not the nominal values that example data are simulated with")
    )
    if ig["at_nominal"]:
        print(
            f"warning: the initial guess of {', '.join(ig['at_nominal'])} is the model's nominal value; on data "
            f"simulated with the nominal model the filter starts at the truth"
        )
    print(
        f"model {out['model']}: {out['samples']} samples over {out['duration_s']:.2f} s, "
        f"filter {out['wall_time_s']:.2f} s, mean NIS {out['mean_nis']:.2f} (expect {out['nis_dof']})"
    )
    print(f"  {'parameter':<10} {'initial':>13} {'estimate':>13} {'1-sigma':>11} {'sigma/|est|':>11}")
    for k, v in out["parameters"].items():
        rel = v["sigma"] / abs(v["estimate"]) if v["estimate"] != 0 else float("inf")
        print(f"  {k:<10} {v['initial']:>13.6g} {v['estimate']:>13.6g} {v['sigma']:>11.3g} {rel:>10.2%}")
    for w in out["warnings"]:
        print(f"warning: {w}")
    from ..api import new_run_dir
    from .model_file import entry, write_model

    folder = Path(args.out) if args.out else new_run_dir("runs", "identify-ekf")
    if folder.suffix.lower() == ".json":
        raise InputError(f"--out {folder}: --out is a run folder (like oceangnc run), not a file name")
    folder.mkdir(parents=True, exist_ok=True)
    dest = folder / f"ekf_{out['model']}.json"
    dest.write_text(json.dumps(out, indent=2))
    print(f"wrote {dest}")
    params = {f"{MODEL_SECTION.get(out['model'], 'vehicle')}.{k}": v["estimate"] for k, v in out["parameters"].items()}
    unc = {
        f"{MODEL_SECTION.get(out['model'], 'vehicle')}.{k}": entry(v["estimate"], v["sigma"], 0)
        for k, v in out["parameters"].items()
    }
    mp = write_model(
        folder / "identified.toml",
        out["model"],
        "identify ekf",
        args.log,
        params,
        unc,
        [f"initial guesses: {ig['rule']}", *out["warnings"]],
    )
    print(f"wrote {mp}")
    return 0


#: config section holding a model's coefficients in the scenarios that simulate it
MODEL_SECTION = {"submarine-vertical": "vehicle"}


def register(sub) -> None:
    p = sub.add_parser(
        "ekf",
        help="hydrodynamic coefficients by augmented-state EKF (document 002)",
        description="Identify model parameters from a log with the continuous-discrete "
        "augmented-state extended Kalman filter.",
    )
    p.add_argument("log", help="log.parquet / .csv, or a run folder holding log.parquet")
    p.add_argument(
        "--model", default="submarine-vertical", help="model name (registered models: an unknown name lists them)"
    )
    p.add_argument("--estimate", required=True, help="comma-separated parameter names, e.g. Zw,Zwdot,Mq")
    p.add_argument("--prefix", default="sub", help="column prefix of measurements and inputs (default sub)")
    p.add_argument("--initial", help="initial guesses name=value,... (default: --initial-scale x nominal values)")
    p.add_argument(
        "--initial-scale",
        type=float,
        default=DEFAULT_INITIAL_SCALE,
        help="initial guesses = this x the model's nominal values (default 0.5: the nominal values "
        "are what the example data were simulated with, so 1 would start at the truth)",
    )
    p.add_argument("--p0-rel", type=float, default=0.3, help="initial 1-sigma relative to each guess")
    p.add_argument("--r-sigma", help="measurement sigmas (SI, comma-separated); default estimated from the log")
    p.add_argument("--q-rel", type=float, default=2.5e-5, help="state process noise, units of R per second")
    p.add_argument("--passes", type=int, default=1, help="passes over the record")
    p.add_argument("--substeps", type=int, default=1, help="RK4 steps per sample interval")
    p.add_argument("--jacobian", choices=["analytic", "complex-step", "finite-difference"])
    p.add_argument(
        "--skip-check",
        action="append",
        choices=["excitation", "condition"],
        help="run the filter although the log fails this identifiability check (repeatable; a warning instead)",
    )
    p.add_argument(
        "--out", help="run folder for ekf_<model>.json and identified.toml (default: runs/identify-ekf-<time>)"
    )
    from ..io.importers.cli import add_source_options

    add_source_options(p)
    p.set_defaults(func=_cmd)
