"""The process's signal handling: how Ctrl-C and SIGTERM end a run, and where they must wait.

One home for the rules the reliability tests rely on (issues 26 and 41; docs/reliability.md):

* :func:`terminate_like_ctrl_c` - under the ``run`` command SIGINT *and* SIGTERM go through one handler
  that raises ``KeyboardInterrupt`` (SIGTERM: :class:`~oceangnc.errors.Terminated`) in the main thread, so
  a terminated run ends as Ctrl-C does (log closed, ``summary.json`` says interrupted, exit 130/143).
  The exception is raised only where Python code can unwind it: never while numba or llvmlite is on
  the stack (an exception raised inside LLVM or numba's dispatcher corrupts their state), never inside
  a finaliser (``__del__``: Python prints "Exception ignored", the signal is lost and the object is left
  half freed), never inside a critical section (:func:`deferred`). There the signal is looked at again
  every :data:`POLL_S` (SIGALRM) until the code has returned. Until issue 41 only SIGTERM was handled so;
  SIGINT kept Python's default handler, which raises anywhere, and neither handler knew of ctypes
  (:func:`_unsafe`): a signal at a random instant of a cached ``oceangnc run usv-turn`` ended in
  SIGSEGV inside the fused driver's call (2 in 34 SIGINTs and 1 in 12 SIGTERMs in the issue, 1 in 50
  SIGINTs here; the stress test crashed after 32 and 47 signals with this handler before ctypes was
  added to :data:`UNSAFE_MODULES`).
* A phase that stays unsafe longer than :data:`HARD_STOP_S` (numba compiling a driver for tens of
  seconds on a first run) is not waited for: the run's *hard stop* (:func:`on_hard_stop`, registered by
  :func:`oceangnc.api.run`) writes ``summary.json`` and the process ends at once with ``os._exit`` (the
  numba cache files are written to temporary names and renamed, so none is left torn).
* :func:`deferred` - a critical section (a log part written and counted) during which the signal is
  held back and delivered right after it. With the handler above this is a counter the handler reads
  (no handler is swapped per flush); elsewhere the handlers are swapped for the body, as before.

Only the interpreter's main thread is concerned; elsewhere these do nothing.
"""

from __future__ import annotations

import os
import signal
import threading
import time
from collections.abc import Callable, Iterator
from contextlib import contextmanager

from ..errors import Terminated

__all__ = ["deferred", "installed", "on_hard_stop", "terminate_like_ctrl_c", "HARD_STOP_S", "POLL_S"]

POLL_S = 0.05  #: seconds between two looks at a signal held back (SIGALRM)
HARD_STOP_S = 0.5  #: seconds a signal waits for an unsafe phase before the hard stop

#: the process's signal state while :func:`terminate_like_ctrl_c` is installed (main thread only)
_STATE: dict = {"installed": False, "critical": 0, "pending": None, "since": 0.0, "hard_stop": None}


#: modules whose Python code an exception must not interrupt: numba and llvmlite (their compiler and cache
#: state), ctypes (called by numba's compiled argument unboxing, which does not check for an error: below)
UNSAFE_MODULES = ("numba", "llvmlite", "ctypes")


def _unsafe(frame) -> bool:
    """A frame of :data:`UNSAFE_MODULES` on the stack, or a finaliser (``__del__``).

    The crash of issue 41: each call of the fused driver unboxes the sensors' ``numpy.random.Generator``
    arguments in numba's compiled wrapper, which calls the Python function ``ctypes.cast`` and reads
    ``.value`` of its result without checking it for NULL (numba 0.68.1, ``numba/core/boxing.py``,
    ``unbox_numpy_random_generator``, ``wire_in_fnptrs``). A signal handler that raised while
    ``ctypes.cast`` ran made that result NULL: ``PyObject_GetAttrString(NULL, "value")``, SIGSEGV "at 8
    in libpython3.11" (gdb on a core of the stress test, tests/test_signal_stress.py)."""
    while frame is not None:
        if frame.f_code.co_name == "__del__":
            return True
        name = str(frame.f_globals.get("__name__", ""))
        if name.split(".", 1)[0] in UNSAFE_MODULES:
            return True
        frame = frame.f_back
    return False


def installed() -> bool:
    """Whether :func:`terminate_like_ctrl_c`'s handler is in place (the ``run`` command)."""
    return bool(_STATE["installed"])


def on_hard_stop(callback: Callable[[int], str] | None) -> None:
    """Register ``callback(signum)``, run before the process ends at once when a signal has waited
    :data:`HARD_STOP_S` for an unsafe phase (module docstring); None removes it."""
    _STATE["hard_stop"] = callback


def _hard_stop(signum: int) -> None:
    import sys

    cb = _STATE["hard_stop"]
    kept = ""
    try:
        if cb is not None:
            kept = cb(signum) or ""
    except BaseException:  # noqa: BLE001  (ending anyway: say what was kept below)
        kept = ""
    term = signum == signal.SIGTERM
    what = "terminated (SIGTERM)" if term else "interrupted"
    print(f"{what} while compiling: {kept or 'nothing was written'}", file=sys.stderr, flush=True)
    os._exit(143 if term else 130)


def _handler(signum, frame):
    st = _STATE
    if signum == signal.SIGALRM:
        signum = st["pending"]
        if signum is None:
            return
    elif st["pending"] is not None:
        return  # a second signal while the first waits: the first decides
    if st["critical"] or _unsafe(frame):
        if st["pending"] is None:
            st["pending"], st["since"] = signum, time.monotonic()
        if not st["critical"] and time.monotonic() - st["since"] >= HARD_STOP_S:
            _hard_stop(signum)
        signal.setitimer(signal.ITIMER_REAL, POLL_S)
        return
    st["pending"] = None
    for s in (signal.SIGINT, signal.SIGTERM, signal.SIGALRM):  # the clean-up is not interrupted again
        signal.signal(s, signal.SIG_IGN)
    raise Terminated() if signum == signal.SIGTERM else KeyboardInterrupt()


def terminate_like_ctrl_c() -> Callable[[], None] | None:
    """Install the handler of the module docstring for SIGINT and SIGTERM. Returns the function that
    restores the previous handlers (the caller runs it when the command ends), or None when not in the
    main thread."""
    try:
        prev = {s: signal.signal(s, _handler) for s in (signal.SIGTERM, signal.SIGINT)}
        signal.signal(signal.SIGALRM, _handler)  # the deferred look (only ever armed by the handler)
    except ValueError:  # not the main thread of the interpreter
        return None
    _STATE.update(installed=True, critical=0, pending=None)

    def restore() -> None:
        signal.setitimer(signal.ITIMER_REAL, 0.0)
        pending = _STATE["pending"]
        _STATE.update(installed=False, pending=None, hard_stop=None)
        for s, h in prev.items():
            signal.signal(s, signal.SIG_DFL if h is None else h)  # (None: a handler not set from Python)
        signal.signal(signal.SIGALRM, signal.SIG_DFL)
        if pending is not None:  # held back to the end of the command: delivered to the handler now in place
            signal.raise_signal(pending)

    return restore


@contextmanager
def deferred() -> Iterator[None]:
    """Hold SIGINT and SIGTERM back for the body (main thread only) and deliver the first one after it
    (module docstring)."""
    if threading.current_thread() is not threading.main_thread():
        yield
        return
    if _STATE["installed"]:
        _STATE["critical"] += 1
        try:
            yield
        finally:
            _STATE["critical"] -= 1
            if not _STATE["critical"] and _STATE["pending"] is not None:
                signal.setitimer(signal.ITIMER_REAL, 1e-6)  # delivered by the handler, outside this frame
        return
    yield from _swapped()


def _swapped() -> Iterator[None]:
    """The body with SIGINT and SIGTERM recorded instead of handled, then the first delivered (a Python
    program's own handlers, where :func:`terminate_like_ctrl_c` is not installed)."""
    got: list[int] = []
    prev = {}
    try:
        for sig in (signal.SIGINT, signal.SIGTERM):
            prev[sig] = signal.signal(sig, lambda signum, frame: got.append(signum))
    except (ValueError, OSError):  # not settable here: run the body as it is
        for sig, h in prev.items():
            signal.signal(sig, signal.SIG_DFL if h is None else h)
        yield
        return
    try:
        yield
    finally:
        for sig, h in prev.items():
            signal.signal(sig, signal.SIG_DFL if h is None else h)
        for signum in got[:1]:
            h = prev[signal.Signals(signum)]
            if callable(h):
                h(signum, None)
            elif h == signal.SIG_DFL:
                signal.raise_signal(signum)
