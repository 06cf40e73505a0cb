"""The sweep's results table: ``results.parquet``, one row per finished run, written as runs finish.

Columns
-------
``run_id``, ``point_id`` (stable hashes, see :mod:`oceangnc.sweep.design`), ``index`` (position in
the design), ``point``, ``seed`` (``sim.seed`` of the run), ``param.<key>`` (the swept values),
``status`` (``ok``, ``diverged`` or ``failed``), ``error`` (one line, empty when ok),
``wall_time_s`` (wall-clock time of the run on its worker, s), ``cpu_time_s`` (CPU time of the
worker process during the run, s: the run's cost independent of the machine's load), ``worker`` (``host:pid``),
``finished_at`` (UTC, ISO 8601), ``out_dir`` (the run's folder), then every metric of the run's
``summary.json`` under its own key (SI units as the scenario documents them; ``duration_s`` is the
simulated time reached).

Crash safety: the whole table is rewritten to ``results.parquet.tmp`` and renamed over
``results.parquet`` (``os.replace``, atomic on POSIX) after every batch of finished runs, so the file
on disk is always a complete table holding every run finished before the last write; a crash
between writes loses at most the runs of the batch being written, none already on disk.
"""

from __future__ import annotations

import os
from pathlib import Path

import pandas as pd
import pyarrow as pa
import pyarrow.parquet as pq

PARAM = "param."
FIXED_COLUMNS = (
    "run_id",
    "point_id",
    "index",
    "point",
    "seed",
    "status",
    "error",
    "wall_time_s",
    "cpu_time_s",
    "worker",
    "finished_at",
    "out_dir",
)
RESULTS = "results.parquet"


def _normalise(col: pd.Series) -> pd.Series:
    """Give an object column one Parquet type: bool, float or string (mixed values become strings)."""
    if col.dtype != object:
        return col
    vals = [v for v in col if v is not None and not (isinstance(v, float) and pd.isna(v))]
    if vals and all(isinstance(v, bool) for v in vals):
        return col.astype("boolean")
    if vals and all(isinstance(v, (int, float)) and not isinstance(v, bool) for v in vals):
        return col.astype(float)
    return col.map(lambda v: None if v is None or (isinstance(v, float) and pd.isna(v)) else str(v))


def rows_to_frame(rows: list[dict]) -> pd.DataFrame:
    """Rows (dicts) -> DataFrame with the fixed columns first, then params, then metrics."""
    df = pd.DataFrame(rows)
    for c in FIXED_COLUMNS:
        if c not in df:
            df[c] = None
    params = [c for c in df.columns if c.startswith(PARAM)]
    metrics = [c for c in df.columns if c not in FIXED_COLUMNS and c not in params]
    df = df[[*FIXED_COLUMNS, *params, *metrics]]
    for c in df.columns:
        df[c] = _normalise(df[c])
    if len(df):
        df = df.sort_values("index", kind="stable").reset_index(drop=True)
    return df


class ResultsTable:
    """The rows of ``DIR/results.parquet`` kept in memory and written atomically on :meth:`flush`."""

    def __init__(self, out_dir: str | Path):
        self.path = Path(out_dir) / RESULTS
        self.rows: dict[str, dict] = {}
        tmp = self.path.with_suffix(".parquet.tmp")
        if tmp.exists():  # a write interrupted by a crash: the previous complete table is still there
            tmp.unlink()
        if self.path.exists():
            for r in pq.read_table(self.path).to_pylist():
                self.rows[r["run_id"]] = {k: v for k, v in r.items() if v is not None}

    def __contains__(self, run_id: str) -> bool:
        return run_id in self.rows

    def __len__(self) -> int:
        return len(self.rows)

    def status(self, run_id: str) -> str | None:
        r = self.rows.get(run_id)
        return None if r is None else r.get("status")

    def add(self, row: dict) -> None:
        """Add (or replace, when retrying a failed run) one finished run's row."""
        self.rows[row["run_id"]] = row

    def frame(self) -> pd.DataFrame:
        return rows_to_frame(list(self.rows.values()))

    def flush(self) -> Path:
        """Write the table: temporary file, fsync, atomic rename."""
        self.path.parent.mkdir(parents=True, exist_ok=True)
        from ..core.files import create_exclusive

        tmp = self.path.with_suffix(".parquet.tmp")
        table = pa.Table.from_pandas(self.frame(), preserve_index=False)
        with create_exclusive(tmp) as f:  # never through a link planted at the temporary name
            pq.write_table(table, f)
            f.flush()
            os.fsync(f.fileno())
        os.replace(tmp, self.path)
        return self.path


def read_results(sweep_dir: str | Path) -> pd.DataFrame:
    """A sweep folder's results table as a pandas DataFrame (rows in design order)."""
    from ..errors import InputError

    p = Path(sweep_dir)
    f = p / RESULTS if p.is_dir() else p
    if not f.is_file():
        raise InputError(f"no sweep results table at {f} (run 'oceangnc sweep ... --out {p}' first)")
    try:
        df = pq.read_table(f).to_pandas()
    except (pa.ArrowInvalid, OSError) as e:
        raise InputError(f"{f}: not a readable Parquet table ({e})") from None
    missing = [c for c in ("run_id", "status", "seed") if c not in df]
    if missing:
        raise InputError(f"{f}: not a sweep results table (missing column {missing[0]})")
    return df.sort_values("index", kind="stable").reset_index(drop=True) if "index" in df else df
