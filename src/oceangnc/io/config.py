"""Scenario configuration: TOML files validated by pydantic models, with dotted ``--set`` overrides.

Every config model derives from :class:`StrictModel` (unknown keys are rejected) and declares ranges
with ``Field(ge=..., le=...)``. :func:`resolve` merges, in order, the model's defaults, the scenario's
defaults, a TOML file and ``key=value`` overrides, validates once, and turns the first validation
error into a one-line :class:`~oceangnc.errors.ConfigError` that names the dotted key and the allowed
range, e.g. ``config error: environment.current.speed = 9.0: allowed range 0 <= value <= 5 (m/s)``.
"""

from __future__ import annotations

import copy
import tomllib
import typing
from pathlib import Path
from typing import Any, Literal

import annotated_types as at
from pydantic import (
    BaseModel,
    ConfigDict,
    Field,
    ValidationError,
    ValidationInfo,
    field_validator,
)

from ..errors import ConfigError

#: largest |coordinate| of a waypoint or route point (m): 10 000 km, more than any mission, small
#: enough that squared distances stay far from float overflow
MAX_COORD_M = 1e7
#: largest |value| inside any list of numbers of a config (gains tables, profiles)
MAX_LIST_VALUE = 1e12


def _walk_numbers(v, path=()):
    if isinstance(v, bool):
        return
    if isinstance(v, (int, float)):
        yield path, v
    elif isinstance(v, (list, tuple)):
        for i, x in enumerate(v):
            yield from _walk_numbers(x, (*path, i))


class StrictModel(BaseModel):
    """Base of all config sections: unknown keys are errors, assignments are validated, every float
    must be finite (NaN and inf are refused with "must be finite"), and numbers inside lists are
    bounded (:data:`MAX_COORD_M` for waypoint/route/point lists, :data:`MAX_LIST_VALUE` otherwise)."""

    model_config = ConfigDict(extra="forbid", validate_assignment=True, allow_inf_nan=False)

    @field_validator("*", mode="after")
    @classmethod
    def _bounded_lists(cls, v, info: ValidationInfo):
        if not isinstance(v, (list, tuple)):
            return v
        name = info.field_name or ""
        geo = any(w in name for w in ("waypoint", "route", "point"))
        lim = MAX_COORD_M if geo else MAX_LIST_VALUE
        for path, x in _walk_numbers(v):
            if abs(x) > lim:
                idx = "".join(f"[{i}]" for i in path)
                what = f"must be within +-{lim:g} m of the origin" if geo else f"must be within +-{lim:g}"
                raise ValueError(f"item {idx} = {x:g} {what}")
        return v


class SimConfig(StrictModel):
    """Simulation clock settings."""

    duration: float = Field(60.0, gt=0, le=1e6, description="simulated time, s")
    dt: float = Field(0.001, gt=0, le=0.1, description="physics (RK4) step, s")
    log_rate: float = Field(20.0, gt=0, le=1000, description="logged rows per second, Hz")
    seed: int = Field(0, ge=0, le=2**63 - 1, description="seed of every random source of the run")


class LogConfig(StrictModel):
    """Run log settings (crash safety: see :mod:`oceangnc.io.logs`)."""

    flush_period: float = Field(
        1.0, gt=0, le=3600, description="simulated time between log flushes, the most a crash can lose, s"
    )
    fsync: bool = Field(
        False, description="force each flushed part to disk (power-cut safety; about 10 ms per part on a busy disk)"
    )
    min_flush_wall_s: float = Field(
        0.25,
        ge=0,
        le=60,
        description="wall-clock time that must also pass between two flushes, so a run much faster than real "
        "time writes a few parts, not one per simulated second; a crash loses at most flush_period of "
        "simulated time or this much wall time, whichever is more, s",
    )


class ScenarioConfig(StrictModel):
    """Base of every scenario's config: the scenario name, the clock and the log."""

    scenario: str = Field("", description="scenario name (set by the registry)")
    sim: SimConfig = SimConfig()
    log: LogConfig = LogConfig()


# -- loading and merging ------------------------------------------------------------------------------


def load_toml(path: str | Path) -> dict:
    """Read a TOML file; a syntax error becomes a ConfigError naming the file and line."""
    p = Path(path)
    if not p.is_file():
        raise ConfigError(f"config file not found: {p}")
    try:
        return tomllib.loads(p.read_text())
    except tomllib.TOMLDecodeError as e:
        raise ConfigError(f"config file {p}: {e}") from None


def parse_value(text: str) -> Any:
    """Parse the right-hand side of ``--set key=value`` as a TOML value, else keep it as a string."""
    try:
        return tomllib.loads(f"v = {text}")["v"]
    except tomllib.TOMLDecodeError:
        return text


def parse_sets(items: list[str] | None) -> dict:
    """Turn ``["a.b=1", "c=x"]`` into a nested dict ``{"a": {"b": 1}, "c": "x"}``."""
    out: dict = {}
    for item in items or []:
        if "=" not in item:
            raise ConfigError(f"--set {item!r}: expected key=value (e.g. environment.current.speed=0.5)")
        key, val = item.split("=", 1)
        key = key.strip()
        if not key or any(not part for part in key.split(".")):
            raise ConfigError(f"--set {item!r}: empty key")
        set_dotted(out, key, parse_value(val.strip()))
    return out


def set_dotted(d: dict, key: str, value: Any) -> None:
    """Set ``d["a"]["b"] = value`` for key ``"a.b"``, creating levels."""
    parts = key.split(".")
    cur = d
    for p in parts[:-1]:
        nxt = cur.get(p)
        if not isinstance(nxt, dict):
            nxt = {}
            cur[p] = nxt
        cur = nxt
    cur[parts[-1]] = value


def deep_merge(base: dict, over: dict) -> dict:
    """Recursively merge ``over`` into a copy of ``base`` (dicts merge, everything else replaces)."""
    out = copy.deepcopy(base)
    for k, v in over.items():
        if isinstance(v, dict) and isinstance(out.get(k), dict):
            out[k] = deep_merge(out[k], v)
        else:
            out[k] = copy.deepcopy(v)
    return out


def flatten(d: dict, prefix: str = "") -> dict:
    """Nested dict -> flat dict with dotted keys."""
    out = {}
    for k, v in d.items():
        key = f"{prefix}{k}"
        if isinstance(v, dict):
            out.update(flatten(v, key + "."))
        else:
            out[key] = v
    return out


# -- error messages -------------------------------------------------------------------------------------


def _field_info(model: type[BaseModel], loc: tuple):
    """Walk ``loc`` through nested models; return (FieldInfo, parent model) or (None, model)."""
    cur: Any = model
    info = None
    for part in loc:
        if isinstance(part, int):
            continue
        if not (isinstance(cur, type) and issubclass(cur, BaseModel)) or part not in cur.model_fields:
            return None, cur
        info = cur.model_fields[part]
        ann = info.annotation
        nxt = None
        for cand in (ann, *typing.get_args(ann)):
            if isinstance(cand, type) and issubclass(cand, BaseModel):
                nxt = cand
                break
            for sub in typing.get_args(cand):
                if isinstance(sub, type) and issubclass(sub, BaseModel):
                    nxt = sub
        cur = nxt if nxt is not None else ann
    return info, cur


def describe_allowed(model: type[BaseModel], loc: tuple) -> str:
    """Human text of what a field accepts: its range, its choices or its type."""
    info, _ = _field_info(model, loc)
    if info is None:
        return ""
    lo = hi = None
    lo_s = hi_s = ""
    nmin = nmax = None
    for m in info.metadata:
        if isinstance(m, at.Ge):
            lo, lo_s = m.ge, "<="
        elif isinstance(m, at.Gt):
            lo, lo_s = m.gt, "<"
        elif isinstance(m, at.Le):
            hi, hi_s = m.le, "<="
        elif isinstance(m, at.Lt):
            hi, hi_s = m.lt, "<"
        elif isinstance(m, at.MinLen):
            nmin = m.min_length
        elif isinstance(m, at.MaxLen):
            nmax = m.max_length
    unit = f" ({info.description.split(',')[-1].strip()})" if info.description and "," in info.description else ""
    choices = _literal_choices(info.annotation)
    if choices:
        return "allowed values: " + ", ".join(repr(c) for c in choices)
    if isinstance(info.annotation, type) and issubclass(info.annotation, BaseModel):
        return ""  # a whole section: a model-level validator's own message says what is wrong
    if nmin is not None or nmax is not None:
        if nmin is not None and nmax is not None:
            return f"allowed length {nmin} to {nmax} items"
        return f"allowed length at least {nmin} items" if nmin is not None else f"allowed length at most {nmax} items"
    if lo is not None or hi is not None:
        left = f"{lo:g} {lo_s} " if isinstance(lo, (int, float)) else ""
        right = f" {hi_s} {hi:g}" if isinstance(hi, (int, float)) else ""
        return f"allowed range {left}value{right}{unit}"
    return f"expected {getattr(info.annotation, '__name__', str(info.annotation))}{unit}"


def _literal_choices(ann) -> list:
    if typing.get_origin(ann) is Literal:
        return list(typing.get_args(ann))
    for a in typing.get_args(ann):
        if typing.get_origin(a) is Literal:
            return list(typing.get_args(a))
    return []


def format_validation_error(model: type[BaseModel], err: ValidationError) -> str:
    """One line for the first error of a pydantic ValidationError, naming the dotted key."""
    errors = err.errors()
    e = errors[0]
    loc = tuple(p for p in e["loc"] if not (isinstance(p, str) and p.startswith("function-")))
    key = ".".join(str(p) for p in loc)
    more = f" (and {len(errors) - 1} more error(s))" if len(errors) > 1 else ""
    if e["type"] == "extra_forbidden":
        _, parent = _field_info(model, loc[:-1]) if len(loc) > 1 else (None, model)
        allowed = ""
        if isinstance(parent, type) and issubclass(parent, BaseModel):
            allowed = "; allowed keys: " + ", ".join(parent.model_fields)
        return _one_line(f"config error: unknown key {key!r}{allowed}{more}")
    allowed = describe_allowed(model, loc)
    val = e.get("input")
    shown = "" if isinstance(val, dict) else f" = {val!r}"
    if len(shown) > 80:
        shown = shown[:77] + "..."
    if any(isinstance(p, int) for p in loc) or e["type"] == "value_error":
        allowed = ""  # an item of a list, or a validator's own message: the range of the list is noise
    if e["type"] == "finite_number":
        msg = "must be finite"
    elif e["type"] in ("too_short", "too_long") and isinstance(val, (list, tuple)):
        msg = f"{len(val)} item(s)"
    elif e["type"] == "value_error" and e["msg"].startswith("Value error, "):
        msg = e["msg"][len("Value error, ") :]
    else:
        msg = e["msg"][0].lower() + e["msg"][1:]
    tail = f"; {allowed}" if allowed else ""
    return _one_line(f"config error: {key}{shown}: {msg}{tail}{more}")


def _one_line(text: str) -> str:
    return text.replace("\r", "\\r").replace("\n", "\\n")


def validate(model: type[BaseModel], data: dict):
    """Validate ``data`` against ``model``; raise a one-line ConfigError on failure."""
    try:
        return model.model_validate(data)
    except ValidationError as err:
        raise ConfigError(format_validation_error(model, err)) from None


def to_dict(cfg: BaseModel) -> dict:
    """A config model as a plain dict (None values dropped, since TOML has no null)."""

    def drop_none(x):
        if isinstance(x, dict):
            return {k: drop_none(v) for k, v in x.items() if v is not None}
        if isinstance(x, (list, tuple)):
            return [drop_none(v) for v in x]
        return x

    return drop_none(cfg.model_dump(mode="json"))


def dump_toml(cfg: BaseModel, path: str | Path) -> None:
    """Write the fully resolved config as TOML."""
    import tomli_w

    Path(path).write_text(tomli_w.dumps(to_dict(cfg)))
