"""Checkpoints of a running :class:`~oceangnc.core.clock.Simulation`, and resuming from them.

A checkpoint is the *complete* state needed to continue a run bit for bit:

* the clock: physics step count ``k``, time ``t``, the signal bus, each block's fire count, the last
  handled step and the logged signal list;
* every plant's state vector ``x`` and its other array/scalar attributes (held inputs, scratch);
* every block's :meth:`~oceangnc.core.blocks.Block.get_state` where a block overrides it, else its
  attributes (functions are code, not state: the rebuilt simulation holds them), including each
  block's own ``numpy.random.Generator``; their ``bit_generator.state`` is also stored explicitly and
  restored last, so a block whose ``get_state`` forgets its generator still resumes the same stream;
* the log position: how many part files and rows of ``log.parquet`` were flushed when it was taken
  (the log is flushed right before saving, so a resumed run drops the later parts and rewrites them).

**Format: data only, never code.** ``checkpoint.npz`` in the run folder is a NumPy ``.npz`` archive
(written with :func:`numpy.savez`, read with ``allow_pickle=False``: an array of Python objects is
refused, nothing is unpickled). Its member ``checkpoint.json`` is a UTF-8 JSON document: ``format``,
``version``, ``scenario``, ``t``, the log position, the checkpoint period and the state tree; its
member ``checkpoint.sha256`` is the SHA-256 of the document's bytes and every array (name, dtype,
shape and bytes, in name order), checked before anything is restored
(:mod:`oceangnc.core.checkpoint_format`, which also bounds the archive and the document's nesting).
Every array is then matched against the live simulation's: an array where it holds one must have its
very shape and dtype. The state tree holds JSON numbers, strings, ``null`` and booleans as
themselves and tags the rest with one ``$`` key: ``$l`` list, ``$t`` tuple, ``$q`` deque,
``$s``/``$fs`` set, ``$d`` dict (as key/value pairs), ``$a`` an array member, ``$n`` a NumPy scalar
(a 0-d array member), ``$g`` a generator (bit-generator name from a fixed list of NumPy's, and its
``state``: a dict of integers), ``$r`` a reference to one of the simulation's own plants or blocks
(restored to the live object, so shared objects stay shared), ``$e`` an enum member and ``$o`` an
object of the simulation's own classes (configs, routes) by its class name and attributes.

Restoring never creates an object from a name in the file: the simulation is first rebuilt from the
run's config and seed, and an ``$o`` or ``$e`` node is written *into* the live object at the same
place, which must be of the class the file names (else the checkpoint does not match: one-line
error). Arrays are written in place where the live array has the same shape and dtype (compiled
closures hold them). What a block's state may hold: numbers, strings, ``None``, lists, tuples,
deques, sets and dicts of these, NumPy arrays (not of Python objects) and scalars, generators, enum
members, references to the simulation's plants and blocks, and plain objects (with a ``__dict__``)
holding these. Anything else (a socket, a lock, an open file) is refused when the checkpoint is
taken, with a one-line error naming the block and the attribute; such a block overrides
``get_state``/``set_state``. What an overridden ``get_state`` returns has no live object to be
written into: it may hold plain data only (no objects, no enum members), also checked when the
checkpoint is taken. ``checkpoint.pkl``, the pickle older versions wrote, is refused
without being read (a pickle can run code).

The file is written atomically (temporary file, fsync, rename), every ``--checkpoint-every``
simulated seconds. :class:`Checkpointer` installs itself in the clock through
``Simulation.checkpoint_hook = (every_steps, callback)``: the clock calls the callback after the
blocks fired and the row was logged at a step ``k`` that is a multiple of ``every_steps``, i.e. at a
point where the rest of the run depends only on the saved state.
"""

from __future__ import annotations

import collections
import enum
import functools
import types
from pathlib import Path
from typing import Any

import numpy as np

from ..errors import ConfigError, InputError
from .checkpoint_format import DOC, FORMAT, SUM, VERSION, check_run, pack, read  # noqa: F401  (re-exported)
from .files import LIMIT_CHECKPOINT, atomic_write_bytes, read_bounded

FILE = "checkpoint.npz"
OLD_FILE = "checkpoint.pkl"  #: the pickle format of older versions: refused, never read
_PLAIN = (np.ndarray, float, int, bool, str, tuple, list, dict, type(None), np.generic)
#: the bit generators a checkpoint may name (restoring creates one only from this list)
_BITGENS = {
    c.__name__: c for c in (np.random.PCG64, np.random.PCG64DXSM, np.random.MT19937, np.random.Philox, np.random.SFC64)
}
_CODE = (
    types.FunctionType,
    types.BuiltinFunctionType,
    types.MethodType,
    types.BuiltinMethodType,
    types.ModuleType,
    functools.partial,
    type,
)
ALLOWED = (
    "numbers, strings, None, lists, tuples, deques, sets and dicts of these, numpy arrays and scalars, "
    "generators, and objects holding these"
)


def _generators(obj, path="", out=None, depth=0):
    """Find numpy Generators inside a block's attributes: ``{attr path: generator}``."""
    if out is None:
        out = {}
    if depth > 3:
        return out
    if isinstance(obj, np.random.Generator):
        out[path] = obj
    elif isinstance(obj, dict):
        for k, v in obj.items():
            if isinstance(k, str):
                _generators(v, f"{path}[{k!r}]", out, depth + 1)
    elif hasattr(obj, "__dict__") and not isinstance(obj, type):
        for k, v in vars(obj).items():
            _generators(v, f"{path}.{k}", out, depth + 1)
    return out


def plant_state(pl) -> dict:
    """A plant's array and scalar attributes (its state ``x``, held inputs, workspace)."""
    return {k: v for k, v in vars(pl).items() if isinstance(v, _PLAIN)}


def set_plant_state(pl, st: dict) -> None:
    """Write a plant's attributes back; a live array is written in place and only from an array of its
    very shape and dtype (compiled code indexes it without bounds checks), else a one-line InputError."""
    for k, v in st.items():
        cur = getattr(pl, k, None)
        if isinstance(cur, np.ndarray):
            if not (isinstance(v, np.ndarray) and cur.shape == v.shape and cur.dtype == v.dtype):
                got = f"{v.shape} {v.dtype}" if isinstance(v, np.ndarray) else type(v).__name__
                raise InputError(
                    f"checkpoint does not match this simulation (plant '{pl.name}' attribute .{k}: "
                    f"{got} where the simulation holds {cur.shape} {cur.dtype}); was the config changed?"
                )
            if cur is not v:
                cur[...] = v  # in place: compiled closures may hold the array
        else:
            setattr(pl, k, v)


def _is_code(v) -> bool:
    """Functions, methods, classes, modules and compiled dispatchers: code, which the rebuilt
    simulation already holds (not state)."""
    if isinstance(v, np.random.Generator):
        return False
    return isinstance(v, _CODE) or (callable(v) and hasattr(v, "py_func"))


def _qualname(tp: type) -> str:
    return f"{tp.__module__}.{tp.__qualname__}"


class _Encoder:
    """Turns state into a JSON tree plus named arrays (the module docstring's tags)."""

    def __init__(self, sim):
        self.arrays: dict[str, np.ndarray] = {}
        self._array_ids: dict[int, str] = {}
        self._objects: dict[int, int] = {}
        self._keep: list[Any] = []  # objects whose id() is remembered stay alive while encoding
        self._refs: dict[int, list] = {id(pl): ["plant", i] for i, pl in enumerate(sim.plants)}
        self._refs.update({id(b): ["block", i] for i, b in enumerate(sim.blocks)})
        self._refs[id(sim)] = ["sim", 0]
        self.owner = "the simulation"
        self.objects = True  #: objects allowed (False for a get_state() result: nothing to write into)

    def refuse(self, path: str, v, why: str = "") -> ConfigError:
        return ConfigError(
            f"checkpoint: {self.owner} attribute {path} holds {why or 'a ' + _qualname(type(v))}, which a "
            f"checkpoint cannot store (a state may hold {ALLOWED}); "
            + ("override get_state/set_state" if self.objects else "return plain data from get_state")
            + ", or run without --checkpoint-every"
        )

    def array(self, a: np.ndarray, path: str) -> str:
        key = self._array_ids.get(id(a))
        if key is None:
            if a.dtype.hasobject:
                raise self.refuse(path, a, "an array of Python objects")
            key = f"a{len(self.arrays)}"
            self.arrays[key] = np.array(a, copy=True)
            self._array_ids[id(a)] = key
            self._keep.append(a)
        return key

    def enc(self, v, path: str, depth: int = 0):
        if depth > 64:
            raise self.refuse(path, v, "a structure nested more than 64 levels deep")
        tp = type(v)
        if v is None or tp in (bool, int, str):
            return v
        if tp is float:
            return v
        ref = self._refs.get(id(v))
        if ref is not None:
            return {"$r": ref}
        if isinstance(v, np.ndarray):
            return {"$a": self.array(v, path)}
        if isinstance(v, np.generic):
            return {"$n": self.array(np.asarray(v), path)}
        if isinstance(v, np.random.Generator):
            name = type(v.bit_generator).__name__
            if name not in _BITGENS:
                raise self.refuse(path, v, f"a generator on bit generator {name}")
            return {"$g": name, "state": self.enc(v.bit_generator.state, f"{path}.bit_generator.state", depth + 1)}
        if isinstance(v, enum.Enum):
            if not self.objects:
                raise self.refuse(path, v, f"a {_qualname(tp)} (get_state() may return no enum members)")
            return {"$e": _qualname(tp), "name": v.name}
        if tp is list or tp is tuple:
            return {"$l" if tp is list else "$t": [self.enc(x, f"{path}[{i}]", depth + 1) for i, x in enumerate(v)]}
        if tp is collections.deque:
            return {"$q": [self.enc(x, f"{path}[{i}]", depth + 1) for i, x in enumerate(v)], "maxlen": v.maxlen}
        if tp is set or tp is frozenset:
            items = sorted(v, key=repr)
            return {"$s" if tp is set else "$fs": [self.enc(x, f"{path}{{}}", depth + 1) for x in items]}
        if tp is dict:
            return {
                "$d": [
                    [self.enc(k, f"{path} key", depth + 1), self.enc(x, f"{path}[{k!r}]", depth + 1)]
                    for k, x in v.items()
                ]
            }
        if _is_code(v) or isinstance(v, (bytes, bytearray, complex)) or not hasattr(v, "__dict__"):
            raise self.refuse(path, v)
        if not self.objects:  # a get_state() result: restored without a live object to write into
            raise self.refuse(path, v, f"a {_qualname(tp)} (get_state() may return no objects, only plain data)")
        # an object of the simulation's own classes: its class name and attributes (restored into the
        # live object of that class, never created from the name)
        n = self._objects.get(id(v))
        if n is not None:
            return {"$o": _qualname(tp), "same": n}
        n = self._objects[id(v)] = len(self._objects)
        self._keep.append(v)
        attrs = {}
        for k, x in vars(v).items():
            if not isinstance(k, str) or k.startswith("__") or _is_code(x):
                continue
            attrs[k] = self.enc(x, f"{path}.{k}", depth + 1)
        return {"$o": _qualname(tp), "id": n, "attrs": attrs}


def capture(sim, meta: dict | None = None) -> bytes:
    """The complete state of ``sim`` (module docstring) as the bytes of a ``checkpoint.npz``;
    ``meta`` (JSON data: scenario, log position) is stored beside it. Raises a one-line
    :class:`~oceangnc.errors.ConfigError` naming the block and attribute that holds something a
    checkpoint cannot store."""
    from .blocks import Block

    e = _Encoder(sim)
    e.owner = "the signal bus"
    bus = e.enc(dict(sim.bus), "")
    plants = []
    for pl in sim.plants:
        e.owner = f"plant '{pl.name}'"
        plants.append({k: e.enc(v, "." + k) for k, v in plant_state(pl).items()})
    blocks = []
    rngs = []
    for b in sim.blocks:
        e.owner = f"block '{b.name}'"
        if type(b).get_state is not Block.get_state and hasattr(b, "get_state"):
            e.objects = False
            blocks.append(["custom", e.enc(b.get_state(), "get_state()")])
            e.objects = True
        else:
            blocks.append(["dict", {k: e.enc(v, "." + k) for k, v in vars(b).items() if not _is_code(v)}])
        rngs.append({p: e.enc(g.bit_generator.state, p) for p, g in _generators(b).items()})
    doc = {
        "format": FORMAT,
        "version": VERSION,
        **(meta or {}),
        "sim": {
            "k": int(sim.k),
            "t": float(sim.t),
            "bus": bus,
            "fire_count": [int(n) for n in sim.fire_count],
            "done_k": int(sim._done_k),
            "log_signals": list(sim.log_signals) if sim.log_signals is not None else None,
            "plant_names": [pl.name for pl in sim.plants],
            "block_names": [b.name for b in sim.blocks],
            "plants": plants,
            "blocks": blocks,
            "rng": rngs,
        },
    }
    return pack(doc, e.arrays)


class _Decoder:
    """Rebuilds values from a checkpoint's tree, writing objects and arrays into the live ones."""

    def __init__(self, sim, arrays: dict[str, np.ndarray]):
        self.sim = sim
        self.arrays = arrays
        self._fresh: dict[str, np.ndarray] = {}
        self._objects: dict[int, Any] = {}
        self._path = []

    where = ""  #: the plant or block being restored, for messages
    _path: list[str]

    def mismatch(self, why: str) -> InputError:
        at = f"{self.where} attribute {''.join(self._path)}: " if self.where and self._path else ""
        return InputError(f"checkpoint does not match this simulation ({at}{why}); was the config changed?")

    def member(self, key) -> np.ndarray:
        if not isinstance(key, str) or key not in self.arrays:
            raise self.mismatch(f"missing array {key!r}")
        return self.arrays[key]

    def dec(self, node, live=None):
        if node is None or isinstance(node, (bool, int, float, str)):
            if isinstance(live, np.ndarray):
                raise self.mismatch(f"a {_kind(node)} where the simulation holds an array {live.shape} {live.dtype}")
            return node
        if isinstance(node, list):  # not written by capture (lists are tagged)
            raise self.mismatch("untagged list")
        if not isinstance(node, dict):
            raise self.mismatch(f"unexpected {type(node).__name__}")
        if "$a" in node:
            a = self.member(node["$a"])
            if isinstance(live, np.ndarray):  # compiled code holds it: the very shape and dtype, or refused
                if live.shape != a.shape or live.dtype != a.dtype:
                    raise self.mismatch(
                        f"an array of shape {a.shape} {a.dtype} where the simulation holds {live.shape} {live.dtype}"
                    )
                if live.flags.writeable:
                    live[...] = a  # in place: compiled closures may hold the array
                    return live
            if node["$a"] not in self._fresh:
                self._fresh[node["$a"]] = np.array(a, copy=True)
            return self._fresh[node["$a"]]
        if isinstance(live, np.ndarray):
            raise self.mismatch(f"a {_kind(node)} where the simulation holds an array {live.shape} {live.dtype}")
        if "$n" in node:
            a = self.member(node["$n"])
            if a.ndim != 0:
                raise self.mismatch("a scalar that is not 0-d")
            if isinstance(live, np.generic) and live.dtype != a.dtype:
                raise self.mismatch(f"a {a.dtype} scalar where the simulation holds a {live.dtype}")
            return a[()]
        if "$r" in node:
            kind, i = node["$r"]
            if kind == "sim":
                return self.sim
            seq = self.sim.plants if kind == "plant" else self.sim.blocks if kind == "block" else None
            if seq is None or not isinstance(i, int) or not 0 <= i < len(seq):
                raise self.mismatch(f"reference {node['$r']!r}")
            return seq[i]
        if "$g" in node:
            cls = _BITGENS.get(node["$g"])
            if cls is None:
                raise self.mismatch(f"unknown bit generator {node['$g']!r}")
            state = self.dec(node["state"])
            g = live if isinstance(live, np.random.Generator) and type(live.bit_generator) is cls else None
            if g is None:
                g = np.random.Generator(cls())
            g.bit_generator.state = state
            return g
        if "$e" in node:
            if not isinstance(live, enum.Enum) or _qualname(type(live)) != node["$e"]:
                raise self.mismatch(f"no {node['$e']} here")
            return type(live)[node["name"]]
        if "$l" in node:
            return [self.dec(x, y) for x, y in zip(node["$l"], _seq(live, len(node["$l"])))]
        if "$t" in node:
            return tuple(self.dec(x, y) for x, y in zip(node["$t"], _seq(live, len(node["$t"]))))
        if "$q" in node:
            return collections.deque((self.dec(x) for x in node["$q"]), maxlen=node.get("maxlen"))
        if "$s" in node or "$fs" in node:
            items = {self.dec(x) for x in (node["$s"] if "$s" in node else node["$fs"])}
            return items if "$s" in node else frozenset(items)
        if "$d" in node:
            out = {}
            old = live if isinstance(live, dict) else {}
            for k, x in node["$d"]:
                key = self.dec(k)
                out[key] = self.dec(x, old.get(key))
            return out
        if "$o" in node:
            if "same" in node:
                if node["same"] not in self._objects:
                    raise self.mismatch(f"object {node['same']!r} used before it is defined")
                return self._objects[node["same"]]
            if live is None or not hasattr(live, "__dict__") or _qualname(type(live)) != node["$o"]:
                raise self.mismatch(f"no {node['$o']} here")
            self._objects[node["id"]] = live
            self.update(live, node["attrs"])
            return live
        raise self.mismatch(f"unknown tag {sorted(node)[:1]}")

    def update(self, obj, attrs: dict) -> None:
        """Write decoded attributes into ``obj`` (bypassing ``__setattr__``: frozen configs too)."""
        d = vars(obj)
        for k, x in attrs.items():
            if not isinstance(k, str) or k.startswith("__"):
                raise self.mismatch(f"attribute name {k!r}")
            self._path.append(f".{k}")
            d[k] = self.dec(x, d.get(k))
            self._path.pop()


def _kind(node) -> str:
    if isinstance(node, dict):
        tag = next((k for k in node if isinstance(k, str) and k.startswith("$")), "?")
        return {"$n": "NumPy scalar", "$l": "list", "$t": "tuple", "$d": "dict", "$o": "object"}.get(tag, tag)
    return type(node).__name__


_SCALARS = (bool, int, float, np.number, np.bool_)


def _plant_value(d: _Decoder, pl, k: str, node):
    """A plant attribute decoded against the live plant (compiled code reads it): an array of the very
    shape and dtype, a number where it holds a number, a string where a string; a name the plant does
    not hold may only be a number, a string or None."""
    d._path = [f".{k}"]
    live = getattr(pl, k, None)
    v = d.dec(node, live)
    if live is None and k not in vars(pl) and not (v is None or isinstance(v, (*_SCALARS, str))):
        raise d.mismatch(f"a {type(v).__name__} the plant does not hold")
    if isinstance(live, _SCALARS) and not isinstance(v, _SCALARS):
        raise d.mismatch(f"a {type(v).__name__} where the simulation holds a number")
    if isinstance(live, (str, list, tuple, dict)) and type(v) is not type(live):
        raise d.mismatch(f"a {type(v).__name__} where the simulation holds a {type(live).__name__}")
    d._path = []
    return v


def _seq(live, n: int) -> list:
    return list(live) if isinstance(live, (list, tuple)) and len(live) == n else [None] * n


def restore(sim, blob: bytes) -> None:
    """Put ``sim`` (freshly built from the same config and seed) into a captured state.

    Everything is checked before the simulation runs again (one-line InputError, the simulation then
    discarded): the bytes whole (:func:`~oceangnc.core.checkpoint_format.read`), the plants and blocks
    by name, every array against the live one (shape and dtype), the clock against the time step."""
    doc, arrays = read(blob)
    st = doc["sim"]
    if st["plant_names"] != [pl.name for pl in sim.plants] or st["block_names"] != [b.name for b in sim.blocks]:
        raise InputError(
            "checkpoint does not match this simulation (different plants or blocks); was the config changed?"
        )
    if abs(st["t"] - st["k"] * sim.dt) > 1e-6 * max(1.0, st["t"]) or st["done_k"] > st["k"]:
        raise InputError(
            f"checkpoint does not match this simulation (clock t = {st['t']!r} s at step {st['k']!r} "
            f"with sim.dt = {sim.dt:g} s); was the config changed?"
        )
    d = _Decoder(sim, arrays)
    try:
        for pl, ps in zip(sim.plants, st["plants"]):
            d.where = f"plant '{pl.name}'"
            set_plant_state(pl, {k: _plant_value(d, pl, k, v) for k, v in ps.items()})
        for b, (kind, bs) in zip(sim.blocks, st["blocks"]):
            d.where = f"block '{b.name}'"
            if kind == "custom":
                b.set_state(d.dec(bs, b.get_state()))  # matched against what the live block gives
            else:
                d.update(b, bs)
        for b, rs in zip(sim.blocks, st["rng"]):
            gens = _generators(b)
            for p, s in rs.items():
                if p in gens:
                    gens[p].bit_generator.state = d.dec(s)
        d.where = "the signal bus"
        bus = d.dec(st["bus"], dict(sim.bus))
        if not isinstance(bus, dict) or not all(isinstance(k, str) for k in bus):
            raise d.mismatch("a signal bus that is not a dict of names")
    except (KeyError, TypeError, ValueError, IndexError, AttributeError, OverflowError) as e:
        if isinstance(e, InputError):
            raise
        raise d.mismatch(f"{type(e).__name__}: {e}") from None
    sim.k = int(st["k"])
    sim.t = float(st["t"])
    sim.bus.clear()
    sim.bus.update(bus)
    sim.fire_count = [int(n) for n in st["fire_count"]]
    sim._done_k = int(st["done_k"])
    sim.log_signals = list(st["log_signals"]) if st["log_signals"] is not None else None


def save(path: str | Path, blob: bytes) -> None:
    """Write a checkpoint's bytes (:func:`capture`) to ``path`` atomically."""
    atomic_write_bytes(path, blob)


def load(run_dir: str | Path) -> dict:
    """Read a run folder's checkpoint: ``{"t", "log", "scenario", "sim": the file's bytes}``.

    One-line InputError when missing, unreadable, damaged, or in the old pickle format (which is
    refused without being read).
    """
    p = Path(run_dir) / FILE
    if not p.is_file():
        if (Path(run_dir) / OLD_FILE).exists():
            raise InputError(
                f"{Path(run_dir) / OLD_FILE} is an old, unsafe format (a pickle can run code) and is not read; "
                "rerun the scenario with --checkpoint-every to write a checkpoint.npz"
            )
        raise InputError(f"no checkpoint in {run_dir} (run with --checkpoint-every S to write one)")
    blob = read_bounded(p, LIMIT_CHECKPOINT, "checkpoint")
    doc, _ = read(blob, f"checkpoint {p}")
    check_run(doc, f"checkpoint {p}")
    return {
        "version": doc["version"],
        "t": float(doc["t"]),
        "log": {"parts": doc["log"]["parts"], "rows": doc["log"]["rows"]},
        "every": doc.get("every"),
        "scenario": doc.get("scenario"),
        "sim": blob,
    }


class Checkpointer:
    """Saves checkpoints of the run's simulation every ``every`` simulated seconds and restores one.

    Parameters
    ----------
    run_dir : path
        Run folder (``checkpoint.npz`` goes there).
    every : float or None
        Simulated seconds between checkpoints (None: do not save).
    log : LogWriter
        The run's log, flushed before each save so that the saved log position is on disk.
    resume_state : dict, optional
        A loaded checkpoint (:func:`load`) to restore into the first simulation attached.
    scenario : str, optional
        The scenario's name, recorded in the checkpoint.
    """

    def __init__(
        self, run_dir, every: float | None, log, resume_state: dict | None = None, scenario: str | None = None
    ):
        self.run_dir = Path(run_dir)
        self.every = every
        self.log = log
        self.resume_state = resume_state
        self.scenario = scenario
        self.attached = 0
        self.saved = 0

    def attach(self, sim) -> bool:
        """Install the save hook on ``sim``; restore the checkpoint into it when resuming.

        Returns True when the simulation was restored (the caller runs only the remaining time).
        """
        self.attached += 1
        if self.attached > 1:
            raise ConfigError(
                "checkpoints: this scenario runs several simulations one after the other; "
                "--checkpoint-every and --resume support single-simulation scenarios"
            )
        restored = False
        if self.resume_state is not None:
            restore(sim, self.resume_state["sim"])
            restored = True
            done = self.resume_state.get("on_restored")
            if done is not None:
                done()  # e.g. the run's log cut to the checkpoint, only now that it was accepted whole
        if self.every is not None:
            tick_s = sim.tick * sim.dt
            steps = max(1, round(self.every / tick_s)) * sim.tick
            sim.checkpoint_hook = (steps, self._save)
        return restored

    def _save(self, sim) -> None:
        self.log.flush()
        self.log.sync()  # the parts the checkpoint counts are on disk before it is
        meta = {
            "scenario": self.scenario,
            "t": float(sim.t),
            "log": {"parts": int(self.log.parts), "rows": int(self.log.rows_written)},
            "every": self.every,  # a resumed run keeps checkpointing at this period
        }
        save(self.run_dir / FILE, capture(sim, meta))
        self.saved += 1
