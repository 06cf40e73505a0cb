"""Run logs: a crash-safe Parquet dataset per run, one row per logged sample, time column ``t`` (s).

Signal columns are named ``<body>.<signal>`` (``usv.x``, ``usv.psi``, ``usv.thrust_port``) and hold
float64 SI values.

Layout (crash safety). ``log.parquet`` is a *folder* (a Parquet dataset) holding one complete file
per flush, ``part-000000.parquet``, ``part-000001.parquet``, ... :class:`LogWriter` buffers rows and
writes a part every ``flush_period`` s of *simulated* time (``log.flush_period``, default 1 s), but
no more often than every ``min_flush_wall_s`` of wall time (``log.min_flush_wall_s``, counted from
the first row: a fast run's build and cache loads do not make its first rows due at once). Each
part is written to a hidden temporary name (``.part-000007.parquet.tmp``), flushed to disk and then
renamed, so every visible part is a whole Parquet file with its footer: a run killed with SIGKILL
or a full disk loses at most the rows buffered since the last flush (the kernel keeps what a killed
process wrote). Parts are written uncompressed (a few ms each). Against a power cut, ``fsync=True``
(config ``log.fsync = true``) also forces each part to disk before the next one is started (about
10 ms per part on a busy disk, so off by default); the compacted log and the parts a checkpoint
counts are always forced to disk. A part left empty or torn by a power cut is unreadable: it is
skipped when reading and removed by repair. pyarrow and pandas
skip names that start with ``.``, and open the folder as one table
(``pandas.read_parquet("run/log.parquet")``, ``pyarrow.parquet.read_table(...)``, or
:func:`read_log`). Each part records its first row index and row count in its key-value metadata
(``oceangnc.row0``, ``oceangnc.rows``).

When the run ends (or fails with an error), :meth:`LogWriter.close` merges the parts into one
``part-000000.parquet``. The switch from the parts to the merged file is atomic for every reader,
including plain ones (pandas and pyarrow read every visible ``*.parquet`` of the folder, so the
merged file must never sit beside the parts it holds). The merge (:func:`compact_log`):

1. builds the complete new folder beside, hidden: ``.log.parquet.merging/part-000000.parquet``
   (temporary name, fsync, rename), then the marker ``.merged`` in it (each fsynced, and the folders);
2. swaps the two folders in one step where the system can: ``renameat2(RENAME_EXCHANGE)`` (Linux
   3.15 and later, through ``ctypes``; ``log.parquet`` then holds the merged file and
   ``.log.parquet.merging`` the old parts). Elsewhere, or on a file system that refuses the
   exchange, two renames: ``log.parquet`` -> ``.log.parquet.old``, then ``.log.parquet.merging`` ->
   ``log.parquet``; between them ``log.parquet`` is briefly missing;
3. removes the marker and the folder of old parts.

A plain reader therefore sees the old parts, the merged file, or (only with the fallback, only
between its renames) no folder; never both. A kill at any step leaves hidden folders beside the log,
which :func:`~oceangnc.io.log_read.read_log` reads around without changing anything (it reads the
complete merged folder when ``log.parquet`` is missing) and :func:`repair_log`
(``oceangnc log repair DIR``) and a resume clean up (:func:`recover_merge`): a merged folder with its
marker whose old folder was moved aside is moved into place (rolled forward); a merged folder while
``log.parquet`` is whole is removed (rolled back: the parts are merged again); a folder of old parts
is removed. The hidden folders are siblings, not children, of ``log.parquet``, so a reader of the
folder never sees them. A crash of an older version in the middle of compaction can leave parts
whose rows are also in part 0; :func:`read_log` ignores such covered parts, and :func:`repair_log`
removes them, as well as temporary files and unreadable parts.
"""

from __future__ import annotations

import math
import os
import shutil
import sys
import time
from collections.abc import Callable
from pathlib import Path

import numpy as np
import pyarrow as pa
import pyarrow.parquet as pq

from ..core.interrupts import deferred
from ..core.files import _fsync_dir, atomic_write_bytes, atomic_write_text, create_exclusive, unlink_quietly  # noqa: F401
from ..errors import InputError

# reading lives in oceangnc.io.log_read; importable from here as before
from .log_read import (  # noqa: F401
    MERGED_MARK,
    META_ROW0,
    META_ROWS,
    PART_FMT,
    _dataset_path,
    _live_parts,
    _part_range,
    list_parts,
    merge_folders,
    read_log,
    read_table,
    readable_dataset,
)

MEM_CELLS = 20_000_000  #: values (rows x columns) of a log kept in memory for compaction (160 MB)


def _f64(a: np.ndarray) -> pa.Array:
    """A float64 Arrow array sharing a contiguous numpy row's memory (``pa.array`` would import pandas
    to check its argument, about 0.5 s of a run's start-up)."""
    a = np.ascontiguousarray(a, dtype=np.float64)
    return pa.Array.from_buffers(pa.float64(), len(a), [None, pa.py_buffer(a)])


class LogWriter:
    """Append rows of named float signals to a crash-safe Parquet dataset folder (module docstring).

    Parameters
    ----------
    path : path
        The dataset folder, normally ``<run>/log.parquet``.
    flush_period : float
        Simulated time between flushes (s): the most a crash can lose.
    flush_rows : int
        Also flush when this many rows are buffered (bounds memory on fast log rates).
    fsync : bool
        Force every part to disk before going on (power-cut safety; costs an fsync per part).
    min_flush_wall_s : float
        Wall-clock seconds that must also have passed since the last flush before a flush is due
        (default 0: every ``flush_period``). A simulation far faster than real time would otherwise write
        a part per simulated second, thousands a minute; with this floor a crash loses at most
        ``flush_period`` simulated seconds or ``min_flush_wall_s`` of wall time, whichever is more.
    start_part, start_row : int
        Continue an existing dataset (resume from a checkpoint) at this part index and row count.

    The column set is fixed by the first row; later rows may not add columns (a missing signal is NaN).
    Extra columns that are constant for a whole sub-run (``extra``, e.g. ``run``) are also floats.
    """

    def __init__(
        self,
        path: str | Path,
        flush_period: float = 1.0,
        flush_rows: int = 100_000,
        start_part: int = 0,
        start_row: int = 0,
        compact: bool = True,
        fsync: bool = False,
        min_flush_wall_s: float = 0.0,
    ):
        self.path = Path(path)
        self.min_flush_wall_s = float(min_flush_wall_s)
        # the wall-clock floor counts from the first row (set then): the time a run spends building and
        # loading before it has any row to lose does not make its first rows due at once
        self._wall_flush: float | None = None
        self.flush_period = float(flush_period)
        self.flush_rows = int(flush_rows)
        self.compact = bool(compact)
        self.fsync = bool(fsync)
        self._unsynced: list[Path] = []
        # the parts written by this writer, kept for compaction at close (no reading back), up to a
        # memory cap; a resumed writer (start_part > 0) compacts from disk
        self._mem: list[pa.Table] | None = [] if start_part == 0 else None
        self._mem_cells = 0
        self.columns: list[str] | None = None
        # rows appended one by one (lists per column) and blocks from append_rows (arrays of shape
        # (columns, rows)), kept in order in _chunks; _nbuf counts the buffered rows of both
        self._buf: dict[str, list] = {}
        self._chunks: list[np.ndarray] = []
        self._nbuf = 0
        self._t0: float | None = None
        self.rows = int(start_row)  # rows appended (including those of a resumed run)
        self.rows_written = int(start_row)  # rows in visible parts
        self.parts = int(start_part)
        self.extra: dict[str, float] = {}
        self.closed = False

    @classmethod
    def for_run(cls, run_dir: str | Path, log_cfg, **kw) -> LogWriter:
        """The writer of a run folder's ``log.parquet`` with the settings of its config's ``log`` table
        (:class:`oceangnc.io.config.LogConfig`); ``kw`` as for the constructor (e.g. a resume's start)."""
        return cls(
            Path(run_dir) / "log.parquet",
            flush_period=log_cfg.flush_period,
            fsync=log_cfg.fsync,
            min_flush_wall_s=log_cfg.min_flush_wall_s,
            **kw,
        )

    def append(self, t: float, row: dict[str, float]) -> None:
        """Add one sample at time ``t`` (s)."""
        t = float(t)
        if self._wall_flush is None:
            self._wall_flush = time.monotonic()
        if self.columns is None:
            self.columns = ["t", *self.extra.keys(), *[k for k in row if k not in self.extra]]
            self._buf = {c: [] for c in self.columns}
        if self._t0 is None:
            self._t0 = t
            # flush at multiples of the period (t = 1, 2, 3 s ...), whatever time the buffer starts at
            self._t_flush = (math.floor(t / self.flush_period + 1e-9) + 1) * self.flush_period
        self._buf["t"].append(t)
        for c in self.columns[1:]:
            if c in self.extra:
                self._buf[c].append(float(self.extra[c]))
            else:
                self._buf[c].append(float(row.get(c, np.nan)))
        self.rows += 1
        self._nbuf += 1
        if (
            (t >= self._t_flush - 1e-9 * self.flush_period and self._wall_due())
            or t < self._t0
            or self._nbuf >= self.flush_rows
        ):
            self.flush()

    def append_rows(self, t, names: list[str], values) -> None:
        """Add many samples at once: ``t`` (m,), ``values`` (m, len(names)) float64, columns named by ``names``.

        The fused clock's log buffer goes through here (one list extension per column, not per row).
        The column set must already be fixed by a first :meth:`append` and equal ``names`` (+ extras).
        """
        m = len(t)
        if m == 0:
            return
        if self._wall_flush is None:
            self._wall_flush = time.monotonic()
        if self.columns is None:  # e.g. a resumed log: the columns are the names, as append() would fix them
            self.columns = ["t", *self.extra.keys(), *[k for k in names if k not in self.extra]]
            self._buf = {c: [] for c in self.columns}
        idx = {c: j for j, c in enumerate(names)}
        ts_all = np.asarray(t, dtype=float)
        vals_all = np.asarray(values, dtype=float)
        # where each column comes from: a column of values, a constant extra, or NaN (absent)
        pos = {c: j for j, c in enumerate(self.columns)}
        src = [c for c in self.columns[1:] if c in idx and c not in self.extra]
        dst_rows = np.array([pos[c] for c in src], dtype=np.intp)
        src_cols = np.array([idx[c] for c in src], dtype=np.intp)
        fill = [
            (j, float(self.extra[c]) if c in self.extra else np.nan)
            for j, c in enumerate(self.columns)
            if j > 0 and (c in self.extra or c not in idx)
        ]
        i0 = 0
        while i0 < m:
            # the same parts as row-by-row append(): a part closes with the first row at or past the flush time
            if self._t0 is None:
                self._t0 = float(ts_all[i0])
                self._t_flush = (math.floor(self._t0 / self.flush_period + 1e-9) + 1) * self.flush_period
            room = self.flush_rows - self._nbuf
            due = self._wall_due()
            past = (
                np.nonzero(ts_all[i0:] >= self._t_flush - 1e-9 * self.flush_period)[0] if due else np.empty(0, np.intp)
            )
            i1 = min(m, i0 + max(1, room), i0 + int(past[0]) + 1 if past.size else m)
            n = i1 - i0
            self._seal_rows()
            block = np.empty((len(self.columns), n))
            block[0] = ts_all[i0:i1]
            block[dst_rows] = vals_all[i0:i1, src_cols].T
            for j, v in fill:
                block[j] = v
            self._chunks.append(block)
            self._nbuf += n
            self.rows += n
            if (due and ts_all[i1 - 1] >= self._t_flush - 1e-9 * self.flush_period) or self._nbuf >= self.flush_rows:
                self.flush()
            i0 = i1

    def _wall_due(self) -> bool:
        since = time.monotonic() - self._wall_flush if self._wall_flush is not None else 0.0
        return self.min_flush_wall_s <= 0.0 or since >= self.min_flush_wall_s

    def _seal_rows(self) -> None:
        """Move the rows appended one by one into an array block (keeps the row order with append_rows)."""
        if self.columns and self._buf["t"]:
            rows = np.array([self._buf[c] for c in self.columns], dtype=float)
            self._chunks.append(rows.reshape(len(self.columns), -1))
            for c in self.columns:
                self._buf[c].clear()

    def _table(self) -> pa.Table:
        self._seal_rows()
        data = self._chunks[0] if len(self._chunks) == 1 else np.concatenate(self._chunks, axis=1)
        return pa.table({c: _f64(data[j]) for j, c in enumerate(self.columns or [])})

    def _write_part(self, table: pa.Table, index: int, row0: int, final_part: bool = True) -> Path:
        meta = dict(table.schema.metadata or {})
        meta.update({META_ROW0: str(row0).encode(), META_ROWS: str(table.num_rows).encode()})
        table = table.replace_schema_metadata(meta)
        final = self.path / PART_FMT.format(index)
        tmp = self.path / f".{final.name}.tmp"
        try:
            with create_exclusive(tmp) as f:  # never through a link planted at the temporary name
                if final_part:
                    pq.write_table(table, f, compression="zstd")
                    f.flush()
                    os.fsync(f.fileno())
                else:  # a part of a running log: small, uncompressed (compaction compresses)
                    pq.write_table(table, f, compression="none", use_dictionary=False, write_statistics=False)
            os.replace(tmp, final)
        except OSError as e:
            unlink_quietly(tmp)
            raise InputError(
                f"cannot write the log {self.path}: {e.strerror or e}; the "
                f"{self.rows_written} rows flushed before are kept"
            ) from None
        if final_part:
            _fsync_dir(self.path)
        else:
            self._unsynced.append(final)
        return final

    def sync(self) -> None:
        """fsync the parts written since the last sync, and the folder (durable on power loss)."""
        for p in self._unsynced:
            try:
                fd = os.open(p, os.O_RDONLY)
            except OSError:
                continue
            try:
                os.fsync(fd)
            finally:
                os.close(fd)
        self._unsynced.clear()
        _fsync_dir(self.path)

    def flush(self) -> None:
        """Write the buffered rows as one new part file (atomically). A Ctrl-C or SIGTERM that arrives
        meanwhile is delivered when the part and the writer's counters agree (:func:`oceangnc.core.interrupts.deferred`)."""
        if not self.columns or not self._nbuf:
            return
        with deferred():
            self._flush()

    def _flush(self) -> None:
        self.path.mkdir(parents=True, exist_ok=True)
        table = self._table()
        self._write_part(table, self.parts, self.rows_written, final_part=False)
        if self._mem is not None:
            self._mem.append(table)
            self._mem_cells += table.num_rows * table.num_columns
            if self._mem_cells > MEM_CELLS:
                self._mem = None
        if self.fsync:
            self.sync()
        self.parts += 1
        self.rows_written += table.num_rows
        self._chunks.clear()
        self._nbuf = 0
        self._t0 = None
        self._wall_flush = time.monotonic()

    def close(self) -> None:
        """Flush, then compact the parts into one file; safe to call twice."""
        if self.closed:
            return
        self.closed = True
        if self.parts == 0 and self._mem == [] and self.columns and self._nbuf:
            # everything still in memory (a short run, or a batch run): one compressed, synced file
            self.path.mkdir(parents=True, exist_ok=True)
            table = self._table()
            self._write_part(table, 0, 0)
            self._mem = [table]
            self.parts, self.rows_written = 1, table.num_rows
            self._chunks.clear()
            self._nbuf = 0
            return
        self.flush()
        self.path.mkdir(parents=True, exist_ok=True)
        parts = list_parts(self.path)
        if not (self.compact and len(parts) > 1 and self._mem is not None and len(self._mem) == len(parts)):
            self.sync()  # (compacted from memory: the parts are replaced by a synced file, no need to force them)
        if not parts:
            # no row at all: still leave a valid, empty log behind
            cols = self.columns or ["t"]
            self._write_part(pa.table({c: pa.array([], type=pa.float64()) for c in cols}), 0, 0)
            return
        in_mem = self._mem is not None and len(self._mem) == len(parts)
        merged = pa.concat_tables(self._mem) if in_mem and self._mem else None
        if self.compact and len(parts) > 1:
            compact_log(self.path, merged)  # the atomic folder swap of the module docstring
        self._mem = [merged] if merged is not None else None

    def table(self) -> pa.Table | None:
        """The rows written so far as one table, from memory (None when the writer no longer keeps
        them: a resumed log, or more than the memory cap). Lets a caller summarise a finished run
        without reading the log back."""
        if self._mem is None:
            return None
        if self.columns and self._nbuf:
            return pa.concat_tables([*self._mem, self._table()])
        return pa.concat_tables(self._mem) if self._mem else None

    def __enter__(self):
        return self

    def __exit__(self, *exc):
        self.close()
        return False


#: called with a step's name between the steps of the final merge (tests kill the process there)
_merge_hook: Callable[[str], None] | None = None


def _step(name: str) -> None:
    if _merge_hook is not None:
        _merge_hook(name)


def _exchange(a: Path, b: Path) -> bool:
    """Swap two paths atomically (``renameat2`` with ``RENAME_EXCHANGE``); False where the system or
    the file system cannot (the caller then renames twice)."""
    if not sys.platform.startswith("linux"):
        return False
    import ctypes
    import errno

    try:
        fn = ctypes.CDLL(None, use_errno=True).renameat2
    except (AttributeError, OSError):
        return False  # a C library without renameat2 (glibc before 2.28)
    at_fdcwd, rename_exchange = -100, 2
    fn.argtypes = [ctypes.c_int, ctypes.c_char_p, ctypes.c_int, ctypes.c_char_p, ctypes.c_uint]
    if fn(at_fdcwd, os.fsencode(a), at_fdcwd, os.fsencode(b), rename_exchange) == 0:
        return True
    err = ctypes.get_errno()
    if err in (errno.ENOSYS, errno.EINVAL, errno.EOPNOTSUPP, errno.EPERM, errno.EXDEV):
        return False
    raise OSError(err, os.strerror(err), str(a))


def _rmtree(p: Path) -> bool:
    if p.is_dir():
        shutil.rmtree(p, ignore_errors=True)
        return True
    return False


def recover_merge(folder: str | Path) -> list[str]:
    """Finish or roll back a final merge cut by a crash (module docstring); returns what was done,
    one phrase per hidden folder handled (empty when there was nothing to do)."""
    d = Path(folder)
    merging, old = merge_folders(d)
    done = []
    if not d.exists() and (merging / MERGED_MARK).is_file():
        os.rename(merging, d)  # cut between the two renames: roll forward
        (d / MERGED_MARK).unlink(missing_ok=True)
        _fsync_dir(d.parent)
        done.append(f"finished the interrupted merge ({merging.name})")
    elif not d.exists() and old.is_dir():
        os.rename(old, d)  # (not left by the merge itself: the old parts back in place)
        _fsync_dir(d.parent)
        done.append(f"put the parts back from {old.name}")
    if _rmtree(merging):
        done.append(f"removed {merging.name}")
    if _rmtree(old):
        done.append(f"removed {old.name}")
    if (d / MERGED_MARK).exists():
        (d / MERGED_MARK).unlink()
    return done


def remove_log(folder: str | Path) -> None:
    """Delete a dataset folder (or file) and the hidden folders of an interrupted merge beside it."""
    d = Path(folder)
    for p in (d, *merge_folders(d)):
        if p.is_dir():
            shutil.rmtree(p)
        elif p.exists():
            p.unlink()


def compact_log(folder: str | Path, table: pa.Table | None = None) -> None:
    """Merge a dataset's parts into one ``part-000000.parquet``, switching atomically from the parts to
    the merged file (module docstring). ``table``: the rows, when the caller holds them (else read)."""
    d = Path(folder)
    if table is None:
        keep, drop = _live_parts(d)
        if len(keep) <= 1 and not drop:
            return
        if not keep:
            return
        table = pa.concat_tables([pq.read_table(p).replace_schema_metadata(None) for p in keep])
    merging, old = merge_folders(d)
    _rmtree(merging)  # leftovers of an earlier crash (repair_log recovers before it compacts)
    _rmtree(old)
    try:
        merging.mkdir()
        _step("started")
        w = LogWriter(merging)
        w._write_part(table.replace_schema_metadata(None), 0, 0)  # temporary name, fsync, rename
        _step("built")
        with create_exclusive(merging / MERGED_MARK) as f:
            os.fsync(f.fileno())
        _fsync_dir(merging)
        _fsync_dir(d.parent)
        _step("marked")
    except (OSError, InputError) as e:  # e.g. a full disk: the parts stay as they are
        _rmtree(merging)
        why = e.strerror if isinstance(e, OSError) and e.strerror else str(e)
        raise InputError(f"cannot merge the log {d}: {why}; its parts are kept, all readable") from None
    try:
        if _exchange(d, merging):
            _step("exchanged")  # log.parquet: the merged file; .merging: the old parts
            (d / MERGED_MARK).unlink()
            _fsync_dir(d.parent)
            _step("unmarked")
            shutil.rmtree(merging)
        else:
            os.rename(d, old)
            _step("moved aside")  # log.parquet missing; read_log reads .merging
            os.rename(merging, d)
            _step("renamed")
            (d / MERGED_MARK).unlink()
            _fsync_dir(d.parent)
            _step("unmarked")
            shutil.rmtree(old)
    except OSError as e:
        raise InputError(
            f"cannot merge the log {d}: {e.strerror or e}; no row is lost (oceangnc log repair {d.parent} finishes it)"
        ) from None
    _step("removed")


def _plural(n: int, what: str) -> str:
    return f"{n:,} {what}{'' if n == 1 else 's'}"


def repair_log(path: str | Path) -> dict:
    """Make a log folder (or a run folder holding ``log.parquet``) whole after a crash.

    Finishes or rolls back an interrupted final merge (:func:`recover_merge`), removes temporary files
    of interrupted writes, unreadable parts and parts already covered by a compacted part, then
    compacts. Returns ``{"parts": kept, "rows": n, "removed": [names], "counts": {...}, "merge": [...]}``
    where ``counts`` has the numbers of ``covered`` and ``unreadable`` parts and ``temporary`` files
    removed; :func:`repair_summary` says it in one line.
    """
    d = _dataset_path(Path(path))
    merge = recover_merge(d)
    if not d.is_dir():
        raise InputError(f"log folder not found: {d}")
    removed = []
    counts = {"covered": 0, "unreadable": 0, "temporary": 0}
    for p in sorted(d.iterdir()):
        if p.name.startswith(".") and p.name.endswith(".tmp"):
            p.unlink()
            removed.append(p.name)
            counts["temporary"] += 1
    keep, drop = _live_parts(d)
    for p in drop:
        counts["covered" if _part_range(p) is not None else "unreadable"] += 1
        p.unlink()
        removed.append(p.name)
    if not keep:
        LogWriter(d)._write_part(pa.table({"t": pa.array([], type=pa.float64())}), 0, 0)
    elif len(keep) > 1:
        compact_log(d)
    parts = list_parts(d)
    rows = sum(pq.read_metadata(p).num_rows for p in parts)
    return {"parts": len(parts), "removed": removed, "rows": rows, "counts": counts, "merge": merge}


def repair_summary(r: dict) -> str:
    """One line for :func:`repair_log`'s result: counts, not names (a crashed long run has thousands
    of parts)."""
    c = r["counts"]
    what = [
        _plural(c["covered"], "covered part"),
        _plural(c["unreadable"], "unreadable part"),
        _plural(c["temporary"], "temporary file"),
    ]
    what = [w for w, n in zip(what, (c["covered"], c["unreadable"], c["temporary"])) if n]
    merge = "finished an interrupted merge; " if any(m.startswith("finished") for m in r["merge"]) else ""
    n_left = sum(m.startswith("removed") for m in r["merge"])
    if n_left:
        what.append(_plural(n_left, "folder") + " of an interrupted merge")
    removed = f"removed {', '.join(what)}" if what else "removed nothing"
    return f"log repaired: {merge}{removed}; log has {_plural(r['rows'], 'row')} in {_plural(r['parts'], 'part file')}"
