"""Base of every configuration model and its one-line error messages (issue 25: the configs' base
classes live in the core, which the scenario configs in :mod:`oceangnc.io.config` and every block's
parameter model build on)."""

from __future__ import annotations

import typing
from typing import Any, Literal

import annotated_types as at
from pydantic import BaseModel, ConfigDict, ValidationError, ValidationInfo, field_validator

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
    lo: Any = None
    hi: Any = None
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
