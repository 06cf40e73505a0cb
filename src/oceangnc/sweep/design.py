"""Sweep designs: the list of runs of a grid or Monte Carlo sweep, each with a stable identity.

A sweep varies config keys (dotted paths, the same as ``oceangnc run --set``) over

* a **grid**: ``--grid key=v1,v2,...`` per key (values parsed as TOML, so ``0.5``, ``3``, ``true``,
  ``"thrust"``; ``linspace(a,b,n)`` gives ``n`` evenly spaced values). Every combination of the
  keys' values is one *point*, in the order the keys were given (the last key varies fastest);
* **random draws**: ``--random key=dist(...)`` with ``--samples N``: ``N`` points whose values are
  drawn from ``uniform(a,b)``, ``loguniform(a,b)``, ``normal(mu,sigma)``, ``randint(a,b)``
  (integers ``a..b`` inclusive) or ``choice(v1,v2,...)``. The draws of key ``k`` come from their own
  generator ``numpy.random.default_rng([design_seed, h(k)])`` with ``h`` the first 8 bytes of
  SHA-256 of the key, so adding a key or a sample never changes the other keys' draws and the
  same command draws the same values again (which ``--resume`` relies on).
  With both a grid and random keys, every grid point is combined with every draw.

Each point is run ``K`` times (``--seeds K``): run ``k = 0..K-1`` of a point sets
``sim.seed = base_seed + k``, ``base_seed`` being ``--base-seed`` or the config's ``sim.seed``
(0 unless set). ``sim.seed`` itself therefore cannot be swept.

A run is identified by ``run_id``, the first 16 hex digits of SHA-256 of the canonical JSON
(sorted keys) of ``{scenario, config file content, fixed overrides, swept values, seed}``; the point
by ``point_id``, the same hash without the seed. Both are stable across processes, machines and
Python versions, so a resumed sweep recognises the runs it already has.
"""

from __future__ import annotations

import hashlib
import itertools
import json
import math
import re
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from ..errors import ConfigError
from ..io.config import parse_value

RESERVED_KEYS = ("sim.seed", "scenario")
DISTRIBUTIONS = ("uniform", "loguniform", "normal", "randint", "choice")
MAX_RUNS = 1_000_000


def split_top(text: str, sep: str = ",") -> list[str]:
    """Split ``text`` at ``sep`` outside brackets, parentheses and quotes (``[1,2],3`` -> 2 items)."""
    parts, depth, quote, cur = [], 0, "", []
    for ch in text:
        if quote:
            cur.append(ch)
            if ch == quote:
                quote = ""
            continue
        if ch in "\"'":
            quote = ch
        elif ch in "[({":
            depth += 1
        elif ch in "])}":
            depth -= 1
        elif ch == sep and depth == 0:
            parts.append("".join(cur).strip())
            cur = []
            continue
        cur.append(ch)
    parts.append("".join(cur).strip())
    return parts


def _split_key(item: str, flag: str) -> tuple[str, str]:
    if "=" not in item:
        raise ConfigError(f"{flag} {item!r}: expected key=values (e.g. environment.current.speed=0.2,0.5)")
    key, val = item.split("=", 1)
    key = key.strip()
    if not key or any(not p for p in key.split(".")):
        raise ConfigError(f"{flag} {item!r}: empty key")
    if key in RESERVED_KEYS:
        what = "use --seeds K and --base-seed S" if key == "sim.seed" else "give the scenario as the first argument"
        raise ConfigError(f"{flag} {key}: this key cannot be swept; {what}")
    if not val.strip():
        raise ConfigError(f"{flag} {key}: no values given")
    return key, val.strip()


_CALL = re.compile(r"^\s*([a-z_]+)\s*\((.*)\)\s*$", re.S)


def _number(text: str, what: str) -> float:
    v = parse_value(text)
    if isinstance(v, bool) or not isinstance(v, (int, float)) or not math.isfinite(v):
        raise ConfigError(f"{what}: {text!r} is not a finite number")
    return v


def parse_grid_values(key: str, text: str) -> list:
    """Values of ``--grid key=TEXT``: a comma list of TOML values or ``linspace(start, stop, n)``."""
    m = _CALL.match(text)
    if m and m.group(1) == "linspace":
        args = split_top(m.group(2))
        if len(args) != 3:
            raise ConfigError(f"--grid {key}: linspace needs (start, stop, n), got {text!r}")
        a, b = (_number(x, f"--grid {key}") for x in args[:2])
        n = _number(args[2], f"--grid {key}")
        if n != int(n) or not 1 <= n <= 100_000:
            raise ConfigError(f"--grid {key}: linspace n = {args[2]}: expected an integer 1..100000")
        return [float(v) for v in np.linspace(a, b, int(n))]
    vals = [parse_value(v) for v in split_top(text)]
    if any(v == "" for v in vals):
        raise ConfigError(f"--grid {key}={text}: empty value in the list")
    return vals


def parse_grid(items: list[str] | dict | None) -> dict[str, list]:
    """``["a=1,2", "b=x,y"]`` (or a dict key -> list) -> ordered dict key -> list of values."""
    out: dict[str, list] = {}
    if isinstance(items, dict):
        it = [(k, list(v) if isinstance(v, (list, tuple)) else [v]) for k, v in items.items()]
        for k, _ in it:
            _split_key(f"{k}=x", "--grid")
    else:
        it = []
        for item in items or []:
            k, text = _split_key(item, "--grid")
            it.append((k, parse_grid_values(k, text)))
    for k, vals in it:
        if k in out:
            raise ConfigError(f"--grid {k}: key given twice")
        if not vals:
            raise ConfigError(f"--grid {k}: no values given")
        out[k] = vals
    return out


@dataclass(frozen=True)
class Distribution:
    """One ``--random`` distribution: ``kind`` and its arguments (see the module docstring)."""

    kind: str
    args: tuple

    def text(self) -> str:
        return f"{self.kind}({', '.join(json.dumps(a) for a in self.args)})"

    def draw(self, rng: np.random.Generator, n: int) -> list:
        """``n`` draws as plain Python values."""
        a = self.args
        if self.kind == "uniform":
            return [float(v) for v in rng.uniform(a[0], a[1], n)]
        if self.kind == "loguniform":
            return [float(v) for v in np.exp(rng.uniform(math.log(a[0]), math.log(a[1]), n))]
        if self.kind == "normal":
            return [float(v) for v in rng.normal(a[0], a[1], n)]
        if self.kind == "randint":
            return [int(v) for v in rng.integers(a[0], a[1], n, endpoint=True)]
        idx = rng.integers(0, len(a), n)
        return [a[i] for i in idx]


def parse_distribution(key: str, text: str) -> Distribution:
    """Parse ``uniform(a,b)`` etc.; bad names or arguments give a ConfigError naming the key."""
    where = f"--random {key}"
    m = _CALL.match(text)
    if not m or m.group(1) not in DISTRIBUTIONS:
        raise ConfigError(f"{where}={text}: expected one of " + ", ".join(f"{d}(...)" for d in DISTRIBUTIONS))
    kind, args = m.group(1), split_top(m.group(2))
    if kind == "choice":
        vals = tuple(parse_value(v) for v in args if v)
        if not vals:
            raise ConfigError(f"{where}: choice needs at least one value")
        return Distribution(kind, vals)
    if len(args) != 2:
        raise ConfigError(f"{where}: {kind} needs 2 arguments, got {text!r}")
    a, b = (_number(x, where) for x in args)
    if kind in ("uniform", "randint") and not a <= b:
        raise ConfigError(f"{where}: {kind}(a, b) needs a <= b, got {text!r}")
    if kind == "randint" and (a != int(a) or b != int(b)):
        raise ConfigError(f"{where}: randint bounds must be integers, got {text!r}")
    if kind == "loguniform" and not 0 < a <= b:
        raise ConfigError(f"{where}: loguniform(a, b) needs 0 < a <= b, got {text!r}")
    if kind == "normal" and not b >= 0:
        raise ConfigError(f"{where}: normal(mu, sigma) needs sigma >= 0, got {text!r}")
    if kind == "randint":
        a, b = int(a), int(b)
    return Distribution(kind, (a, b))


def parse_random(items: list[str] | dict | None) -> dict[str, Distribution]:
    """``["a=uniform(0,1)"]`` (or a dict key -> text) -> ordered dict key -> Distribution."""
    pairs = list(items.items()) if isinstance(items, dict) else [_split_key(i, "--random") for i in items or []]
    out: dict[str, Distribution] = {}
    for k, text in pairs:
        _split_key(f"{k}=x", "--random")
        if k in out:
            raise ConfigError(f"--random {k}: key given twice")
        out[k] = text if isinstance(text, Distribution) else parse_distribution(k, str(text))
    return out


def stable_hash(obj: Any, n: int = 16) -> str:
    """First ``n`` hex digits of SHA-256 of the canonical JSON of ``obj`` (sorted keys, repr floats)."""
    s = json.dumps(obj, sort_keys=True, separators=(",", ":"), allow_nan=True, default=str)
    return hashlib.sha256(s.encode()).hexdigest()[:n]


def _key_seed(key: str) -> int:
    return int.from_bytes(hashlib.sha256(key.encode()).digest()[:8], "little")


@dataclass(frozen=True)
class RunSpec:
    """One run of a sweep.

    Attributes
    ----------
    index : int
        Position in the design (points in order, seeds innermost).
    point : int
        Index of the grid point / random draw.
    params : dict
        The swept keys' values of this run (dotted key -> value).
    seed : int
        ``sim.seed`` of this run (``base_seed + k``).
    run_id, point_id : str
        Stable hashes (see the module docstring).
    """

    index: int
    point: int
    params: dict
    seed: int
    run_id: str
    point_id: str

    def overrides(self, fixed: dict) -> dict:
        """The dotted overrides passed to :func:`oceangnc.api.run`: fixed, swept, then the seed."""
        return {**fixed, **self.params, "sim.seed": self.seed}


@dataclass
class Design:
    """A sweep's definition; :meth:`runs` expands it into :class:`RunSpec` objects.

    ``fixed`` are dotted overrides applied to every run (``--set``, ``--duration``); ``config`` a
    TOML-derived dict merged over the scenario defaults (``--config``).
    """

    scenario: str
    grid: dict[str, list] = field(default_factory=dict)
    random: dict[str, Distribution] = field(default_factory=dict)
    samples: int = 0
    seeds: int = 1
    base_seed: int = 0
    design_seed: int = 0
    fixed: dict = field(default_factory=dict)
    config: dict | None = None

    def __post_init__(self):
        if self.seeds < 1:
            raise ConfigError(f"--seeds {self.seeds}: need at least 1")
        if self.random and self.samples < 1:
            raise ConfigError("--random needs --samples N (N >= 1 draws)")
        if self.samples and not self.random:
            raise ConfigError("--samples needs at least one --random key=dist(...)")
        both = set(self.grid) & set(self.random)
        if both:
            raise ConfigError(f"key {sorted(both)[0]} is given both as --grid and --random")
        clash = set(self.fixed) & (set(self.grid) | set(self.random))
        if clash:
            raise ConfigError(f"key {sorted(clash)[0]} is both fixed (--set/--duration) and swept")
        if not 0 <= self.base_seed or self.base_seed + self.seeds - 1 > 2**63 - 1:
            raise ConfigError(f"--base-seed {self.base_seed}: seeds must lie in 0..2**63-1")
        n = self.n_points() * self.seeds
        if n > MAX_RUNS:
            raise ConfigError(f"sweep of {n} runs is larger than the limit of {MAX_RUNS}")

    @property
    def keys(self) -> list[str]:
        """The swept keys, grid keys first."""
        return [*self.grid, *self.random]

    def n_points(self) -> int:
        n = math.prod(len(v) for v in self.grid.values()) if self.grid else 1
        return n * (self.samples if self.random else 1)

    def points(self) -> list[dict]:
        """Every point (dotted key -> value) in design order."""
        grid_pts = [dict(zip(self.grid, combo)) for combo in itertools.product(*self.grid.values())] or [{}]
        if not self.random:
            return grid_pts
        draws = {
            k: d.draw(np.random.default_rng([self.design_seed, _key_seed(k)]), self.samples)
            for k, d in self.random.items()
        }
        rand_pts = [{k: draws[k][i] for k in self.random} for i in range(self.samples)]
        return [{**g, **r} for g in grid_pts for r in rand_pts]

    def identity(self) -> dict:
        """What makes runs of this sweep the same runs: everything but the swept values and seed."""
        return {"scenario": self.scenario, "config": self.config or {}, "fixed": self.fixed}

    def runs(self) -> list[RunSpec]:
        """All runs: each point with seeds ``base_seed .. base_seed + seeds - 1``."""
        ident = self.identity()
        out = []
        for p, params in enumerate(self.points()):
            point_id = stable_hash({**ident, "params": params})
            for k in range(self.seeds):
                seed = self.base_seed + k
                out.append(
                    RunSpec(len(out), p, params, seed, stable_hash({**ident, "params": params, "seed": seed}), point_id)
                )
        return out

    def to_json(self) -> dict:
        """JSON-able description (stored as ``sweep.json`` in the sweep folder)."""
        return {
            "scenario": self.scenario,
            "grid": self.grid,
            "random": {k: d.text() for k, d in self.random.items()},
            "samples": self.samples,
            "seeds": self.seeds,
            "base_seed": self.base_seed,
            "design_seed": self.design_seed,
            "fixed": self.fixed,
            "config": self.config,
        }

    @classmethod
    def from_json(cls, d: dict) -> "Design":
        return cls(
            scenario=d["scenario"],
            grid=parse_grid(d.get("grid") or {}),
            random=parse_random(d.get("random") or {}),
            samples=int(d.get("samples", 0)),
            seeds=int(d.get("seeds", 1)),
            base_seed=int(d.get("base_seed", 0)),
            design_seed=int(d.get("design_seed", 0)),
            fixed=dict(d.get("fixed") or {}),
            config=d.get("config"),
        )
