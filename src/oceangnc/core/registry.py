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

import importlib.util
import sys
from pathlib import Path

from ..errors import ConfigError, InputError

_KINDS: dict[str, type] = {}
_ENTRY_POINTS_LOADED = False


def register_block(kind: str):
    """Class decorator registering a block class (or factory) under ``kind``; sets ``cls.kind``."""
    if not isinstance(kind, str) or "." not in kind:
        raise ValueError(f"block kind must look like 'family.name', got {kind!r}")

    def deco(cls):
        prev = _KINDS.get(kind)
        if prev is not None and prev is not cls and getattr(prev, "__qualname__", None) != getattr(cls, "__qualname__", None):
            raise ValueError(f"block kind '{kind}' registered twice ({prev!r} and {cls!r})")
        _KINDS[kind] = cls
        try:
            cls.kind = kind
        except (AttributeError, TypeError):
            pass
        return cls

    return deco


def _load_entry_points() -> None:
    global _ENTRY_POINTS_LOADED
    if _ENTRY_POINTS_LOADED:
        return
    _ENTRY_POINTS_LOADED = True
    from importlib.metadata import entry_points

    for ep in entry_points(group="oceangnc.blocks"):
        ep.load()


def kinds(family: str | None = None) -> list[str]:
    """Registered kinds, sorted; only those starting with ``family + '.'`` if given."""
    _load_entry_points()
    return sorted(k for k in _KINDS if family is None or k.startswith(family + "."))


def lookup(kind: str, key: str = "kind"):
    """The class registered under ``kind``; ConfigError naming ``key`` and the known kinds otherwise."""
    _load_entry_points()
    if kind not in _KINDS:
        family = kind.split(".")[0] if "." in kind else None
        known = kinds(family) or kinds()
        raise ConfigError(f"{key}: unknown block kind '{kind}'; registered: {', '.join(known)}")
    return _KINDS[kind]


def make_block(kind: str, *args, key: str = "kind", **kwargs):
    """Instantiate the block registered under ``kind`` with the given arguments."""
    return lookup(kind, key)(*args, **kwargs)


def load_plugin(path: str | Path) -> None:
    """Import a user's Python file so that its ``@register_block`` classes become available."""
    p = Path(path)
    if not p.is_file():
        raise InputError(f"--plugin: file not found: {p}")
    name = f"oceangnc_plugin_{abs(hash(str(p.resolve())))}"
    spec = importlib.util.spec_from_file_location(name, p)
    if spec is None or spec.loader is None:
        raise InputError(f"--plugin: cannot import {p} (not a Python file?)")
    mod = importlib.util.module_from_spec(spec)
    sys.modules[name] = mod
    try:
        spec.loader.exec_module(mod)
    except Exception as exc:  # a user's file: report, don't trace back
        raise InputError(f"--plugin {p}: {type(exc).__name__}: {exc}") from exc
