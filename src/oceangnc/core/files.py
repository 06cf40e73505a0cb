"""Crash-safe file writes: a temporary file in the same folder, fsync, rename, fsync of the folder
(a reader sees the old file or the new one, never half of one)."""

from __future__ import annotations

import os
from pathlib import Path


def _fsync_dir(d: Path) -> None:
    try:
        fd = os.open(d, os.O_RDONLY)
    except OSError:
        return
    try:
        os.fsync(fd)
    except OSError:
        pass
    finally:
        os.close(fd)


def atomic_write_bytes(path: str | Path, data: bytes) -> None:
    """Write ``data`` to ``path`` atomically: a temporary file in the same folder, fsync, rename."""
    p = Path(path)
    tmp = p.with_name(f".{p.name}.tmp")
    with open(tmp, "wb") as f:
        f.write(data)
        f.flush()
        os.fsync(f.fileno())
    os.replace(tmp, p)
    _fsync_dir(p.parent)


def atomic_write_text(path: str | Path, text: str) -> None:
    """:func:`atomic_write_bytes` for text (UTF-8); ``summary.json`` is written this way."""
    atomic_write_bytes(path, text.encode("utf-8"))


class LineAppender:
    """Crash-safe append of text lines (the console's ``events.jsonl``): the file is opened with
    ``O_APPEND`` and each line reaches the kernel in one ``write`` (nothing is buffered in this
    process), so a killed process loses no line it wrote and leaves at most a partial last line, which
    :func:`read_json_lines` skips. ``write(..., sync=True)`` also fsyncs (for the rare lines that must
    survive a power loss too)."""

    def __init__(self, path: str | Path):
        self.path = Path(path)
        self._fd: int | None = os.open(self.path, os.O_WRONLY | os.O_APPEND | os.O_CREAT, 0o644)
        _fsync_dir(self.path.parent)

    def write(self, line: str, sync: bool = False) -> None:
        """Append ``line`` (a newline is added); a closed appender ignores the call."""
        if self._fd is None:
            return
        data = (line.rstrip("\n") + "\n").encode("utf-8")
        while data:  # a regular file takes it in one write; loop only for the pathological case
            n = os.write(self._fd, data)
            data = data[n:]
        if sync:
            os.fsync(self._fd)

    def close(self) -> None:
        if self._fd is not None:
            fd, self._fd = self._fd, None
            try:
                os.fsync(fd)
            except OSError:
                pass
            os.close(fd)


def read_json_lines(path: str | Path) -> list:
    """The JSON values of a JSON-lines file, one per complete line; a partial last line (a write cut by
    a crash) and blank lines are skipped."""
    import json

    text = Path(path).read_text(encoding="utf-8")
    lines = text.split("\n")
    if not text.endswith("\n"):
        lines = lines[:-1]  # the last line was never finished
    return [json.loads(s) for s in lines if s.strip()]
