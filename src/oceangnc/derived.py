"""Values derived from a model by a numerical search, computed once per machine and kept on disk.

Building the flagship scenario needs the vehicles' minimum turning radii (the look-ahead distance of
003 eq. 3.6), found by trimming the USV and UUV models: a few dozen calls of the compiled models,
which cost little themselves but make the process load those models' machine code and SciPy's BLAS
(0.3-0.5 s of a cached run's start-up), while the fused simulation needs neither. :func:`cached`
stores such a value in ``<cache root>/derived-<version>/<name>-<key hash>.json``, keyed by its
inputs and by the content of the source files it depends on, so an edited model computes it again.
The stored floats round-trip exactly (JSON keeps the shortest repr), so a run from the stored value
is bit-identical to one that computes it.
"""

from __future__ import annotations

import functools
import hashlib
import json
import os
from collections.abc import Callable, Iterable
from pathlib import Path

from .cachedir import versioned


def _package_dir() -> Path:
    return Path(__file__).resolve().parent


def _cache_dir() -> Path:
    return versioned("derived")


@functools.lru_cache(maxsize=8)
def sources_digest(subpackages: tuple[str, ...]) -> str:
    """SHA-256 of the ``.py`` files under the given subpackages of oceangnc (names relative to it).

    Once per process (a batch builds many runs; ~3 ms per call otherwise): an edit is seen by the
    next process, as numba's caches see it."""
    h = hashlib.sha256()
    base = _package_dir()
    for sub in subpackages:
        for p in sorted((base / sub).rglob("*.py")):
            h.update(str(p.relative_to(base)).encode())
            h.update(p.read_bytes())
    return h.hexdigest()


def cached(name: str, key, compute: Callable[[], list], sources: Iterable[str]) -> list:
    """``compute()`` (a list of floats) for these inputs, from the disk if it was computed before.

    ``key`` is any JSON-serialisable description of the inputs; ``sources`` the subpackages whose
    code the value depends on. An unreadable or unwritable cache just computes the value.
    """
    blob = json.dumps([key, sources_digest(tuple(sources))], sort_keys=True, default=str)
    path = _cache_dir() / f"{name}-{hashlib.sha256(blob.encode()).hexdigest()[:20]}.json"
    try:
        return list(json.loads(path.read_text()))
    except (OSError, ValueError):
        pass
    value = list(compute())
    try:
        path.parent.mkdir(parents=True, exist_ok=True)
        tmp = path.with_name(f".{path.name}.{os.getpid()}.tmp")
        tmp.write_text(json.dumps(value))
        os.replace(tmp, path)  # atomic: concurrent runs never read half a file
    except OSError:
        pass
    return value
