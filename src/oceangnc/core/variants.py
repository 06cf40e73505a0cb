"""Compiled functions without the features a configuration does not use (issue 25: compile less).

A plant whose compiled laws carry optional features (a winch, a seabed, waves...) writes each law
once, with each optional part behind a *switch*: a module-level constant tested before the runtime
flag, ``if WINCH and p[H_WIN] > 0.5:``. The module sets every switch to True, so the functions as
written handle every configuration and the runtime flags decide.

:class:`Variants` gives copies of a group of such functions in which chosen switches are False. A
global is a compile-time constant to numba, whose dead-branch pruning removes a branch on a False
constant before typing: the code behind it, and every function only it calls, is never typed,
optimised or linked into the callers. A calm-water plant without winch, seabed or bridle then
compiles none of those laws (and its deep call chains are optimised without them at every level).
Nothing is written twice: a copy is the same code object over a copy of its module's globals, in
which the switches take the variant's values and each member of the group names its copy.

Each copy is a compiled function of its own, cached on disk by numba like the original: its name
(and so numba's cache file and symbol names) carries the switches' values, ``imex_advance__sea0_bed0``,
and the module holding the group resolves such names (its ``__getattr__`` calls
:meth:`Variants.attribute`), so a generated fused driver imports a copy by name like any kernel.

The group must be closed: a compiled function that reads a switch, or calls a member, must itself
be a member (else it would call the full-featured original). The constructor checks that.
"""

from __future__ import annotations

import types
from collections.abc import Iterable, Mapping

from numba import njit


def _is_compiled(v) -> bool:
    return hasattr(v, "py_func") and hasattr(v, "overloads")


class Variants:
    """A group of compiled functions and their copies per value of the switches.

    Parameters
    ----------
    home : name of the module whose ``__getattr__`` resolves the copies' names (``__name__`` of
        the module that builds this object).
    switches : the switch names (module-level constants, True in the modules of the members).
    members : the compiled functions (numba dispatchers) of the group.
    """

    def __init__(self, home: str, switches: Iterable[str], members: Iterable):
        self.home = home
        self.switches = tuple(switches)
        self._members = {d.py_func.__name__: d for d in members}
        self._made: dict[tuple[bool, ...], dict] = {}
        self._check()

    # -- the group -----------------------------------------------------------------------------------
    def _reads(self, d, memo: dict) -> bool:
        """Whether compiled function ``d`` reads a switch or calls a member, directly or through callees."""
        key = id(d)
        if key in memo:
            return memo[key]
        memo[key] = False  # recursion guard
        fn = d.py_func
        names = fn.__code__.co_names
        hit = any(s in names for s in self.switches)
        for name in names:
            v = fn.__globals__.get(name)
            if hit:
                break
            if _is_compiled(v):
                hit = v in self._members.values() or self._reads(v, memo)
        memo[key] = hit
        return hit

    def _check(self) -> None:
        memo: dict = {}
        for name, d in self._members.items():
            fn = d.py_func
            for s in self.switches:
                if s in fn.__code__.co_names and fn.__globals__.get(s) is not True:
                    raise TypeError(f"{fn.__module__}.{name} reads switch {s}, which its module must set to True")
            for callee in fn.__code__.co_names:
                v = fn.__globals__.get(callee)
                if _is_compiled(v) and v not in self._members.values() and self._reads(v, memo):
                    raise TypeError(
                        f"{fn.__module__}.{name} calls {callee}, which reads a switch or calls a member of "
                        f"the group: make {callee} a member of the {self.home} variants"
                    )

    def tag(self, values: tuple[bool, ...]) -> str:
        """The suffix of the copies' names for switch ``values`` (in the order of ``switches``)."""
        return "_".join(f"{s.lower()}{int(v)}" for s, v in zip(self.switches, values))

    # -- copies ----------------------------------------------------------------------------------------
    def get(self, **on: bool) -> Mapping:
        """The group's functions by name for the switches ``on`` (every switch named): the originals when
        every switch is on, else the copies (either mapping made once per process)."""
        missing = set(self.switches) ^ set(on)
        if missing:
            raise TypeError(f"Variants.get: give exactly the switches {self.switches} (got {sorted(on)})")
        values = tuple(bool(on[s]) for s in self.switches)
        made = self._made.get(values)
        if made is None:
            made = self._made[values] = dict(self._members) if all(values) else self._copies(values)
        return made

    def _copies(self, values: tuple[bool, ...]) -> dict:
        tag = self.tag(values)
        envs, made = {}, {}
        for name, d in self._members.items():
            fn = d.py_func
            env = dict(fn.__globals__)
            env.update(zip(self.switches, values))
            vname = f"{name}__{tag}"
            cp = types.FunctionType(fn.__code__, env, vname, fn.__defaults__, fn.__closure__)
            cp.__qualname__ = vname
            cp.__module__ = self.home
            cp.__doc__ = fn.__doc__
            cp.__kwdefaults__ = fn.__kwdefaults__
            envs[name] = env
            opts = {k: v for k, v in d.targetoptions.items() if k != "nopython"}  # inline=..., fastmath=...
            made[name] = njit(cache=True, **opts)(cp)
        copy_of = {id(d): made[name] for name, d in self._members.items()}
        for env in envs.values():  # every member calls the copies (under whatever name it imports them)
            for k, v in list(env.items()):
                if id(v) in copy_of:
                    env[k] = copy_of[id(v)]
        return made

    def attribute(self, name: str):
        """The copy named ``name`` (``<member>__<tag>``), for the home module's ``__getattr__``."""
        base, sep, tag = name.rpartition("__")
        if sep and base in self._members:
            for values in _all_values(len(self.switches)):
                if self.tag(values) == tag:
                    return self.get(**dict(zip(self.switches, values)))[base]
        raise AttributeError(f"module {self.home!r} has no attribute {name!r}")


def _all_values(n: int) -> list[tuple[bool, ...]]:
    return [tuple(bool(i >> k & 1) for k in range(n)) for i in range(2**n)]
