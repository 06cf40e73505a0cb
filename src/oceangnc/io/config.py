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
from pathlib import Path
from typing import Any

from pydantic import (
    BaseModel,
    Field,
    model_validator,
)

from ..core.config import (  # noqa: F401  (re-exported: the configs' base and messages)
    MAX_COORD_M,
    MAX_LIST_VALUE,
    StrictModel,
    _field_info,
    _literal_choices,
    _one_line,
    describe_allowed,
    format_validation_error,
    validate,
)
from ..errors import ConfigError, InputError


#: the most physics steps (``sim.duration / sim.dt``) a run may take: every default ``dt`` (1 ms) up to the longest
#: ``sim.duration`` (10^6 s); 10^12 steps (``dt`` 1e-12 s for 1 s) was accepted and ran for days (issue 41)
MAX_STEPS = 1e9
#: physics steps a second of the fastest vehicle (usv-turn, fused loop, one core: 5e6 steps in 2.9 s measured on
#: the 2-core CI machine, 1.7e6/s), rounded up: the lower bound of a refused run's duration in the message
STEPS_PER_S = 2e6


class SimConfig(StrictModel):
    """Simulation clock settings."""

    duration: float = Field(60.0, gt=0, le=1e6, description="simulated time, s")
    dt: float = Field(0.001, gt=0, le=0.1, description="physics (RK4) step, s")
    log_rate: float = Field(20.0, gt=0, le=1000, description="logged rows per second, Hz")
    seed: int = Field(0, ge=0, le=2**63 - 1, description="seed of every random source of the run")

    @model_validator(mode="after")
    def _bounded_steps(self):
        """Refuse more than :data:`MAX_STEPS` physics steps (docs/reliability.md), saying how long they would take."""
        steps = self.duration / self.dt if self.dt > 0 else 0.0  # (dt <= 0: a console's idle config)
        if steps > MAX_STEPS:
            days = steps / STEPS_PER_S / 86400.0
            took = f"{days:.3g} days" if days >= 1.0 else f"{days * 24.0:.3g} h"
            raise ValueError(
                f"sim.duration / sim.dt = {self.duration:g} / {self.dt:g} = {steps:.3g} physics steps: more than the "
                f"{MAX_STEPS:.0e} a run may take (it would run at least {took}, at {STEPS_PER_S:.0e} steps/s, the "
                "fastest vehicle's rate on one core); raise sim.dt or shorten sim.duration"
            )
        return self


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


def parse_toml(text: str, where: str) -> dict:
    """Parse TOML text; a syntax error, or nesting too deep for the parser (an array nested 100,000
    levels), is a one-line ConfigError starting with ``where``."""
    try:
        return tomllib.loads(text)
    except tomllib.TOMLDecodeError as e:
        raise ConfigError(f"{where}: {e}") from None
    except RecursionError:
        raise ConfigError(f"{where}: nested too deeply to be a config") from None


def load_toml(path: str | Path, what: str = "config file") -> dict:
    """Read a TOML file, bounded (a regular file of at most 16 MiB of UTF-8,
    :func:`oceangnc.core.files.read_text_bounded`); a syntax error becomes a ConfigError naming the file
    and line."""
    from ..core.files import LIMIT_TOML, read_text_bounded

    p = Path(path)
    try:
        text = read_text_bounded(p, LIMIT_TOML, what)
    except InputError as e:  # a config error, as a syntax error is
        raise ConfigError(str(e)) from None
    return parse_toml(text, f"{what} {p}")


def parse_value(text: str) -> Any:
    """Parse the right-hand side of ``--set key=value`` as a TOML value, else keep it as a string."""
    try:
        return tomllib.loads(f"v = {text}")["v"]
    except tomllib.TOMLDecodeError:
        return text
    except RecursionError:
        raise ConfigError(f"--set value {text[:40]!r}...: nested too deeply") from None


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
    """Recursively merge ``over`` into a copy of ``base`` (dicts merge, everything else replaces; a block
    slot written as its kind, ``uuv = "backstepping"``, merges with parameters given for it)."""
    out = copy.deepcopy(base)
    for k, v in over.items():
        if isinstance(v, dict) and isinstance(out.get(k), str) and "kind" not in v:
            out[k] = {"kind": out[k]}  # a block slot given by its kind alone: its parameters join that kind
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


def to_dict(cfg: BaseModel) -> dict:
    """A config model as a plain dict (None values dropped, since TOML has no null)."""

    def drop_none(x):
        if isinstance(x, dict):
            return {k: drop_none(v) for k, v in x.items() if v is not None}
        if isinstance(x, (list, tuple)):
            return [drop_none(v) for v in x]
        return x

    return drop_none(cfg.model_dump(mode="json"))


def dump_toml(cfg: BaseModel, path: str | Path, extra: dict | None = None) -> None:
    """Write the fully resolved config as TOML, with the sections of ``extra`` (e.g. a MAVLink session's
    ``mavlink`` settings) added."""
    import tomli_w

    from ..core.files import atomic_write_text

    atomic_write_text(path, tomli_w.dumps({**to_dict(cfg), **(extra or {})}))  # never through a link at the name
