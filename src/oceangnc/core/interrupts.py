"""The process's signal handling: how Ctrl-C and SIGTERM end a run, and where they must wait.

One home for the two rules the reliability tests rely on (issue 26):

* :func:`terminate_like_ctrl_c` - the ``run`` command's SIGTERM raises
  :class:`~oceangnc.errors.Terminated` (a ``KeyboardInterrupt``) in the main thread, so a terminated run
  ends as Ctrl-C does (log closed, ``summary.json`` says interrupted, exit 143). A SIGTERM that lands
  while numba or LLVM is on the stack is looked at again every 0.1 s until the compiler has returned
  (an exception raised inside LLVM left the process to crash at exit: SIGSEGV seen in CI).
* :func:`deferred` - a critical section (a log part written and counted) during which SIGINT and
  SIGTERM are held back and delivered to their handlers right after it (a KeyboardInterrupt between
  writing a part and counting it left the log writer with rows counted and no chunk: seen under load).

Both only act in the interpreter's main thread; elsewhere they do nothing (a signal handler can only
be set there).
"""

from __future__ import annotations

import signal
import threading
from collections.abc import Callable, Iterator
from contextlib import contextmanager

from ..errors import Terminated

__all__ = ["deferred", "terminate_like_ctrl_c"]


def _compiling(frame) -> bool:
    """numba or llvmlite on the stack: an exception raised there can corrupt LLVM's state."""
    while frame is not None:
        if str(frame.f_globals.get("__name__", "")).startswith(("numba", "llvmlite")):
            return True
        frame = frame.f_back
    return False


def terminate_like_ctrl_c() -> Callable[[], None] | None:
    """Make SIGTERM raise :class:`~oceangnc.errors.Terminated` in the main thread (module docstring); a
    second SIGTERM during the clean-up is ignored. Returns the function that restores the previous
    handlers (the caller runs it when the command ends), or None when not in the main thread."""

    def handler(signum, frame):
        if _compiling(frame):  # end as soon as the compiler returns: look again in 0.1 s
            signal.setitimer(signal.ITIMER_REAL, 0.1)
            return
        signal.signal(signal.SIGTERM, signal.SIG_IGN)
        signal.signal(signal.SIGALRM, signal.SIG_IGN)
        raise Terminated()

    try:
        previous = signal.signal(signal.SIGTERM, handler)
        signal.signal(signal.SIGALRM, handler)  # the deferred look (only ever armed by the handler)
    except ValueError:  # not the main thread of the interpreter
        return None
    previous = signal.SIG_DFL if previous is None else previous  # (None: a handler not set from Python)

    def restore() -> None:
        signal.signal(signal.SIGTERM, previous)
        signal.setitimer(signal.ITIMER_REAL, 0.0)
        signal.signal(signal.SIGALRM, signal.SIG_DFL)

    return restore


@contextmanager
def deferred() -> Iterator[None]:
    """Hold SIGINT and SIGTERM back for the body (main thread only) and deliver the first one to its
    handler after it (module docstring)."""
    if threading.current_thread() is not threading.main_thread():
        yield
        return
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
