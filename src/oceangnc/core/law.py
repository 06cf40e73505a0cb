"""One law per block (issue 25): a block's arithmetic is one compiled function in the block's own file.

A :class:`LawBlock` declares, once and by name,

* its **signals** (:class:`Signals`): roles in slot order, each an input (:func:`In`), an optional
  input (:func:`Opt`, slot -1 when nobody writes it) or an output (:func:`Out`), with its unit;
* its **parameters** and **state** (:class:`Layout`): named entries of two flat float64 arrays;

and names its **law**, one ``@njit(cache=True)`` function of the block's module::

    law(t, sig, sl, st, pa)            # or law(t, sig, sl, st, pa, rng) for a block drawing noise

which reads its inputs as ``sig[sl[S.z]]``, writes its outputs as ``sig[sl[S.volt]] = v``, updates
its state ``st[X.y]`` in place and reads its parameters ``pa[P.gain]``, where ``S``, ``X`` and ``P``
are the layouts' ``at`` records (namedtuples of offsets, frozen into the compiled code as
constants): no hand-kept ``pa[5]``. The fused loop (:mod:`oceangnc.core.fused`) calls the law tick by
tick with slots into its signal array; the block's Python :meth:`LawBlock.step` (the console, the
Python clock, user glue) calls *the same compiled function* with a small signal array gathered from
the bus. The law is written once, its random draws are made once, and the state array is shared:
after a fused run the block holds the fused state.

A block's bus names carry prefixes known only when it is built (``uuv.z``, ``usv_gps.x``), so
:meth:`LawBlock.bind` maps each role to its bus key and generates the declared ``inputs``,
``optional_inputs`` and ``outputs`` (units from the roles) that the wiring check reads. A block
written in plain Python (a :class:`~oceangnc.core.blocks.Block` with its own ``step``) still runs,
on the Python clock; ``oceangnc run --verbose`` says why.
"""

from __future__ import annotations

from collections import namedtuple
from collections.abc import Callable, Mapping
from dataclasses import dataclass
from typing import Any

import numpy as np

from .blocks import Block
from .fused import CompiledBlock
from .fused_strings import ENUMS
from .fused_strings import code as _code

IN, OPT, EXT, OUT = "in", "opt", "ext", "out"

#: flags for a law's callees as numpy scalars, not Python literals: numba compiles a callee once per
#: *literal* argument value, so ``pid_run(..., True, ...)`` and ``pid_run(..., False, ...)`` would be two
#: compilations of the same function (a first run's compile time, issue 25)
TRUE, FALSE = np.bool_(True), np.bool_(False)


@dataclass(frozen=True)
class Role:
    """One signal of a law: its direction (``in``, ``opt``, ``out``), unit, and ``size`` slots."""

    kind: str
    unit: str
    size: int = 1


def In(unit: str, size: int = 1) -> Role:  # noqa: N802 (a declaration reads like a type)
    """A required input (the wiring check refuses a simulation where nobody writes it)."""
    return Role(IN, unit, size)


def Opt(unit: str, size: int = 1) -> Role:  # noqa: N802
    """An optional input: slot -1 when nobody writes it (the law uses its own default)."""
    return Role(OPT, unit, size)


def Ext(unit: str, size: int = 1) -> Role:  # noqa: N802
    """An external input (an operator's: ``console.mode``, ``joystick.surge``): optional for the wiring
    check, but always given a slot, holding 0 (or -1 for an :data:`~oceangnc.core.fused_strings.ENUMS`
    string) while absent, so that a value injected into the bus later (console, MAVLink) reaches the law."""
    return Role(EXT, unit, size)


def Out(unit: str, size: int = 1) -> Role:  # noqa: N802
    """An output, written every time the law runs (held on the bus until the next run)."""
    return Role(OUT, unit, size)


def _record(typename: str, names, offsets):
    return namedtuple(typename, names)(*offsets) if names else ()


class Layout:
    """Named offsets in a flat float64 array (a law's parameters or state), generated from names.

    ``Layout("offset", "gain", ("ring", 30))``: scalars, or ``(name, size)`` blocks. ``.at`` is a
    namedtuple of offsets for compiled code (``pa[P.gain]``); :meth:`pack` builds the array from
    ``{name: value}`` (every entry given), :meth:`unpack` reads it back.
    """

    def __init__(self, *fields: str | tuple[str, int]):
        names, sizes = [], []
        for f in fields:
            n, k = (f, 1) if isinstance(f, str) else (f[0], int(f[1]))
            if n in names:
                raise ValueError(f"layout entry '{n}' declared twice")
            names.append(n)
            sizes.append(k)
        self.names: tuple[str, ...] = tuple(names)
        self.sizes: tuple[int, ...] = tuple(sizes)
        self.offsets: tuple[int, ...] = tuple(int(v) for v in np.cumsum([0, *sizes[:-1]])) if names else ()
        self.size = int(sum(sizes))
        self.at = _record("At", names, self.offsets)

    def pack(self, values: Mapping[str, object] | None = None, **kw) -> np.ndarray:
        """``{name: value (or array of its size)}`` -> a new flat array; every entry must be given."""
        values = {**(values or {}), **kw}
        missing = [n for n in self.names if n not in values]
        extra = [k for k in values if k not in self.names]
        if missing or extra:
            raise ValueError(f"pack: missing {missing}, unknown {extra}")
        a = np.zeros(max(self.size, 1))
        for n, o, k in zip(self.names, self.offsets, self.sizes):
            a[o : o + k] = values[n]  # type: ignore[call-overload]
        return a

    def unpack(self, a: np.ndarray) -> dict:
        """The array as ``{name: float or array}``."""
        return {
            n: (float(a[o]) if k == 1 else a[o : o + k].copy()) for n, o, k in zip(self.names, self.offsets, self.sizes)
        }


class Signals(Layout):
    """A law's signals by role, in slot order: ``Signals(z=In("m"), volt=Out("V"))``; ``.at.z`` is
    the role's slot number, ``.roles`` the declarations."""

    def __init__(self, **roles: Role):
        super().__init__(*[(n, r.size) for n, r in roles.items()])
        self.roles: dict[str, Role] = dict(roles)


_MISSING = object()


def entry(array: str, offset: int, cast: Callable = float, doc: str = "") -> property:
    """A block attribute that *is* ``self.<array>[offset]`` (``array`` "st" for the state, "pa" for the
    parameters), read as ``cast`` (``float``, ``int`` or ``bool``) and stored as a float (a bool as 1.0
    / 0.0): a change made while running reaches the law, on the Python clock and in the fused loop."""

    def fget(self):
        return cast(getattr(self, array)[offset])

    def fset(self, value) -> None:
        getattr(self, array)[offset] = float(value)

    return property(fget, fset, doc=doc)


def param(offset: int, doc: str = "") -> property:
    """A float attribute that *is* one entry of the block's parameter array (``hi = param(P.hi, "N")``)."""
    return entry("pa", offset, float, doc)


class LawBlock(Block):
    """A block whose law is one compiled function (module docstring).

    Subclasses set the class attributes ``law`` (``staticmethod`` of the ``@njit`` law), ``signals``
    (:class:`Signals`) and ``draws`` (True when the law takes the block's random generator), and in
    ``__init__`` call :meth:`bind` and set ``self.pa`` (parameters) and ``self.st`` (state), both
    flat float64 arrays (:meth:`Layout.pack`). :meth:`reset` implementations change ``self.st`` in
    place or assign a new array before the loop is built.
    """

    law: Any = None
    signals: Signals = Signals()
    draws: bool = False
    pa: np.ndarray
    st: np.ndarray
    rng = None

    def bind(self, **names: str | list[str]) -> None:
        """Map each role to its bus key (a list of keys for a role of size > 1) and declare the
        block's ``inputs``, ``optional_inputs`` and ``outputs`` with the roles' units."""
        missing = [r for r in self.signals.roles if r not in names]
        extra = [r for r in names if r not in self.signals.roles]
        if missing or extra:
            raise ValueError(f"{type(self).__name__}.bind: missing roles {missing}, unknown {extra}")
        wiring: list[tuple[str, str]] = []
        decl: dict[str, dict[str, str]] = {IN: {}, OPT: {}, EXT: {}, OUT: {}}
        for role, r in self.signals.roles.items():
            keys = names[role]
            keys = [keys] if isinstance(keys, str) else list(keys)
            if len(keys) != r.size:
                raise ValueError(f"{type(self).__name__}.bind: role '{role}' takes {r.size} names, got {len(keys)}")
            for k in keys:
                wiring.append((k, r.kind))
                decl[r.kind][k] = r.unit
        self.inputs, self.optional_inputs, self.outputs = decl[IN], {**decl[OPT], **decl[EXT]}, decl[OUT]
        self._wiring = wiring
        self._sig = np.zeros(max(len(wiring), 1))
        self._sl = np.arange(max(len(wiring), 1), dtype=np.int64)
        self._outs = [(j, k) for j, (k, kind) in enumerate(wiring) if kind == OUT and k not in ENUMS]

    def get_state(self) -> dict:
        """The block's state for a checkpoint: its state and parameter arrays (parameters may be drawn
        at reset, e.g. a sensor's offset) and its generator's state, as plain arrays and dicts."""
        state = {"st": self.st.copy(), "pa": self.pa.copy()}
        if self.rng is not None:
            state["rng"] = self.rng.bit_generator.state
        return state

    def set_state(self, state: dict) -> None:
        """Restore :meth:`get_state`, in place: the fused loop holds these very arrays and generator."""
        self.st[:] = state["st"]
        self.pa[:] = state["pa"]
        if "rng" in state and self.rng is not None:
            self.rng.bit_generator.state = state["rng"]

    def slot_names(self) -> list[str]:
        """The bound bus keys in slot order (``?key`` for an optional input), as the fused loop wants."""
        return [("?" + k if kind == OPT else k) for k, kind in self._wiring]

    def compiled(self) -> CompiledBlock:
        """The fused loop's form: the very law :meth:`step` calls, on the block's own state array."""
        return CompiledBlock(type(self).law, self.slot_names(), self.st, self.pa, rng=self.rng if self.draws else None)

    def bus_outputs(self) -> list[str]:
        """The keys :meth:`step` writes on the bus: the declared outputs that are numbers (a string
        output's code reaches only the fused loop's signal array)."""
        return [k for _, k in self._outs]

    def compile_jobs(self) -> list[tuple]:
        """The law with arguments of the types :meth:`step` and the fused loop pass
        (:func:`oceangnc.core.caches.compile_ahead`)."""
        if type(self).law is None or not hasattr(self, "_sig"):
            return []
        args: tuple = (0.0, self._sig, self._sl, self.st, self.pa)
        if self.draws:
            args += (self.rng if self.rng is not None else np.random.default_rng(0),)
        return [(type(self).law, args)]

    def step(self, t: float, bus: dict) -> None:
        """Gather the bound signals from ``bus``, run the compiled law, write the outputs back."""
        sig, sl = self._sig, self._sl
        for j, (k, kind) in enumerate(self._wiring):
            v = bus.get(k, _MISSING)
            if v is _MISSING:
                if kind == IN:
                    raise KeyError(k)
                sl[j] = -1 if kind == OPT else j
                sig[j] = _code(k, None)  # an absent external input: 0, or -1 for a string's code
            else:
                sl[j] = j
                sig[j] = _code(k, v)
        law = type(self).law
        if self.draws:
            law(float(t), sig, sl, self.st, self.pa, self.rng)
        else:
            law(float(t), sig, sl, self.st, self.pa)
        for j, k in self._outs:
            bus[k] = float(sig[j])


__all__ = ["TRUE", "FALSE", "entry", "param", "In", "Opt", "Ext", "Out", "Role", "Layout", "Signals", "LawBlock"]
