"""Safe file input and output.

* Crash-safe writes: a temporary file in the same folder, fsync, rename, fsync of the folder (a reader
  sees the old file or the new one, never half of one).
* Temporary files are created, never followed (:func:`create_exclusive`): whatever sits at the
  temporary name (a leftover of a crash, or a symbolic link planted in a shared run folder) is
  unlinked, and the file is then created with ``O_CREAT | O_EXCL | O_NOFOLLOW``, which fails on any
  entry at that name rather than open it: a planted link is never written through.
* Inputs are bounded before they are read (:func:`read_bounded`): a regular file (not a device, FIFO
  or folder), at most a given number of bytes, else one line (:class:`~oceangnc.errors.InputError`).
"""

from __future__ import annotations

import os
import stat
from pathlib import Path

from ..errors import InputError

#: size limits of the loaders (bytes): generous for real inputs, small against /dev/zero-like files
LIMIT_TOML = 16 * 2**20  #: a config or vehicle file
LIMIT_JSON = 64 * 2**20  #: a summary or another JSON document of a run
LIMIT_CHECKPOINT = 2 * 2**30  #: a checkpoint.npz
_NOFOLLOW = getattr(os, "O_NOFOLLOW", 0)
_CLOEXEC = getattr(os, "O_CLOEXEC", 0)


def _mib(n: int) -> str:
    return f"{n / 2**20:,.0f} MiB" if n >= 2**20 else f"{n:,} bytes"


def read_bounded(path: str | Path, limit: int, what: str = "file") -> bytes:
    """The bytes of ``path``, checked first: a regular file of at most ``limit`` bytes. A missing file,
    a folder, a device (``/dev/zero``), a FIFO or a larger file is a one-line InputError naming
    ``what`` and the path; nothing beyond ``limit + 1`` bytes is ever read (a file growing while read
    is refused too)."""
    p = Path(path)
    try:
        fd = os.open(p, os.O_RDONLY | _CLOEXEC | getattr(os, "O_NONBLOCK", 0))  # a FIFO must not block
    except FileNotFoundError:
        raise InputError(f"{what} not found: {p}") from None
    except OSError as e:
        raise InputError(f"{what} {p}: cannot open it ({e.strerror or e})") from None
    try:
        st = os.fstat(fd)
        if not stat.S_ISREG(st.st_mode):
            kind = "a folder" if stat.S_ISDIR(st.st_mode) else "not a regular file (a device, FIFO or socket)"
            raise InputError(f"{what} {p}: is {kind}; give a regular file")
        if st.st_size > limit:
            raise InputError(f"{what} {p}: {_mib(st.st_size)}, more than the {_mib(limit)} allowed")
        chunks, n = [], 0
        while n <= limit:
            b = os.read(fd, min(limit + 1 - n, 1 << 20))
            if not b:
                break
            chunks.append(b)
            n += len(b)
        if n > limit:
            raise InputError(f"{what} {p}: grew past the {_mib(limit)} allowed while read")
        return b"".join(chunks)
    except OSError as e:
        raise InputError(f"{what} {p}: cannot read it ({e.strerror or e})") from None
    finally:
        os.close(fd)


def read_text_bounded(path: str | Path, limit: int, what: str = "file") -> str:
    """:func:`read_bounded` decoded as UTF-8; text that is not UTF-8 is a one-line InputError with the
    byte offset."""
    data = read_bounded(path, limit, what)
    try:
        return data.decode("utf-8")
    except UnicodeDecodeError as e:
        raise InputError(f"{what} {path}: not UTF-8 text (byte {e.start}: {data[e.start : e.start + 1]!r})") from None


def create_exclusive(path: str | Path, mode: int = 0o644):
    """Create ``path`` as a new, empty file opened for binary writing, never following a link: any
    entry at that name (a temporary file left by a crash, a planted symbolic link) is unlinked first
    (a link is removed, not its target), then the file is created with ``O_EXCL | O_NOFOLLOW``. An
    entry that cannot be removed (a folder) or that reappears is an OSError (the callers say it in
    one line). Returns a file object."""
    p = Path(path)
    try:
        st = os.lstat(p)
    except FileNotFoundError:
        pass
    else:
        if stat.S_ISDIR(st.st_mode):
            raise IsADirectoryError(21, "a folder is in the way of a temporary file", str(p))
        os.unlink(p)
    fd = os.open(p, os.O_WRONLY | os.O_CREAT | os.O_EXCL | _NOFOLLOW | _CLOEXEC, mode)
    return os.fdopen(fd, "wb")


def temp_name(path: str | Path) -> Path:
    """The hidden temporary name beside ``path`` that its atomic writes use (``.NAME.tmp``)."""
    p = Path(path)
    return p.with_name(f".{p.name}.tmp")


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
    tmp = temp_name(p)
    try:
        with create_exclusive(tmp) as f:
            f.write(data)
            f.flush()
            os.fsync(f.fileno())
        os.replace(tmp, p)
    except BaseException:
        unlink_quietly(tmp)
        raise
    _fsync_dir(p.parent)


def unlink_quietly(p: Path) -> None:
    try:
        if not os.path.isdir(p):
            os.unlink(p)
    except OSError:
        pass


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


#: files of a run folder that no export or page may replace
RUN_FILES = ("config.toml", "summary.json", "checkpoint.npz", "log.parquet", "events.jsonl", "import.json")


def check_output(path: str | Path, kind: str, is_same_kind) -> Path:
    """Check that ``path`` may receive an output of ``kind`` (``--out`` of ``view`` and ``export``);
    returns it. Refused in one line (InputError): a run's own files (:data:`RUN_FILES`), anything that
    is not a regular file (a device such as ``/dev/full``, a folder, a FIFO, a symbolic link), and an
    existing regular file that ``is_same_kind(first_bytes)`` does not recognise as a previous output of
    the same kind. Its folder is created; one that cannot be is one line too."""
    p = Path(path)
    if p.name in RUN_FILES:
        raise InputError(f"--out {p}: would replace a run's own {p.name}; give another file name")
    try:
        st = os.lstat(p)
    except FileNotFoundError:
        st = None
    except OSError as e:
        raise InputError(f"--out {p}: cannot use it ({e.strerror or e})") from None
    if st is not None:
        if not stat.S_ISREG(st.st_mode):
            raise InputError(f"--out {p}: exists and is not a regular file (a link, device or folder); refused")
        try:
            with open(p, "rb") as f:
                head = f.read(4096)
        except OSError as e:
            raise InputError(f"--out {p}: cannot read it to check it ({e.strerror or e})") from None
        if not is_same_kind(head):
            raise InputError(f"--out {p}: exists and is not a {kind} written by oceangnc; refused (remove it first)")
    try:
        p.parent.mkdir(parents=True, exist_ok=True)
    except OSError as e:
        raise InputError(f"--out {p}: cannot create its folder ({e.strerror or e})") from None
    return p


def write_output(path: str | Path, write) -> None:
    """Write an output file through a temporary file created exclusively beside it (never through a
    link), then rename it into place: ``write(file)`` fills the temporary file. A failure removes the
    temporary file and is a one-line InputError; the file at ``path`` is then unchanged."""
    p = Path(path)
    tmp = temp_name(p)
    try:
        with create_exclusive(tmp) as f:
            write(f)
            f.flush()
            os.fsync(f.fileno())
        os.replace(tmp, p)
    except OSError as e:
        unlink_quietly(tmp)
        raise InputError(f"--out {p}: cannot write it ({e.strerror or e})") from None
    except BaseException:
        unlink_quietly(tmp)
        raise
    _fsync_dir(p.parent)
