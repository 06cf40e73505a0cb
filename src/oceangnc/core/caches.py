"""Every cache of oceangnc, and the key that keeps them from going stale (issue 25).

oceangnc keeps three things on disk so that a second run starts at once: numba's machine code of
the package's ``@njit(cache=True)`` functions, the generated steppers and fused-loop drivers
(:func:`oceangnc.core.integrators.load_generated`), and values derived from the models by a
numerical search (:func:`cached`). All of them live under one **code key**, a hash of the *meaning*
(syntax tree, without comments and docstrings) of the package's modules that compiled code can depend
on (:mod:`oceangnc.core.source_keys`)::

    <root>/numba-<version>-<key>/        numba's caches (NUMBA_CACHE_DIR of the process)
    <root>/steppers-<version>-<key>/     generated modules and their numba caches
    <root>/derived-<version>-<key>/      derived values (JSON)

numba keys a cached function on its *own* source file only, so a kernel that calls a law in another
file would keep the old law after that file is edited (the mixed result of issue 25). Here any edit
that compiled code can see gives a new key, hence new, empty folders: a compiled function can never
run with an old callee. A reinstall of the same files (new mtimes, same content), an edit of a comment
or a docstring, or of a module no compiled function reaches (a CLI, a server), keeps the key and every
cache (numba itself recompiles the functions of a file whose time stamp changed). Old key folders are
pruned (:func:`prune`, the newest :data:`KEEP` of each kind stay).

A user's compiled code (a ``--plugin`` file, an ``oceangnc.blocks`` entry point) is keyed by the
package *and* its own package's files (:func:`add_sources`, :func:`user_code`): numba caches the
functions decorated while it is imported under ``numba-<version>-<combined key>``, so an edit of
any file of the user's package recompiles them (and not oceangnc); the generated fused driver names
the fingerprint of the user kernels it calls in its source (:func:`oceangnc.core.fused.kernels_key`).

The root is ``$OCEANGNC_CACHE_DIR``, else ``$XDG_CACHE_HOME/oceangnc`` (default
``~/.cache/oceangnc``); a ``NUMBA_CACHE_DIR`` set by the user is the base of the numba folder
instead. The key of a tree is computed once and remembered under ``<root>/keys/`` against the files'
(name, mtime, ctime, inode, size) list, so a process pays a few ``stat`` calls (about 1 ms), not a read
of 1.2 MB; an edit re-parses only the files it touched.

Nothing here imports numba at module level (``import oceangnc`` must stay light); the process's
numba folder is set through numba's own ``NUMBA_CACHE_DIR`` setting (:func:`configure_numba`), with
no change to numba's code.
"""

from __future__ import annotations

import contextlib
import functools
import hashlib
import json
import os
import shutil
import sys
from collections.abc import Callable, Iterable
from pathlib import Path

from .._version import __version__
from . import source_keys

#: key folders kept per kind (numba, steppers, derived); older ones are deleted by :func:`prune`
KEEP = 4

_PKG = Path(__file__).resolve().parents[1]  # the oceangnc package folder
_EXTRA: dict[str, str] = {}  # plugin source path -> its key (add_sources)


def cache_root() -> Path:
    """``$OCEANGNC_CACHE_DIR``, else ``$XDG_CACHE_HOME/oceangnc`` (default ``~/.cache/oceangnc``)."""
    root = os.environ.get("OCEANGNC_CACHE_DIR")
    if not root:
        base = os.environ.get("XDG_CACHE_HOME") or os.path.join(os.path.expanduser("~"), ".cache")
        root = os.path.join(base, "oceangnc")
    return Path(root)


def _write_atomic(path: Path, data: str) -> None:
    try:
        path.parent.mkdir(parents=True, exist_ok=True)
        tmp = path.with_name(f".{path.name}.{os.getpid()}.tmp")
        tmp.write_text(data)
        os.replace(tmp, path)  # concurrent processes never read half a file
    except OSError:
        pass  # a read-only cache folder: computed again next time


def tree_key(path: Path, closure: bool = False) -> str:
    """:func:`oceangnc.core.source_keys.tree_key` with its memos under ``<root>/keys/``."""
    return source_keys.tree_key(path, cache_root() / "keys", _write_atomic, closure)


@functools.cache
def package_key() -> str:
    """The code key of the oceangnc package's own sources (once per process): the content, without
    comments and docstrings, of the modules compiled code can depend on (:func:`compiled_closure`)."""
    return tree_key(_PKG, closure=True)


def code_key() -> str:
    """The key of the package with the user sources added so far (:func:`add_sources`)."""
    if not _EXTRA:
        return package_key()
    h = hashlib.blake2b(package_key().encode(), digest_size=8)
    for p in sorted(_EXTRA):
        h.update(f"{p}\0{_EXTRA[p]}".encode())
    return h.hexdigest()


def keyed(kind: str) -> Path:
    """``<root>/<kind>-<version>-<package key>``: the folder of one kind of cache for this code."""
    return cache_root() / f"{kind}-{__version__}-{package_key()}"


def _numba_base() -> str:
    """The user's ``NUMBA_CACHE_DIR`` (not one this module set), else the base remembered from the
    parent process, else "" (the cache root)."""
    cur = os.environ.get("NUMBA_CACHE_DIR")
    if cur and cur != os.environ.get("OCEANGNC_NUMBA_SET"):
        return cur
    return os.environ.get("OCEANGNC_NUMBA_BASE", "")


def numba_dir(key: str | None = None) -> Path:
    """numba's cache folder for code of this key (default: the package's): under the user's
    ``NUMBA_CACHE_DIR`` if set, else the cache root."""
    key = key or package_key()
    base = _numba_base()
    return Path(base) / f"oceangnc-{__version__}-{key}" if base else cache_root() / f"numba-{__version__}-{key}"


def configure_numba(key: str | None = None) -> None:
    """Point numba's cache folder (``NUMBA_CACHE_DIR``) at :func:`numba_dir` of ``key``.

    Called by ``import oceangnc``, before numba is imported, for the package's key; numba reads
    the folder when a function is decorated, so each function caches under the key of the code
    that was current then (:func:`user_code`). If numba is loaded its configuration is re-read.
    Child processes inherit the setting and the user's base (``OCEANGNC_NUMBA_BASE``); a
    ``NUMBA_CACHE_DIR`` the user sets for a child wins.
    """
    base = _numba_base()
    target = str(numba_dir(key))
    os.environ["OCEANGNC_NUMBA_BASE"] = base
    os.environ["OCEANGNC_NUMBA_SET"] = target
    if os.environ.get("NUMBA_CACHE_DIR") == target:
        return
    os.environ["NUMBA_CACHE_DIR"] = target
    cfg = sys.modules.get("numba.core.config")
    if cfg is not None:
        cfg.reload_config()


def package_root(path: str | Path) -> Path:
    """The top-level package folder a source file belongs to (parents with ``__init__.py``), else the file."""
    path = Path(path).resolve()
    top, d = path, path.parent
    while (d / "__init__.py").is_file():
        top, d = d, d.parent
    return top


def add_sources(paths: Iterable[str | Path]) -> None:
    """Make user code (a plugin file, a package folder) part of the key of :func:`user_code`."""
    for p in paths:
        rp = str(Path(p).resolve())
        _EXTRA[rp] = tree_key(Path(rp))


@contextlib.contextmanager
def user_code():
    """Within the block, compiled functions being decorated (a plugin's, while it is imported)
    cache under the key of the package *and* the user sources (:func:`add_sources`): an edit of any
    file of the user's package, or of oceangnc, recompiles them. The package's own functions keep
    the package key, so a plugin's edit does not recompile oceangnc."""
    if not _EXTRA:
        yield
        return
    configure_numba(code_key())
    try:
        yield
    finally:
        configure_numba(package_key())


def prune(keep: int = KEEP) -> list[Path]:
    """Delete all but the ``keep`` most recently used key folders of each kind; returns those deleted.

    The folders of the current key are never deleted. Called when a new key folder is created."""
    root = cache_root()
    current = {keyed(k).name for k in ("numba", "steppers", "derived")}
    removed: list[Path] = []
    try:
        entries = [p for p in root.iterdir() if p.is_dir() and p.name.count("-") >= 2]
    except OSError:
        return removed
    by_kind: dict[str, list[Path]] = {}
    for p in entries:
        by_kind.setdefault(p.name.split("-", 1)[0], []).append(p)
    for group in by_kind.values():
        group.sort(key=lambda p: p.stat().st_mtime, reverse=True)
        for p in group[keep:]:
            if p.name not in current:
                shutil.rmtree(p, ignore_errors=True)
                removed.append(p)
    return removed


def ensure(kind: str) -> Path:
    """:func:`keyed` folder of ``kind``, created (and the old keys pruned) if it is new."""
    d = keyed(kind)
    if not d.is_dir():
        d.mkdir(parents=True, exist_ok=True)
        prune()
    return d


# -- derived values -----------------------------------------------------------------------------------


def cached(name: str, key, compute: Callable[[], list]) -> list:
    """``compute()`` (a list of floats) for these inputs, from ``derived-<version>-<code key>`` if known.

    Values derived from a model by a numerical search (the flagship's turning radii, by trimming
    the vehicle models) are computed once per machine and code: ``key`` is any JSON-serialisable
    description of the inputs; the code key covers the sources. The floats round-trip exactly (JSON
    keeps the shortest repr), so a run from the stored value is bit-identical to one that computes
    it. An unreadable or unwritable cache just computes the value.
    """
    blob = json.dumps(key, sort_keys=True, default=str)
    path = keyed("derived") / f"{name}-{hashlib.sha256(blob.encode()).hexdigest()[:20]}.json"
    try:
        return list(json.loads(path.read_text()))
    except (OSError, ValueError):
        pass
    value = list(compute())
    try:
        ensure("derived")
    except OSError:
        return value
    _write_atomic(path, json.dumps(value))
    return value


# -- loading cached machine code ------------------------------------------------------------------------

#: blake2b of the source of numba's ``Cache.load_overload`` that :func:`lean_loads` was written for;
#: any other numba keeps its own loading (tests/test_caches.py checks both branches)
LOAD_OVERLOAD_SOURCE = "5ef13fb2a4017d1a"  # numba 0.68


def _load_overload_source_hash() -> str:
    import inspect

    from numba.core import caching

    src = inspect.getsource(caching.Cache.load_overload)
    return hashlib.blake2b(src.encode(), digest_size=8).hexdigest()


def _lean_load_overload(self, sig, target_context):
    from numba.core.runtime import rtsys

    rtsys.initialize(target_context)  # what a cached function needs of the target's refresh: the runtime
    with self._guard_against_spurious_io_errors():
        return self._load_overload(sig, target_context)


class lean_loads:  # noqa: N801  (used as a context manager, like contextlib's)
    """Within the block, numba loads cached functions without refreshing its target context.

    numba's ``Cache.load_overload`` refreshes the target context before a load, which imports and
    installs every implementation numba has (0.4-0.9 s of a run's start-up); machine code loaded
    from the cache needs only the runtime. Used by ``oceangnc run`` around the run. Only for the
    numba whose ``load_overload`` source hash is :data:`LOAD_OVERLOAD_SOURCE`: any other keeps its
    own loading, so a numba upgrade cannot break a run.
    """

    def __enter__(self):
        from numba.core import caching

        self._orig = None
        if _load_overload_source_hash() == LOAD_OVERLOAD_SOURCE:
            self._orig = caching.Cache.load_overload
            caching.Cache.load_overload = _lean_load_overload  # type: ignore[method-assign]
        return self

    def __exit__(self, *exc):
        if self._orig is not None:
            from numba.core import caching

            caching.Cache.load_overload = self._orig  # type: ignore[method-assign]
        return False


# -- compiling ahead in a second process ----------------------------------------------------------------

#: while :class:`ahead_of_time` is active: ids of the compiled functions handed to a child so far
_AHEAD: set[int] | None = None


class ahead_of_time:  # noqa: N801  (a context manager, like lean_loads)
    """Within the block, :func:`compile_ahead` may fork (``oceangnc run`` enables it; a Python program
    calling ``oceangnc.run`` or a sweep keeps one process). ``OCEANGNC_COMPILE_AHEAD=0`` disables it."""

    def __enter__(self):
        global _AHEAD
        self._prev = _AHEAD
        _AHEAD = set() if os.environ.get("OCEANGNC_COMPILE_AHEAD", "1") != "0" else None
        return self

    def __exit__(self, *exc):
        global _AHEAD
        _AHEAD = self._prev
        return False


def _index_path(disp) -> str | None:
    """The path of numba's cache index of a ``cache=True`` dispatcher (read, not changed), else None."""
    try:
        return str(disp._cache._cache_file._index_path)
    except AttributeError:  # cache=False (NullCache), or a numba that names it otherwise: not ours to compile
        return None


def python_body(disp, _memo: dict | None = None):
    """The Python body of the compiled function ``disp`` calling the Python bodies of the compiled
    functions it names (recursively): the same code, run by the interpreter, compiling nothing.

    A function object of its own (``disp.py_func``'s code over a copy of its module's globals in which
    each compiled callee is replaced by its Python body, and over new closure cells in which a compiled
    function closed over is too): neither the module nor numba is changed."""
    import types

    memo = {} if _memo is None else _memo
    if id(disp) in memo:
        return memo[id(disp)]
    fn = disp.py_func
    env = dict(fn.__globals__)
    cells = fn.__closure__
    if cells and any(_compiled(c.cell_contents) for c in cells):
        cells = tuple(types.CellType() for _ in cells)
    memo[id(disp)] = out = types.FunctionType(fn.__code__, env, fn.__name__, fn.__defaults__, cells)
    for name in fn.__code__.co_names:
        v = env.get(name)
        if _compiled(v):
            env[name] = python_body(v, memo)
    if cells is not fn.__closure__:
        for new, old in zip(cells, fn.__closure__):
            v = old.cell_contents
            new.cell_contents = python_body(v, memo) if _compiled(v) else v
    return out


def _compiled(v) -> bool:
    """Whether ``v`` is a compiled (numba) function."""
    return v is not None and hasattr(v, "py_func") and hasattr(v, "overloads")


def cheapest(disp):
    """``disp`` itself when its machine code is in the disk cache (loading it costs less than running
    its Python body: a cached run), else its Python body with its callees' (:func:`python_body`; a
    first run, whose child may be compiling them meanwhile, :func:`compile_ahead`: calling a compiled
    callee from Python would compile it here, before the child is forked). For a one-off call at build
    time."""
    path = _index_path(disp)
    return disp if path is not None and os.path.exists(path) else python_body(disp)


def _child_compile(sigs: list, parent: int) -> None:
    """In the forked child: compile, which saves each function to numba's cache, then leave silently."""
    import signal

    code = 1
    try:
        try:  # end with the parent (Linux prctl PR_SET_PDEATHSIG = 1), whatever kills it
            import ctypes

            ctypes.CDLL(None, use_errno=True).prctl(1, int(signal.SIGTERM), 0, 0, 0)
        except (OSError, AttributeError):
            pass

        def stop(signum, frame):
            raise KeyboardInterrupt  # unwinds numba's writes (a temporary file, then a rename)

        signal.signal(signal.SIGTERM, stop)
        signal.signal(signal.SIGINT, stop)
        null = os.open(os.devnull, os.O_RDWR)
        for fd in (0, 1, 2):
            os.dup2(null, fd)  # nothing printed, and the parent's pipes are not held open
        os.closerange(3, 1 << 16)
        if os.getppid() == parent:
            for disp, sig in sigs:
                disp.compile(sig)
            code = 0
    except BaseException:  # noqa: BLE001  (a child never reports: the parent compiles what is missing)
        pass
    finally:
        os._exit(code)


class Ahead:
    """A forked child compiling functions into numba's disk cache (:func:`compile_ahead`)."""

    def __init__(self, pid: int, names: list[str]):
        self.pid = pid
        self.names = names

    def wait(self) -> None:
        """Wait for the child (once). On an interrupt the child is stopped and the interrupt goes on."""
        pid, self.pid = self.pid, 0
        if not pid:
            return
        try:
            os.waitpid(pid, 0)
        except ChildProcessError:
            pass
        except BaseException:
            self._stop(pid)
            raise

    def cancel(self) -> None:
        """Stop the child (it removes a file it is writing) and reap it."""
        pid, self.pid = self.pid, 0
        if pid:
            self._stop(pid)

    @staticmethod
    def _stop(pid: int) -> None:
        import signal

        with contextlib.suppress(OSError):
            os.kill(pid, signal.SIGTERM)
            os.waitpid(pid, 0)


def compile_ahead(jobs: Iterable[tuple]) -> Ahead | None:
    """Compile ``jobs`` in a forked child process while this one goes on with other work.

    ``jobs``: ``(dispatcher, args)`` pairs, a ``cache=True`` compiled function and arguments of the
    types it will be called with (they are not run: the child only compiles, for ``numba.typeof`` of
    each argument, and numba saves the machine code in its disk cache, atomically). When this
    process later calls a function (or compiles a caller of it), numba's normal dispatch finds it in
    the cache and loads it instead of compiling: a first run uses both cores. Call :meth:`Ahead.wait`
    before the work that needs them (the fused driver), so that nothing is compiled twice.

    No child (None) outside :class:`ahead_of_time`, off Linux, with more than one Python thread, for
    functions already handed to a child in this block, and -- what keeps a cached run from paying
    anything but a ``stat`` per function -- when every function already has a cache index on disk.
    The child prints nothing and ends with this process (a child that fails just leaves the work to
    this one).
    """
    if _AHEAD is None or sys.platform != "linux":
        return None
    import threading

    if threading.active_count() > 1:
        return None
    todo = []
    for disp, args in jobs:
        path = _index_path(disp)
        if path is None or id(disp) in _AHEAD or os.path.exists(path):
            continue
        todo.append((disp, args))
    if not todo:
        return None
    from numba import typeof

    sigs = []
    for disp, args in todo:
        sig = tuple(typeof(a) for a in args)
        if sig not in disp.overloads:
            sigs.append((disp, sig))
    if not sigs:
        return None
    for stream in (sys.stdout, sys.stderr):
        with contextlib.suppress(Exception):
            stream.flush()
    parent = os.getpid()
    pid = os.fork()
    if pid == 0:
        _child_compile(sigs, parent)
    _AHEAD.update(id(d) for d, _ in sigs)
    return Ahead(pid, [d.py_func.__qualname__ for d, _ in sigs])
