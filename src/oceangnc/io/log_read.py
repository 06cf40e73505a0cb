"""Reading the crash-safe Parquet logs written by :class:`oceangnc.io.logs.LogWriter` (layout, the
atomic final merge and crash semantics: :mod:`oceangnc.io.logs`, which also compacts and repairs).

Reading never changes the files: a log whose final merge was interrupted between its two renames (no
``log.parquet``, the old parts in ``.log.parquet.old`` and the complete merged file in
``.log.parquet.merging``) is read from the merged folder (:func:`readable_dataset`);
:func:`oceangnc.io.logs.repair_log` finishes the merge on disk."""

from __future__ import annotations

from pathlib import Path

import pyarrow as pa
import pyarrow.parquet as pq

from ..errors import InputError

PART_FMT = "part-{:06d}.parquet"
MERGED_MARK = ".merged"  #: in a merged folder once its part is whole and on disk (hidden from readers)
META_ROW0 = b"oceangnc.row0"
META_ROWS = b"oceangnc.rows"


def _part_index(p: Path) -> int | None:
    name = p.name
    if not (name.startswith("part-") and name.endswith(".parquet")):
        return None
    try:
        return int(name[5:-8])
    except ValueError:
        return None


def list_parts(folder: str | Path) -> list[Path]:
    """The visible part files of a dataset folder, in write order."""
    d = Path(folder)
    # regular files only: a FIFO or device named like a part would block or never end a read
    parts = [(i, p) for p in d.iterdir() if (i := _part_index(p)) is not None and p.is_file()]
    return [p for _, p in sorted(parts)]


def _part_range(p: Path) -> tuple[int, int] | None:
    """(first row, row count) from a part's metadata, or None when unreadable."""
    try:
        md = pq.read_metadata(p)
    except (pa.ArrowInvalid, OSError, ValueError):
        return None
    kv = md.metadata or {}
    try:
        return int(kv[META_ROW0]), int(kv[META_ROWS])
    except (KeyError, ValueError):
        return -1, md.num_rows  # not written by LogWriter: keep, no order information


def _live_parts(folder: Path) -> tuple[list[Path], list[Path]]:
    """(parts to read in order, parts to drop: unreadable or covered by an earlier compaction)."""
    keep: list[Path] = []
    drop: list[Path] = []
    covered = 0
    for p in list_parts(folder):
        r = _part_range(p)
        if r is None:
            drop.append(p)
            continue
        row0, n = r
        if row0 >= 0 and row0 + n <= covered and n > 0:
            drop.append(p)  # its rows are already in a compacted part
            continue
        keep.append(p)
        if row0 >= 0:
            covered = max(covered, row0 + n)
    return keep, drop


def merge_folders(d: Path) -> tuple[Path, Path]:
    """The hidden sibling folders of dataset folder ``d`` used by its final merge:
    ``(.<name>.merging, .<name>.old)``."""
    return d.parent / f".{d.name}.merging", d.parent / f".{d.name}.old"


def _dataset_path(p: Path) -> Path:
    if p.is_dir() and p.name != "log.parquet":
        d = p / "log.parquet"
        if d.exists() or any(q.exists() for q in merge_folders(d)):
            return d
    return p


def readable_dataset(d: Path) -> Path:
    """Where the rows of dataset folder ``d`` are: ``d`` itself, or, when a final merge was cut
    between its two renames (``d`` missing), the complete merged folder (else the old parts)."""
    if d.exists():
        return d
    merging, old = merge_folders(d)
    if (merging / MERGED_MARK).is_file():
        return merging
    if old.is_dir():
        return old
    return d


def read_table(path: str | Path, columns: list[str] | None = None) -> pa.Table:
    """A log as a pyarrow Table: a dataset folder (parts in order, covered parts skipped), a single
    Parquet file, or a run folder holding ``log.parquet``."""
    p = readable_dataset(_dataset_path(Path(path)))
    if p.is_dir():
        keep, _ = _live_parts(p)
        if not keep:
            raise InputError(f"log {p} holds no readable part (try: oceangnc log repair {p.parent})")
        tables = [_read_file(q, columns) for q in keep]
        schema = tables[0].schema
        return pa.concat_tables([t.replace_schema_metadata(None) for t in tables]).replace_schema_metadata(
            {k: v for k, v in (schema.metadata or {}).items() if not k.startswith(b"oceangnc.")} or None
        )
    return _read_file(p, columns)


def _read_file(p: Path, columns: list[str] | None = None) -> pa.Table:
    """One Parquet file as a Table (``ParquetFile``: ``pq.read_table`` goes through pyarrow.dataset,
    which imports pandas, about 0.5 s of a run's start-up)."""
    with pq.ParquetFile(p) as f:
        return f.read(columns=columns)


def read_log(path: str | Path, columns: list[str] | None = None):
    """Read a Parquet log (dataset folder or file) or a CSV log as a pandas DataFrame.

    ``path`` may be a run folder (its ``log.parquet`` is read). A missing or unreadable log is an
    :class:`~oceangnc.errors.InputError` with a one-line message.
    """
    import pandas as pd

    p = _dataset_path(Path(path))
    if not readable_dataset(p).exists():
        raise InputError(f"log not found: {p}")
    try:
        if p.is_file() and p.suffix.lower() == ".csv":
            df = pd.read_csv(p)
        else:
            df = read_table(p, columns=columns).to_pandas()
    except (pa.ArrowInvalid, OSError, ValueError, KeyError) as e:
        if isinstance(e, InputError):
            raise
        raise InputError(f"cannot read log {p}: {e}") from None
    if columns:
        missing = [c for c in columns if c not in df.columns]
        if missing:
            raise InputError(f"log {p} has no column(s) {', '.join(missing)}; it has: {', '.join(df.columns[:30])}")
    return df


def _t_at(p: Path, i: int) -> float | None:
    try:
        with pq.ParquetFile(p) as f:
            col = f.read(columns=["t"]).column("t")
            return float(col[i].as_py()) if -len(col) <= i < len(col) else None
    except (KeyError, ValueError, OSError, TypeError, pa.ArrowInvalid):
        return None


def log_gaps(path: str | Path) -> list[str]:
    """The gaps a damaged or missing part leaves in a log (a run folder or its ``log.parquet``), one
    phrase each naming the part(s), the rows and the time span between the rows around it; empty when
    the readable parts hold every row in order (or the log is not a folder of oceangnc parts)."""
    d = readable_dataset(_dataset_path(Path(path)))
    if not d.is_dir():
        return []
    keep, drop = _live_parts(d)
    bad = [p.name for p in drop if _part_range(p) is None]
    out, covered, prev = [], 0, None
    for p in keep:
        r = _part_range(p)
        if r is None or r[0] < 0:
            return out
        row0, n = r
        if row0 > covered:
            t0 = _t_at(prev, -1) if prev is not None else None
            t1 = _t_at(p, 0)
            span = f"t = {t0:.3f} s to {t1:.3f} s" if t0 is not None and t1 is not None else f"before t = {t1} s"
            which = f" ({', '.join(bad)} unreadable)" if bad else ""
            out.append(f"log {d}: rows {covered:,} to {row0 - 1:,} are missing{which}: no data between {span}")
        covered, prev = max(covered, row0 + n), p
    return out
