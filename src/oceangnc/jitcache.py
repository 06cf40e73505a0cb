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
import functools
import os
from pathlib import Path

from numba.core import caching, config

from .cachedir import versioned


def package_dir() -> Path:
    """The folder of the imported oceangnc package (its source files)."""
    return Path(__file__).resolve().parent


def package_cache_dir() -> Path:
    """Where the package's own compiled functions are cached: ``<cache_root>/numba-<version>``."""
    return versioned("numba")


@functools.cache
def _package_parts(py_file: str) -> tuple[str, ...] | None:
    """The sub-package folders of a source file of this package (``("models",)``), None for other files.

    Memoised: numba asks once per decorated function (about 100 at a flagship's start-up), and each
    answer resolves paths on disk.
    """
    try:
        return Path(py_file).resolve().parent.relative_to(package_dir()).parts
    except (ValueError, OSError):
        return None


#: cache folders this process has made and found writable (numba checks each function's folder by
#: creating a temporary file in it; once per folder is enough)
_READY: set[str] = set()


class PackageCacheLocator(caching._SourceFileBackedLocatorMixin, caching._CacheLocator):  # type: ignore[name-defined]
    """numba cache locator for functions defined in oceangnc's source files (module docstring).

    The cache folder mirrors the package layout (``numba-0.1.0/models``, ``numba-0.1.0/core``, ...),
    so functions of equal names in different modules never meet; the source stamp is numba's
    content hash of the file.
    """

    def __init__(self, py_func, py_file):
        self._py_file = py_file
        self._lineno = py_func.__code__.co_firstlineno
        self._cache_path = os.path.join(package_cache_dir(), *(_package_parts(py_file) or ()))

    def get_cache_path(self):
        return self._cache_path

    def ensure_cache_path(self):
        if self._cache_path not in _READY:
            super().ensure_cache_path()
            _READY.add(self._cache_path)

    @classmethod
    def from_function(cls, py_func, py_file):
        if config.CACHE_DIR:  # the user chose numba's cache folder: numba's own locator
            return None
        if _package_parts(py_file) is None:
            return None  # not a file of this package (user code, generated modules)
        return super().from_function(py_func, py_file)


def register() -> None:
    """Put :class:`PackageCacheLocator` first in numba's locators (idempotent)."""
    classes = caching.CacheImpl._locator_classes
    if not any(getattr(c, "__qualname__", None) == PackageCacheLocator.__qualname__ for c in classes):
        classes.insert(0, PackageCacheLocator)


register()  # importing this module is enough (oceangnc._numba_hook imports it when numba is imported)


def _init_runtime(target_context) -> None:
    """numba's runtime (NRT) initialised with its small LLVM library loaded from the cache folder.

    ``rtsys.initialize`` registers the runtime's C helpers with LLVM and compiles a dozen functions
    (reference counts, atomics) from IR on every process start (~30 ms); here the compiled object code
    is kept beside the package's numba caches, keyed by numba's and llvmlite's versions and the CPU
    (numba's own ``magic_tuple``). Anything unexpected falls back to ``rtsys.initialize``.
    """
    import hashlib
    import pickle

    import llvmlite
    import numba
    from llvmlite import binding as ll
    from numba.core.compiler_lock import global_compiler_lock
    from numba.core.runtime import _nrt_python, nrtdynmod, rtsys

    if rtsys._init:
        return
    try:
        with global_compiler_lock:
            codegen = target_context.codegen()
            key = repr((numba.__version__, llvmlite.__version__, codegen.magic_tuple())).encode()
            path = package_cache_dir() / f"nrt-{hashlib.sha1(key).hexdigest()[:16]}.pkl"
            if config.NRT_STATS:
                _nrt_python.memsys_enable_stats()
            for py_name, address in _nrt_python.c_helpers.items():  # as rtsys.initialize does
                ll.add_symbol(py_name if py_name.startswith("_") else "NRT_" + py_name, address)
            try:
                library = codegen.unserialize_library(pickle.loads(path.read_bytes()))
            except (OSError, EOFError, pickle.UnpicklingError, ValueError, TypeError):
                ir_module, library = nrtdynmod.create_nrt_module(target_context)
                library.enable_object_caching()
                library.add_ir_module(ir_module)
                library.finalize()
                _write_atomic(path, pickle.dumps(library.serialize_using_object_code()))
            rtsys._library = library
            rtsys._init = True
    except Exception:  # a numba whose runtime differs from the one this was written for
        if not rtsys._init:
            rtsys.initialize(target_context)


def _write_atomic(path: Path, data: bytes) -> None:
    try:
        path.parent.mkdir(parents=True, exist_ok=True)
        tmp = path.with_name(f".{path.name}.{os.getpid()}.tmp")
        tmp.write_bytes(data)
        os.replace(tmp, path)
    except OSError:
        pass  # a read-only cache folder: compiled again next time


def _lean_load_overload(self, sig, target_context):
    _init_runtime(target_context)  # what a cached function needs of the target's refresh: the runtime
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
