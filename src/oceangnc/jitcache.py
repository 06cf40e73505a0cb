"""Where oceangnc's numba functions are cached on disk, and how a cached run loads them (issue 19).

**Location.** numba caches an ``@njit(cache=True)`` function next to its source, in
``__pycache__``; a non-editable reinstall of the package deletes that folder with the old files, so
every model and controller was compiled again (15-60 s). :class:`PackageCacheLocator` keeps the
caches of the functions defined in oceangnc's own source files in the user cache folder instead::

    $OCEANGNC_CACHE_DIR/numba-<version>/<subpackage>/      (default root ~/.cache/oceangnc)

beside the generated stepper and fused-driver modules (``steppers-<version>``). numba stamps each
index with a hash of the source file's *content* (numba >= 0.60) and keys each entry by the
function's bytecode, the Python version and the CPU, so a reinstall of the same version (same
files, new mtimes) keeps every entry, while an edited file is compiled again. When the user sets
``NUMBA_CACHE_DIR`` numba's own choice is left alone. The locator is put first in numba's list of
locators by :func:`register` (through :mod:`oceangnc._numba_hook` as soon as numba is imported); it
answers only for files of this package, so other libraries' caches are unaffected.

**Loading.** Before loading a cached function numba refreshes its target context, which imports
and installs every implementation numba has (about 0.4-0.9 s of a run's start-up, more than the
cached flagship simulation). Loading machine code needs none of it: :func:`lean_loads` (used by the
``oceangnc run`` command) only initialises numba's runtime before a load. A function that must be
compiled still goes through numba's compiler, which refreshes the context itself.
"""

from __future__ import annotations

import contextlib
from pathlib import Path

from numba.core import caching, config

from .cachedir import versioned


def package_dir() -> Path:
    """The folder of the imported oceangnc package (its source files)."""
    return Path(__file__).resolve().parent


def package_cache_dir() -> Path:
    """Where the package's own compiled functions are cached: ``<cache_root>/numba-<version>``."""
    return versioned("numba")


class PackageCacheLocator(caching._SourceFileBackedLocatorMixin, caching._CacheLocator):  # type: ignore[name-defined]
    """numba cache locator for functions defined in oceangnc's source files (module docstring).

    The cache folder mirrors the package layout (``numba-0.1.0/models``, ``numba-0.1.0/core``, ...),
    so functions of equal names in different modules never meet; the source stamp is numba's
    content hash of the file.
    """

    def __init__(self, py_func, py_file):
        self._py_file = py_file
        self._lineno = py_func.__code__.co_firstlineno
        rel = Path(py_file).resolve().parent.relative_to(package_dir())
        self._cache_path = str(package_cache_dir().joinpath(*rel.parts))

    def get_cache_path(self):
        return self._cache_path

    @classmethod
    def from_function(cls, py_func, py_file):
        if config.CACHE_DIR:  # the user chose numba's cache folder: numba's own locator
            return None
        try:
            Path(py_file).resolve().relative_to(package_dir())
        except (ValueError, OSError):
            return None  # not a file of this package (user code, generated modules)
        return super().from_function(py_func, py_file)


def register() -> None:
    """Put :class:`PackageCacheLocator` first in numba's locators (idempotent)."""
    classes = caching.CacheImpl._locator_classes
    if not any(getattr(c, "__qualname__", None) == PackageCacheLocator.__qualname__ for c in classes):
        classes.insert(0, PackageCacheLocator)


register()  # importing this module is enough (oceangnc._numba_hook imports it when numba is imported)


def _lean_load_overload(self, sig, target_context):
    from numba.core.runtime import rtsys

    rtsys.initialize(target_context)  # what a cached function needs of the target's refresh: the runtime
    with self._guard_against_spurious_io_errors():
        return self._load_overload(sig, target_context)


@contextlib.contextmanager
def lean_loads():
    """Within the block, numba loads cached functions without refreshing its target context.

    Falls back to numba's normal loading if its ``Cache.load_overload`` is not the one this was
    written for (refresh, then ``_load_overload``), so a numba upgrade cannot break a run.
    """
    orig = caching.Cache.load_overload
    code = getattr(orig, "__code__", None)
    known = code is not None and {"refresh", "_load_overload", "_guard_against_spurious_io_errors"} <= set(
        code.co_names
    )
    if not known:
        yield
        return
    caching.Cache.load_overload = _lean_load_overload  # type: ignore[method-assign]
    try:
        yield
    finally:
        caching.Cache.load_overload = orig  # type: ignore[method-assign]
