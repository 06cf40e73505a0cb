"""Helpers of the view tests (tests/test_view.py, tests/test_console_view3d.py)."""

from __future__ import annotations

import subprocess


def first_line(proc: subprocess.Popen, timeout: float) -> str:
    """The first line a subprocess prints, waited for at most ``timeout`` s ("" if none came)."""
    import threading

    out: list[str] = []
    t = threading.Thread(target=lambda: out.append(proc.stdout.readline()), daemon=True)
    t.start()
    t.join(timeout)
    return out[0] if out else ""
