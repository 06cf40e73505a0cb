"""The block registry: blocks registered under a kind name, picked by ``kind`` in a scenario's TOML.

>>> from oceangnc.core.registry import register_block, make_block, kinds
>>> @register_block("demo.constant")
... class Constant: ...

A kind is ``"<family>.<law>"`` (``"uuv.pid"``, ``"uuv.backstepping"``, ``"usv.los"``,
``"sensor.gps"``, ``"winch.drum"``). A user's block is registered the same way from their own
module, which oceangnc loads with ``--plugin path.py`` or through the ``oceangnc.blocks`` entry-point
group. :func:`make_block` on an unknown kind raises :class:`~oceangnc.errors.ConfigError` listing
the registered kinds of that family.
"""

from __future__ import annotations

import hashlib
import importlib
import importlib.util
import sys
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any, ClassVar

from pydantic import BaseModel, ConfigDict, Field, ValidationError, field_validator, model_validator

from ..errors import ConfigError, InputError
from .caches import add_sources, package_root, user_code
from .config import format_validation_error

_KINDS: dict[str, type] = {}
_ENTRY_POINTS_LOADED = False
_EPS: list | None = None
_OWN_EPS: list | None = None


def register_block(kind: str):
    """Class decorator registering a block class (or factory) under ``kind``; sets ``cls.kind``."""
    if not isinstance(kind, str) or "." not in kind:
        raise ValueError(f"block kind must look like 'family.name', got {kind!r}")

    def deco(cls):
        prev = _KINDS.get(kind)
        same = getattr(prev, "__qualname__", None) == getattr(cls, "__qualname__", None)
        if prev is not None and prev is not cls and not same:
            raise ValueError(f"block kind '{kind}' registered twice ({prev!r} and {cls!r})")
        _KINDS[kind] = cls
        try:
            cls.kind = kind
        except (AttributeError, TypeError):
            pass
        return cls

    return deco


def _add_package_sources(module: str) -> None:
    """Make the top-level package of ``module`` part of the compiled-code key before it is imported
    (:func:`oceangnc.core.caches.add_sources`): an edit of any of its files recompiles its kernels."""
    spec = importlib.util.find_spec(module.split(".")[0])
    if spec is None:
        return
    roots = list(spec.submodule_search_locations or ()) or ([spec.origin] if spec.origin else [])
    add_sources(roots[:1])


def _is_own(ep) -> bool:
    """An entry point of the oceangnc package itself (a built-in kind)."""
    return ep.module.split(".")[0] == "oceangnc"


def _entry_points() -> list:
    """The ``oceangnc.blocks`` entry points of every installed distribution (scanned once)."""
    global _EPS
    if _EPS is None:
        from importlib.metadata import entry_points

        _EPS = list(entry_points(group="oceangnc.blocks"))
        if not any(_is_own(ep) for ep in _EPS):
            raise InputError("oceangnc's block entry points are missing: install the package (pip install -e .)")
    return _EPS


def _load(ep) -> None:
    """Import one entry point: the package's own as is, a user's with its package in the code key and
    its errors reported in one line."""
    if _is_own(ep):
        ep.load()
        return
    try:
        _add_package_sources(ep.module)
        with user_code():
            ep.load()
    except Exception as exc:  # a user's package: report, don't trace back
        raise InputError(
            f"entry point {ep.name} = {ep.value} (group oceangnc.blocks): {type(exc).__name__}: {exc}"
        ) from exc


def _own_entry_points() -> list:
    """The package's own ``oceangnc.blocks`` entry points, from its own metadata (read once): finding
    a built-in kind does not read the entry points of every installed distribution (~15 ms with a few
    hundred of them, :func:`_entry_points`)."""
    global _OWN_EPS
    if _OWN_EPS is None:
        from importlib.metadata import PackageNotFoundError, distribution

        try:
            _OWN_EPS = [ep for ep in distribution("oceangnc").entry_points if ep.group == "oceangnc.blocks"]
        except PackageNotFoundError:
            _OWN_EPS = []
    return _OWN_EPS


def _load_named(kind: str) -> None:
    """Import the entry points named ``kind`` (the package names its entry points after the kinds
    their modules register, so one lookup imports one module, not all of them): the package's own
    if it has one of that name, else those of every installed distribution."""
    eps = [ep for ep in _own_entry_points() if ep.name == kind]
    for ep in eps or [ep for ep in _entry_points() if ep.name == kind]:
        _load(ep)


def _load_entry_points() -> None:
    """Import every ``oceangnc.blocks`` entry point, the package's own first (once)."""
    global _ENTRY_POINTS_LOADED
    if _ENTRY_POINTS_LOADED:
        return
    _ENTRY_POINTS_LOADED = True
    eps = _entry_points()
    for ep in sorted(eps, key=lambda ep: not _is_own(ep)):
        _load(ep)


def kinds(family: str | None = None) -> list[str]:
    """Registered kinds, sorted; only those starting with ``family + '.'`` if given."""
    _load_entry_points()
    return sorted(k for k in _KINDS if family is None or k.startswith(family + "."))


def kinds_for(family: str, role: str | None = None) -> list[str]:
    """Kinds of ``family`` whose class declares ``role`` (or declares no role)."""
    return [k for k in kinds(family) if role is None or getattr(_KINDS[k], "role", None) in (None, role)]


def full_kind(kind: str, family: str | None = None, role: str | None = None) -> str:
    """``kind`` as registered: a short name is looked up in ``family`` (``"pid"`` -> ``"uuv.pid"``),
    a dotted one as is (a user's ``"my.ctrl"`` may fill any slot). ValueError listing the kinds.

    A kind already registered (its module imported) is returned at once; another is looked up by
    importing the entry point named after it (each built-in kind has one); every entry point is
    imported (0.15-0.4 s of start-up) only when that finds nothing, or to list the kinds."""
    if not isinstance(kind, str) or not kind:
        raise ValueError(f"block kind must be a non-empty string, got {kind!r}")
    full = kind if "." in kind or family is None else f"{family}.{kind}"
    if full not in _KINDS:
        _load_named(full)
    if full not in _KINDS:
        _load_entry_points()
    if full not in _KINDS:
        fam = family or (kind.split(".")[0] if "." in kind else None)
        known = (kinds_for(fam, role) if fam else []) or kinds()
        raise ValueError(f"unknown block kind '{kind}'; registered: {', '.join(known)}")
    return full


def lookup(kind: str, key: str = "kind"):
    """The class registered under ``kind``; ConfigError naming ``key`` and the known kinds otherwise."""
    try:
        return _KINDS[full_kind(kind)]
    except ValueError as e:
        raise ConfigError(f"{key}: {e}") from None


def make_block(kind: str, *args, key: str = "kind", **kwargs):
    """Instantiate the block registered under ``kind`` with the given arguments."""
    return lookup(kind, key)(*args, **kwargs)


def load_plugin(path: str | Path) -> None:
    """Import a user's Python file so that its ``@register_block`` classes become available."""
    p = Path(path)
    if not p.is_file():
        raise InputError(f"--plugin: file not found: {p}")
    _load_entry_points()  # the built-in blocks first: their compiled functions keep the package's key
    add_sources([package_root(p)])  # its compiled functions cache under a key of its package's content
    # a stable name (str hashes change per process): generated drivers import its kernels by name
    name = f"oceangnc_plugin_{hashlib.blake2b(str(p.resolve()).encode(), digest_size=6).hexdigest()}"
    spec = importlib.util.spec_from_file_location(name, p)
    if spec is None or spec.loader is None:
        raise InputError(f"--plugin: cannot import {p} (not a Python file?)")
    mod = importlib.util.module_from_spec(spec)
    sys.modules[name] = mod
    try:
        with user_code():
            spec.loader.exec_module(mod)
    except Exception as exc:  # a user's file: report, don't trace back
        raise InputError(f"--plugin {p}: {type(exc).__name__}: {exc}") from exc


# -- picking blocks from a scenario's config ---------------------------------------------------------


@dataclass
class BlockContext:
    """What a scenario offers every block it builds from a ``kind``: the firing period and the wiring.

    A block takes nothing else from its scenario: no config, no scenario facts. What it needs (the
    vehicle it drives, a speed target, a formation geometry) is one of its own parameters (a field of
    its ``params_model``, filled by the scenario through ``build_block(..., given=...)``) or a declared
    input read from the bus, so it runs in every scenario that offers them, whatever that scenario's
    config looks like (``tests/test_block_context.py``).

    Attributes
    ----------
    period : float
        Firing period, s.
    signals : dict
        Role -> bus key of the measurements the scenario wires (roles are the truth signal
        names, e.g. ``"usv.psi"`` -> ``"usv_ahrs.psi"`` when sensors are on); see :meth:`signal`.
    """

    period: float
    signals: dict[str, str] = field(default_factory=dict)

    def signal(self, role: str) -> str:
        """The bus key wired to ``role`` (the role itself when the scenario maps nothing)."""
        return self.signals.get(role, role)


class BlockChoice(BaseModel):
    """A config slot picking a registered block: ``kind`` plus the block's own parameters.

    Subclasses set ``family`` (and optionally ``role``); ``kind = "pid"`` then means
    ``"uuv.pid"`` in the ``uuv`` family, a dotted kind (``"my.ctrl"``) is taken as is. Every other
    key is a parameter of the block, validated by the block's ``params_model`` (a pydantic model)
    when it is built. A plain string is accepted for the whole slot (``control.uuv = "pid"``, the
    older spelling).
    """

    model_config = ConfigDict(extra="allow", validate_assignment=True)
    family: ClassVar[str] = ""
    role: ClassVar[str | None] = None
    kind: str = Field(..., description="registered block kind: a name in the slot's family or family.name")

    @model_validator(mode="before")
    @classmethod
    def _from_string(cls, v):
        return {"kind": v} if isinstance(v, str) else v

    @field_validator("kind")
    @classmethod
    def _known(cls, v: str) -> str:
        full_kind(v, cls.family or None, cls.role)
        return v

    @model_validator(mode="after")
    def _own_parameters(self):
        """A parameter belongs to the selected kind: one of another kind is refused, never taken as a
        reason to switch kinds (issue 26)."""
        if not self.model_extra:  # nothing to check: the kind is resolved when the block is built
            return self
        try:
            cls = _KINDS.get(self.full_kind)
        except ValueError:
            return self
        model = getattr(cls, "params_model", None)
        if model is None:
            return self
        unknown = [k for k in self.model_extra if k not in model.model_fields]
        if unknown:
            raise ValueError(
                f"'{unknown[0]}' is not a parameter of kind '{self.kind}' (set kind to the block it belongs to); "
                f"its parameters: {', '.join(model.model_fields)}"
            )
        return self

    @property
    def full_kind(self) -> str:
        return full_kind(self.kind, self.family or None, self.role)

    @property
    def params(self) -> dict:
        """The block's parameters (every key but ``kind``)."""
        return dict(self.model_extra or {})


def build_block(choice: BlockChoice, ctx: BlockContext, key: str, base: dict | None = None, given: dict | None = None):
    """Build the block ``choice`` picks, with ``base`` parameters (the scenario's section for a
    built-in kind) updated by the choice's own keys, and the ``given`` values its ``params_model``
    declares.

    ``given`` is what the scenario offers every block of the slot, by parameter name (the vehicle
    config ``usv`` or ``uuv``, the surge target ``u_d``, the formation ``l_d``, ``lambda_d``,
    ``mode``): a block gets those its ``params_model`` has a field for, and the choice may not set
    them (their home is the scenario's own section; a ConfigError says so). A class with
    ``params_model`` gets its parameters validated into that model (a bad value is a ConfigError
    naming ``<key>.<param>``); one with a ``from_context(params, ctx)`` classmethod is built by it,
    any other as ``cls(params, ctx)``.
    """
    cls = lookup(choice.full_kind, f"{key}.kind")
    params: Any = {**(base or {}), **choice.params}
    model = getattr(cls, "params_model", None)
    if model is not None:
        for name in model.model_fields.keys() & (given or {}).keys():
            if name in choice.params:
                raise ConfigError(f"config error: {key}.{name} is set by the scenario, not by the block's slot")
            params[name] = given[name]  # type: ignore[index]
        try:
            params = model.model_validate(params)
        except ValidationError as err:
            msg = format_validation_error(model, err)
            if msg.startswith("config error: unknown key '"):
                msg = msg.replace("unknown key '", f"unknown key '{key}.", 1)
            else:
                msg = msg.replace("config error: ", f"config error: {key}.", 1)
            raise ConfigError(msg) from None
    factory = getattr(cls, "from_context", None)
    return factory(params, ctx) if factory is not None else cls(params, ctx)
