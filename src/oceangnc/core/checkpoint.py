"""Checkpoints of a running :class:`~oceangnc.core.clock.Simulation`, and resuming from them.

A checkpoint is the *complete* state needed to continue a run bit for bit:

* the clock: physics step count ``k``, time ``t``, the signal bus, each block's fire count, the last
  handled step and the logged signal list;
* every plant's state vector ``x`` and its other array/scalar attributes (held inputs, scratch);
* every block's :meth:`~oceangnc.core.blocks.Block.get_state` (which includes each block's own
  ``numpy.random.Generator``; their ``bit_generator.state`` is also stored explicitly and restored
  last, so a block whose ``get_state`` forgets its generator still resumes the same random stream);
* the log position: how many part files and rows of ``log.parquet`` were flushed when it was taken
  (the log is flushed right before saving, so a resumed run drops the later parts and rewrites them).

It is written with :func:`pickle` to ``checkpoint.pkl`` in the run folder, atomically (temporary
file, fsync, rename), every ``--checkpoint-every`` simulated seconds. :class:`Checkpointer` installs
itself in the clock through ``Simulation.checkpoint_hook = (every_steps, callback)``: the clock
calls the callback after the blocks fired and the row was logged at a step ``k`` that is a multiple
of ``every_steps``, i.e. at a point where the rest of the run depends only on the saved state.
"""

from __future__ import annotations

import pickle
from pathlib import Path

import numpy as np

from ..errors import ConfigError, InputError
from .files import atomic_write_bytes

VERSION = 1
FILE = "checkpoint.pkl"
_PLAIN = (np.ndarray, float, int, bool, str, tuple, list, dict, type(None), np.generic)


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
    for k, v in st.items():
        cur = getattr(pl, k, None)
        if isinstance(cur, np.ndarray) and isinstance(v, np.ndarray) and cur.shape == v.shape:
            cur[...] = v  # in place: compiled closures may hold the array
        else:
            setattr(pl, k, v)


class _Pickler(pickle.Pickler):
    """Pickles references to the simulation's own plants and blocks as ids (restored to the live
    objects), so a block that holds its plant, or two blocks sharing an object, resume correctly."""

    def __init__(self, f, sim):
        super().__init__(f, protocol=pickle.HIGHEST_PROTOCOL)
        self._ids = {id(pl): ("plant", i) for i, pl in enumerate(sim.plants)}
        self._ids.update({id(b): ("block", i) for i, b in enumerate(sim.blocks)})

    def persistent_id(self, obj):
        return self._ids.get(id(obj))


class _Unpickler(pickle.Unpickler):
    def __init__(self, f, sim):
        super().__init__(f)
        self._sim = sim

    def persistent_load(self, pid):
        kind, i = pid
        return self._sim.plants[i] if kind == "plant" else self._sim.blocks[i]


def _block_state(b):
    from .blocks import Block

    if type(b).get_state is not Block.get_state and hasattr(b, "get_state"):
        return ("custom", b.get_state())
    # functions are code, not state: the freshly built simulation already holds them
    return (
        "dict",
        {k: v for k, v in vars(b).items() if not callable(v) or isinstance(v, type) or hasattr(v, "bit_generator")},
    )


def capture(sim) -> bytes:
    """The complete state of ``sim`` (see the module docstring), pickled (one pickle, so objects
    shared between blocks stay shared)."""
    import io

    state = {
        "k": sim.k,
        "t": sim.t,
        "bus": dict(sim.bus),
        "fire_count": list(sim.fire_count),
        "done_k": sim._done_k,
        "log_signals": list(sim.log_signals) if sim.log_signals is not None else None,
        "plant_names": [pl.name for pl in sim.plants],
        "block_names": [b.name for b in sim.blocks],
        "plants": [plant_state(pl) for pl in sim.plants],
        "blocks": [_block_state(b) for b in sim.blocks],
        "rng": [{p: g.bit_generator.state for p, g in _generators(b).items()} for b in sim.blocks],
    }
    buf = io.BytesIO()
    try:
        _Pickler(buf, sim).dump(state)
    except (pickle.PicklingError, TypeError, AttributeError) as e:
        raise ConfigError(
            f"checkpoint: the simulation holds state that cannot be saved ({e}); run without --checkpoint-every"
        ) from None
    return buf.getvalue()


def restore(sim, blob: bytes) -> None:
    """Put ``sim`` (freshly built from the same config and seed) into a captured state."""
    import io

    state = _Unpickler(io.BytesIO(blob), sim).load()
    if state["plant_names"] != [pl.name for pl in sim.plants] or state["block_names"] != [b.name for b in sim.blocks]:
        raise InputError(
            "checkpoint does not match this simulation (different plants or blocks); was the config changed?"
        )
    for pl, st in zip(sim.plants, state["plants"]):
        set_plant_state(pl, st)
    for b, (kind, st) in zip(sim.blocks, state["blocks"]):
        if kind == "custom":
            b.set_state(st)
        else:
            vars(b).update(st)
    for b, rs in zip(sim.blocks, state["rng"]):
        gens = _generators(b)
        for p, s in rs.items():
            if p in gens:
                gens[p].bit_generator.state = s
    sim.k = int(state["k"])
    sim.t = float(state["t"])
    sim.bus.clear()
    sim.bus.update(state["bus"])
    sim.fire_count = list(state["fire_count"])
    sim._done_k = int(state["done_k"])
    sim.log_signals = list(state["log_signals"]) if state["log_signals"] is not None else None


def save(path: str | Path, payload: dict) -> None:
    """Pickle ``payload`` (plain data; the simulation inside is already bytes) to ``path`` atomically."""
    atomic_write_bytes(path, pickle.dumps(payload, protocol=pickle.HIGHEST_PROTOCOL))


def load(run_dir: str | Path) -> dict:
    """Read a run folder's checkpoint; one-line InputError when missing or unreadable."""
    p = Path(run_dir) / FILE
    if not p.is_file():
        raise InputError(f"no checkpoint in {run_dir} (run with --checkpoint-every S to write one)")
    try:
        payload = pickle.loads(p.read_bytes())
    except Exception as e:  # noqa: BLE001 - any unpickling failure is a bad file
        raise InputError(f"checkpoint {p} is unreadable: {type(e).__name__}") from None
    if not isinstance(payload, dict) or payload.get("version") != VERSION:
        raise InputError(f"checkpoint {p} has an unknown format")
    return payload


class Checkpointer:
    """Saves checkpoints of the run's simulation every ``every`` simulated seconds and restores one.

    Parameters
    ----------
    run_dir : path
        Run folder (``checkpoint.pkl`` goes there).
    every : float or None
        Simulated seconds between checkpoints (None: do not save).
    log : LogWriter
        The run's log, flushed before each save so that the saved log position is on disk.
    resume_state : dict, optional
        A loaded checkpoint payload to restore into the first simulation attached.
    """

    def __init__(self, run_dir, every: float | None, log, resume_state: dict | None = None):
        self.run_dir = Path(run_dir)
        self.every = every
        self.log = log
        self.resume_state = resume_state
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
        if self.every is not None:
            tick_s = sim.tick * sim.dt
            steps = max(1, round(self.every / tick_s)) * sim.tick
            sim.checkpoint_hook = (steps, self._save)
        return restored

    def _save(self, sim) -> None:
        self.log.flush()
        self.log.sync()  # the parts the checkpoint counts are on disk before it is
        payload = {
            "version": VERSION,
            "t": sim.t,
            "sim": capture(sim),
            "log": {"parts": self.log.parts, "rows": self.log.rows_written},
        }
        save(self.run_dir / FILE, payload)
        self.saved += 1
