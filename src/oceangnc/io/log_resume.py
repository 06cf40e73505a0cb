"""Cutting a run's log back to a checkpoint before the run resumes (:func:`cut_to_checkpoint`).

The cut is decided by the log folder itself, never by a part count written in the checkpoint: each
part records its first row and row count (``oceangnc.row0``, ``oceangnc.rows``), and the parts read
in order must hold rows ``0 .. rows - 1`` of the checkpoint without a gap, and the last of those
rows must be at the checkpoint's time. Parts wholly after the checkpoint are removed, a part that
straddles it (a log compacted when the run was interrupted) is rewritten with its first rows only,
atomically; a log that cannot give the checkpoint's rows is refused in one line, unchanged.
"""

from __future__ import annotations

from pathlib import Path

import pyarrow.parquet as pq

from ..errors import InputError
from .log_read import _live_parts, _part_index, _part_range, list_parts


def _plan(folder: Path, rows: int) -> tuple[list[tuple[Path, int, int]], list[Path]]:
    """(kept parts with (row0, n), parts to remove); an InputError when the parts cannot give ``rows``."""
    keep, drop = _live_parts(folder)
    kept: list[tuple[Path, int, int]] = []
    covered = 0
    for p in keep:
        r = _part_range(p)
        row0, n = r if r is not None else (-1, 0)
        if row0 < 0:
            raise InputError(f"log {folder}: part {p.name} was not written by oceangnc; cannot resume into it")
        if row0 >= rows:
            drop.append(p)  # written after the checkpoint
            continue
        if row0 != covered:
            raise InputError(
                f"log {folder} misses rows {covered:,} to {row0 - 1:,} that the checkpoint needs "
                f"(a damaged part?); cannot resume: rerun the scenario"
            )
        kept.append((p, row0, n))
        covered = row0 + n
    if covered < rows:
        raise InputError(
            f"log {folder} holds {covered:,} rows; the checkpoint needs its first {rows:,}; cannot resume: "
            "rerun the scenario"
        )
    return kept, drop


def _time_at(p: Path, i: int) -> float:
    try:
        with pq.ParquetFile(p) as f:
            col = f.read(columns=["t"]).column("t")
            return float(col[i].as_py()) if 0 <= i < len(col) else float("nan")
    except (KeyError, ValueError, OSError, TypeError):
        return float("nan")


def cut_to_checkpoint(folder: str | Path, rows: int, t: float) -> int:
    """Cut log folder ``folder`` to its first ``rows`` rows (the checkpoint's, taken at time ``t`` s) and
    return the index of the next part to write. Checked before anything is changed: a log that cannot
    give those rows, or whose row ``rows - 1`` is not at ``t``, is a one-line InputError."""
    from .logs import LogWriter, recover_merge

    d = Path(folder)
    recover_merge(d)  # a run killed during its final merge: finish or roll it back first
    if rows == 0:
        return 0
    if not d.is_dir():
        raise InputError(f"log {d} is missing; the checkpoint at t = {t:g} s needs its first {rows:,} rows")
    kept, drop = _plan(d, rows)
    last, row0, n = kept[-1]
    t_last = _time_at(last, rows - 1 - row0)
    if not abs(t_last - t) <= 1e-9 * max(1.0, abs(t)):
        raise InputError(
            f"log {d}: row {rows - 1:,} is at t = {t_last:g} s, the checkpoint at t = {t:g} s; they are not of "
            "the same run: cannot resume"
        )
    for p in d.iterdir():
        if p.name.startswith(".") and p.name.endswith(".tmp") and not p.is_dir():
            p.unlink()
    for p in drop:
        p.unlink()
    if row0 + n > rows:  # a compacted log running past the checkpoint: its first rows, rewritten atomically
        with pq.ParquetFile(last) as f:
            table = f.read().slice(0, rows - row0)
        LogWriter(d)._write_part(table.replace_schema_metadata(None), _part_index(last) or 0, row0)
    return max(_part_index(p) or 0 for p in list_parts(d)) + 1
