"""Identified models as TOML files that ``oceangnc run --model identified.toml`` takes as vehicle parameters.

Layout::

    [model]
    kind = "usv-first-order"          # or "submarine-vertical"
    method = "identify first-order"   # what produced it
    source = "runs/trials-.../log.parquet"
    created = "2026-11-23T09:00:00"
    confidence = 0.95

    [parameters]                       # dotted config keys, merged over the scenario's defaults
    "usv.kv_slope" = 0.000401
    ...

    [uncertainty."usv.kv_slope"]       # one table per identified coefficient
    estimate = 0.000401
    std_error = 1.2e-6
    ci95 = [0.000398, 0.000404]
    dof = 7                            # residual degrees of freedom (t quantile); 0 = normal quantile
    unit = "(m/s)/rpm per m/s"

Only ``[parameters]`` is applied by ``run``; ``--set`` still wins over it. Parameters that were not
identified (e.g. the trial speed ranges when the log has one speed) are not written, so the scenario's
defaults stay. The 95 % interval is ``estimate +- q std_error`` with q the Student-t quantile for
``dof`` residual degrees of freedom (the normal 1.96 when dof = 0, e.g. for an EKF's posterior sigma).
"""

from __future__ import annotations

import datetime as _dt
import math
from pathlib import Path

from ..errors import ConfigError


def quantile95(dof: int) -> float:
    """Two-sided 95 % quantile: Student t with ``dof`` degrees of freedom, normal (1.96) if dof <= 0."""
    if dof and dof > 0:
        from scipy.stats import t

        return float(t.ppf(0.975, dof))
    return 1.959963984540054


def entry(estimate: float, std_error: float, dof: int = 0, unit: str = "") -> dict:
    q = quantile95(dof)
    se = float(std_error) if std_error is not None and math.isfinite(std_error) else float("nan")
    return {
        "estimate": float(estimate),
        "std_error": se,
        "ci95": [float(estimate) - q * se, float(estimate) + q * se],
        "dof": int(dof),
        "unit": unit,
    }


def write_model(
    path, kind: str, method: str, source: str, parameters: dict, uncertainty: dict, notes: list[str] | None = None
) -> Path:
    """Write the model TOML (NaN standard errors are written as the string "nan": TOML has nan too)."""
    import tomli_w

    doc: dict = {
        "model": {
            "kind": kind,
            "method": method,
            "source": str(source),
            "created": _dt.datetime.now().isoformat(timespec="seconds"),
            "confidence": 0.95,
        },
        "parameters": {k: float(v) for k, v in parameters.items()},
        "uncertainty": {k: v for k, v in uncertainty.items()},
    }
    if notes:
        doc["model"]["notes"] = list(notes)
    p = Path(path)
    p.parent.mkdir(parents=True, exist_ok=True)
    p.write_text("# identified model: [parameters] is what `oceangnc run --model` applies\n" + tomli_w.dumps(doc))
    return p


def load_model_overrides(path) -> dict:
    """The ``[parameters]`` of a model file as dotted overrides (ConfigError if absent or malformed)."""
    from ..io.config import load_toml

    doc = load_toml(path)
    params = doc.get("parameters")
    if not isinstance(params, dict) or not params:
        raise ConfigError(
            f'model file {path}: no [parameters] table (expected dotted config keys, e.g. "usv.kr_intercept" = 0.71)'
        )
    bad = [k for k, v in params.items() if not isinstance(v, (int, float)) or isinstance(v, bool)]
    if bad:
        raise ConfigError(f"model file {path}: parameter {bad[0]} is not a number")
    return dict(params)
