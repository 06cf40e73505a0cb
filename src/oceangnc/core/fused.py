"""The fused closed loop: every block and plant of a simulation in one compiled call (issue 19).

The Python clock (:mod:`oceangnc.core.clock`) costs ~37 us per tick in block calls and string-keyed
bus reads and writes. When every block of a simulation has a *compiled form* (its ``compiled()``
method returns a :class:`CompiledBlock`) and every plant has one (:func:`plant_form`), the clock
runs the loop fused instead:

* the signals live in one float64 array; each block's signals are resolved to slot numbers once,
  when the fused loop is built. When every part declares its outputs the loop is built before the
  first tick (:func:`first_tick_plan`: the signals, and the log columns, follow from the
  declarations) and the driver runs the first tick too, so no law is loaded on its own; otherwise
  (or while a child process compiles ahead) the Python clock runs the first tick and the names come
  from the bus after it;
* a driver is generated as Python source -- one ``@njit(cache=True)`` function that, tick by tick,
  calls each block's kernel ``kernel(t, sig, slots, state, params)`` at its period, logs a row into a
  preallocated buffer, then reads the plants' inputs, advances them with their compiled steppers
  and publishes their outputs -- and cached on disk under
  :func:`oceangnc.core.integrators.stepper_cache_dir`, keyed by a hash of its source (the block
  kinds, their order and the plants);
* the buffer is handed to the :class:`~oceangnc.io.logs.LogWriter` in blocks of rows
  (:meth:`~oceangnc.io.logs.LogWriter.append_rows`), so no Python code runs per tick.

The kernels repeat the Python blocks' arithmetic operation for operation; ``tests/test_fused.py``
checks that both paths give the same log. Divergence (a non-finite logged signal, a plant above its
state bound) raises the same :class:`~oceangnc.errors.DivergenceError` as the Python path.

A block without a compiled form (a user's Python block, a :class:`~oceangnc.core.blocks.FunctionBlock`,
a sensor drawing random numbers) makes :func:`build_fused` return the reason, and the clock keeps
the Python path (``oceangnc run --verbose`` says so once). After a fused run the Python block
objects keep their state of the first tick: the fused state lives in the loop's arrays.
"""

from __future__ import annotations

import hashlib
import math
import sys
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from .caches import code_key, package_root, tree_key
from .fused_strings import ENUMS
from .fused_strings import code as _code
from .fused_strings import strings_ok as _strings_ok


@dataclass
class CompiledBlock:
    """A block's compiled form.

    ``kernel`` is a module-level ``@njit`` function ``kernel(t, sig, slots, state, params)``;
    ``signals`` the names of the signals it reads and writes, in the kernel's slot order (a name
    starting with ``?`` is an optional input: slot -1 when nobody writes it, and the kernel uses the
    Python block's default); ``state`` and ``params`` flat float64 arrays (``state`` is updated in
    place by the kernel).
    """

    kernel: object
    signals: list[str]
    state: np.ndarray = field(default_factory=lambda: np.zeros(1))
    params: np.ndarray = field(default_factory=lambda: np.zeros(1))
    rng: object = None  # the block's numpy Generator, passed as the kernel's 6th argument (sensors)


@dataclass
class PlantForm:
    """A plant's part of the fused driver: imports, array arguments and source lines.

    In ``code``, ``{name}`` stands for the argument ``name`` of ``args`` (made unique per plant);
    the lines may use ``t``, ``dt``, ``n`` (steps this tick) and ``sig``, and must set ``tn`` to the
    stepper's return value (negative on divergence).
    """

    imports: list[str]
    args: dict
    code: list[str]


def _kernel_ref(fn) -> tuple[Any, Any]:
    mod = getattr(fn, "__module__", None)
    name = getattr(getattr(fn, "py_func", fn), "__name__", None)
    return mod, name


def rk4_stepper_imports(rhs) -> list[str]:
    """Generated-code lines binding ``{adv}`` to the cached RK4 stepper of the compiled rhs ``rhs``
    (:func:`oceangnc.core.integrators.rk4_stepper`), imported by name from its module."""
    mod, name = _kernel_ref(rhs)
    return [
        "from oceangnc.core.integrators import rk4_stepper as _rk4_stepper",
        f"from {mod} import {name} as _rhs_{{adv}}",
        "{adv} = _rk4_stepper(_rhs_{adv})",
    ]


def kernels_key(import_lines) -> str:
    """Hash of the user code the generated import lines name: the key of the registered user sources
    (:func:`oceangnc.core.caches.code_key`) and, for each module outside oceangnc, its whole top-level
    package (:func:`~oceangnc.core.caches.package_root`), so a kernel's callees in sibling files count."""
    h = hashlib.sha1(code_key().encode())
    for line in dict.fromkeys(import_lines):
        name = line.split()[1]
        if name == "oceangnc" or name.startswith("oceangnc."):
            continue  # the package's own code: the cache folder's key
        src = getattr(sys.modules.get(name), "__file__", None)
        if src:
            h.update(f"{name}:{tree_key(package_root(src))}".encode())
    return h.hexdigest()[:16]


def plant_bus_keys(slot_of) -> set:
    """Names the signal array carries (the bus's numeric keys and the blocks' signals)."""
    return set(getattr(slot_of, "names", ()))


def plant_form(plant, slot_of) -> PlantForm | None:
    """The compiled form of a plant (its ``compiled_form(slot_of)``), or None.

    Every plant supplies its own (:meth:`oceangnc.core.blocks.Plant.compiled_form` for the generic
    RK4 plant that publishes its states; a vehicle model with its own integrator or outputs overrides
    it in its own module): the fused loop knows no vehicle. ``slot_of(name)`` gives a signal's slot.
    """
    own = getattr(plant, "compiled_form", None)
    return own(slot_of) if own is not None else None


def advance_and_publish(plant, slot_of, imports: list[str], names: list[str], publish) -> PlantForm:
    """The usual plant form: read the inputs from their slots, advance with the stepper bound to
    ``{adv}`` by ``imports``, then ``publish(x, sig, oslots)`` (a module-level compiled function,
    imported by name; the plant's outputs in the order of ``names``)."""
    mod, name = _kernel_ref(publish)
    imports = [*imports, f"from {mod} import {name} as _pub_{{adv}}"]
    uin = np.array([slot_of(k) for k in plant.input_names], dtype=np.int64)
    args = {"x": plant.x, "u": plant.u, "p": plant.p, "w": plant.work, "bound": float(plant.state_bound), "uin": uin}
    args["oslots"] = np.array([slot_of(k) for k in names], dtype=np.int64)
    code = [
        "for j in range({uin}.size):",
        "    {u}[j] = sig[{uin}[j]]",
        "tn = {adv}(t, {x}, {u}, {p}, dt, n, {w}, {bound})",
        "_pub_{adv}({x}, sig, {oslots})",
    ]
    return PlantForm(imports, args, code)


_HEAD = '''\
# Generated by oceangnc.core.fused; do not edit. Cached numba driver of one fused closed loop.
import math

from numba import njit, prange

{imports}


@njit(cache=True)
def drive(k, done_k, n_end, tick, dt, sig, stop_slot, log_on, log_steps, log_slots, nan_ok, buf, max_ticks, nbs{args}):
    """Run ticks from step k; returns (k, done_k, rows, status, info, t_new).

    status 0: end or _stop reached; 1: log buffer full; 2: non-finite logged signal (info: column);
    3: plant info diverged (t_new its stepper's return); 4: max_ticks ticks done.
    """
    row = 0
    ticks = 0
    cap = buf.shape[0]
    while True:
        t = k * dt
        fresh = k != done_k
        if fresh and log_on and k % log_steps == 0 and row >= cap:
            return k, done_k, row, 1, 0, 0.0
        if fresh and ticks >= max_ticks:
            return k, done_k, row, 4, 0, 0.0
        done_k = k
        if fresh:
            ticks += 1
{blocks}
            if log_on and k % log_steps == 0:
                buf[row, 0] = t
                bad = -1
                for j in range(log_slots.size):
                    val = sig[log_slots[j]]
                    buf[row, j + 1] = val
                    if bad < 0 and not math.isfinite(val) and nan_ok[j] == 0:
                        bad = j
                row += 1
                if bad >= 0:
                    return k, done_k, row, 2, bad, 0.0
        if k >= n_end or sig[stop_slot] != 0.0:
            return k, done_k, row, 0, 0, 0.0
        n = min(tick, n_end - k)
{plants}
        k += n


@njit(parallel=True, cache=True)
def drive_batch(active, ks, done_ks, n_end, tick, dt, SIG, stop_slot, log_on, log_steps, log_slots, nan_ok, BUF,
                max_ticks, nbs{bargs}, OUT):
    """:func:`drive` for K independent runs in parallel (numba prange over runs); results in OUT (K, 6)."""
    for r in prange(active.size):
        if active[r] == 0:
            OUT[r, 2] = 0.0
            OUT[r, 3] = 0.0
            continue
        res = drive(ks[r], done_ks[r], n_end, tick, dt, SIG[r], stop_slot, log_on, log_steps, log_slots, nan_ok,
                    BUF[r], max_ticks, nbs{bcall})
        OUT[r, 0] = res[0]
        OUT[r, 1] = res[1]
        OUT[r, 2] = res[2]
        OUT[r, 3] = res[3]
        OUT[r, 4] = res[4]
        OUT[r, 5] = res[5]
'''


#: the loop's own flags: always carried (0 = false until set), so an optional reader always sees them, even
#: when nothing had set them when the loop was built (an e-stop injected later must reach every block)
_FLAGS = ("_stop", "_estop")


class FusedLoop:
    """A built fused loop of one :class:`~oceangnc.core.clock.Simulation` (see the module docstring)."""

    def __init__(self, sim, forms: list[CompiledBlock], plan: FirstTick | None = None):
        bus = sim.bus
        # the bus keys after the first tick: the bus itself once that tick ran in Python, else the plan's
        after = bus.keys() if plan is None else plan.after
        self._readers = list(zip(sim.blocks, forms))
        self._plants = list(sim.plants)
        names = sorted(k for k, v in bus.items() if _numeric(v) or k in ENUMS)
        for f in forms:
            for s in f.signals:
                if not s.startswith("?") and s not in names:
                    names.append(s)
        for s in _FLAGS:
            if s not in names:
                names.append(s)
        self.names = names
        self.slot = {k: i for i, k in enumerate(names)}
        self.sig = np.array([_code(k, bus.get(k)) for k in names])
        self.had = {k for k in names if k in after}

        def slot_of(name: str) -> int:
            if name not in self.slot:
                self.slot[name] = len(self.names)
                self.names.append(name)
                self.sig = np.append(self.sig, _code(name, bus.get(name)))
            return self.slot[name]

        slot_of.names = self.slot  # type: ignore[attr-defined]
        args: dict = {}
        imports: list[str] = []
        block_lines: list[str] = []
        #: the arguments for the first tick when the driver runs it and an optional input written by a later
        #: block must be absent then (:class:`FirstTick`), else None
        self.first_args: dict | None = None
        first: dict = {}
        for i, f in enumerate(forms):
            mod, name = _kernel_ref(f.kernel)
            alias = f"_k{i}"
            imports.append(f"from {mod} import {name} as {alias}")
            slots = np.array(
                [
                    (self.slot[s[1:]] if s[1:] in self.slot and (s[1:] in after or s[1:] in _FLAGS) else -1)
                    if s.startswith("?")
                    else slot_of(s)
                    for s in f.signals
                ],
                dtype=np.int64,
            )
            args[f"sl{i}"] = slots
            if plan is not None:  # at the first tick an optional input is there only if already on the bus
                sl0 = np.array(
                    [v if not s.startswith("?") or s[1:] in plan.before[i] else -1 for s, v in zip(f.signals, slots)],
                    dtype=np.int64,
                )
                if not np.array_equal(sl0, slots):
                    first[f"sl{i}"] = sl0
            args[f"st{i}"] = np.ascontiguousarray(f.state, dtype=np.float64)
            args[f"pa{i}"] = np.ascontiguousarray(f.params, dtype=np.float64)
            rg = ""
            if f.rng is not None:
                args[f"rg{i}"] = f.rng
                rg = f", rg{i}"
            block_lines += [
                f"            if k % nbs[{i}] == 0:",
                f"                {alias}(t, sig, sl{i}, st{i}, pa{i}{rg})",
            ]
        plant_lines: list[str] = []
        self.plant_forms: list = []
        for j, pl in enumerate(sim.plants):
            pf = plant_form(pl, slot_of)
            if pf is None:
                raise _NoFused(f"plant '{pl.name}' ({type(pl).__name__}) has no compiled form")
            sub = {a: f"p{j}_{a}" for a in pf.args}
            sub["adv"] = f"_adv{j}"
            for line in pf.imports:
                imports.append(line.format(**sub))
            for a, v in pf.args.items():
                args[sub[a]] = v
            for line in pf.code:
                plant_lines.append("        " + line.format(**sub))
            plant_lines += ["        if tn < 0.0:", f"            return k, done_k, row, 3, {j}, tn"]
        self.stop_slot = self.slot["_stop"]
        self.nbs = np.array(sim.block_steps, dtype=np.int64)
        self.arg_names = list(args)
        self.args = args
        if first:
            self.first_args = {**args, **first}
        arg_src = "".join(f", {a}" for a in self.arg_names)
        bargs = "".join(f", B_{a}" for a in self.arg_names)
        bcall = "".join(f", B_{a}[r]" for a in self.arg_names)
        self.source = _HEAD.format(
            imports="\n".join(dict.fromkeys(imports)),
            args=arg_src,
            bargs=bargs,
            bcall=bcall,
            blocks="\n".join(block_lines),
            plants="\n".join(plant_lines),
        )
        # numba's cache does not follow callees: the package's own kernels are covered by the code key
        # of the cache folder (oceangnc.core.caches); a user's kernels by the key of their package
        self.source = f"# kernels fingerprint: {kernels_key(imports)}\n" + self.source
        from .integrators import load_generated

        digest = hashlib.sha1(self.source.encode()).hexdigest()[:16]
        self.module = load_generated(f"fused_{digest}", self.source)
        self.drive = self.module.drive
        self.log_slots: Any = None
        self.nan_ok: Any = None

    def set_log(self, log_signals) -> None:
        self.log_signals = list(log_signals)
        self.log_slots = np.array(
            [self.slot[k] if k in self.slot else self._extra(k) for k in self.log_signals], dtype=np.int64
        )
        self.nan_ok = np.array([1 if k.endswith("_nan_ok") else 0 for k in self.log_signals], dtype=np.int64)

    def _extra(self, k):
        # a logged name that no slot carries (not numeric on the bus): logged as NaN like the Python path
        self.slot[k] = len(self.names)
        self.names.append(k)
        self.sig = np.append(self.sig, np.nan)
        return self.slot[k]

    def to_bus(self, bus: dict) -> None:
        """Copy the signal array back onto the bus (after each fused call)."""
        vals = self.sig.tolist()
        for k, v in zip(self.names, vals):
            if k in ENUMS:
                continue  # a string signal read as its code: the kernels never write it
            if k in ("_stop", "_estop"):
                if v != 0.0 or k in self.had:
                    bus[k] = bool(v)
            else:
                bus[k] = v
        for pl in self._plants:  # a plant's own follow-up of a fused call (e.g. a warning its publish gives)
            hook = getattr(pl, "after_fused", None)
            if hook is not None:
                hook(bus)

    def from_bus(self, bus: dict) -> None:
        """Copy numeric bus values into the signal array (values injected between runs); a console
        string the kernels cannot read (a route sent by the console) is refused with a ConfigError."""
        why = _strings_ok(bus, self._readers)
        if why is not None:
            from ..errors import ConfigError

            raise ConfigError(f"fused loop: {why}; run this simulation with use_fused = False")
        for k, v in bus.items():
            i = self.slot.get(k)
            if i is not None and (_numeric(v) or k in ENUMS):
                self.sig[i] = _code(k, v)


class _NoFused(Exception):
    pass


def _numeric(v) -> bool:
    return isinstance(v, (int, float, bool, np.floating, np.integer, np.bool_))


@dataclass(frozen=True)
class FirstTick:
    """What the Python clock's first tick would put on the bus (:func:`first_tick_plan`): ``before[i]``, the
    keys on the bus when block ``i`` fires (the plants' outputs, external inputs, and what the blocks
    before it wrote), and ``after``, the keys on the bus after the tick."""

    before: list[frozenset]
    after: frozenset


def first_tick_plan(sim) -> FirstTick | None:
    """The bus of ``sim``'s first tick, known from the declarations, so that the fused driver can run that
    tick too (the Python clock's :meth:`~oceangnc.core.law.LawBlock.step` would give the same signals); None
    when a part declares no outputs (the bus after the first tick then fixes the log columns) or a
    block's required input is not on the bus when it fires (the Python clock reports it).

    A block writes, at each firing, its :meth:`~oceangnc.core.blocks.Block.bus_outputs` (a
    :class:`~oceangnc.core.law.LawBlock`'s string outputs reach only the fused loop's array), and reads an
    optional input only when it is on the bus: at the first tick, an optional input written by a later
    block is absent (its default is used), as on the Python clock."""
    if any(getattr(p, "outputs", None) is None for p in [*sim.plants, *sim.blocks]):
        return None
    present = set(sim.bus)
    before: list[frozenset] = []
    for b in sim.blocks:
        if any(k not in present for k in (b.inputs or {})):
            return None
        before.append(frozenset(present))
        written = getattr(b, "bus_outputs", None)  # a block not derived from core.blocks.Block: its outputs
        present.update(written() if written is not None else b.outputs)
    return FirstTick(before, frozenset(present))


def build_fused(sim, plan: FirstTick | None = None):
    """``(FusedLoop, None)`` when every block and plant of ``sim`` has a compiled form, else ``(None, reason)``.

    ``plan`` (:func:`first_tick_plan`): the loop is built before the first tick, which its driver runs."""
    forms = []
    for b in sim.blocks:
        fn = getattr(b, "compiled", None)
        f = fn() if fn is not None else None
        if f is None:
            return None, f"block '{b.name}' ({type(b).__name__}) has no compiled form"
        forms.append(f)
    why = _strings_ok(sim.bus, list(zip(sim.blocks, forms)))
    if why is not None:
        return None, why
    try:
        return FusedLoop(sim, forms, plan), None
    except _NoFused as e:
        return None, str(e)


def log_rows_capacity(sim) -> int:
    """Rows of the log buffer: a few row groups' worth, at least 1."""
    return 2000


__all__ = [
    "CompiledBlock",
    "PlantForm",
    "FusedLoop",
    "FirstTick",
    "build_fused",
    "first_tick_plan",
    "plant_form",
    "math",
]
