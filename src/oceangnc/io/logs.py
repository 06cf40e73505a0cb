"""Run logs: one Parquet file per run, one row per logged sample, time column ``t`` (s).

Signal columns are named ``<body>.<signal>`` (``usv.x``, ``usv.psi``, ``usv.thrust_port``) and hold
float64 SI values. :class:`LogWriter` buffers rows and writes a Parquet row group every
``flush_rows`` rows, and closes the file (writing its footer) when the run ends *or fails*, so a run
that diverges or is interrupted with Ctrl-C keeps everything it simulated.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pyarrow as pa
import pyarrow.parquet as pq

from ..errors import InputError


class LogWriter:
    """Append rows of named float signals to a Parquet file.

    The column set is fixed by the first row; later rows may not add columns (a missing signal is NaN).
    Extra string/int columns that are constant for a whole sub-run (e.g. ``run``) are also floats.
    """

    def __init__(self, path: str | Path, flush_rows: int = 2000):
        self.path = Path(path)
        self.flush_rows = int(flush_rows)
        self.columns: list[str] | None = None
        self._buf: dict[str, list] = {}
        self._writer: pq.ParquetWriter | None = None
        self.rows = 0
        self.extra: dict[str, float] = {}

    def append(self, t: float, row: dict[str, float]) -> None:
        """Add one sample at time ``t`` (s)."""
        if self.columns is None:
            self.columns = ["t", *self.extra.keys(), *[k for k in row if k not in self.extra]]
            self._buf = {c: [] for c in self.columns}
        self._buf["t"].append(float(t))
        for c in self.columns[1:]:
            if c in self.extra:
                self._buf[c].append(float(self.extra[c]))
            else:
                self._buf[c].append(float(row.get(c, np.nan)))
        self.rows += 1
        if len(self._buf["t"]) >= self.flush_rows:
            self.flush()

    def append_rows(self, t, names: list[str], values) -> None:
        """Add many samples at once: ``t`` (m,), ``values`` (m, len(names)) float64, columns named by ``names``.

        The fused clock's log buffer goes through here (one list extension per column, not per row).
        The column set must already be fixed by a first :meth:`append` and equal ``names`` (+ extras).
        """
        m = len(t)
        if m == 0:
            return
        if self.columns is None:
            raise ValueError("append_rows needs a first append() to fix the columns")
        idx = {c: j for j, c in enumerate(names)}
        self._buf["t"].extend(np.asarray(t, dtype=float).tolist())
        vals = np.asarray(values, dtype=float)
        for c in self.columns[1:]:
            if c in self.extra:
                self._buf[c].extend([float(self.extra[c])] * m)
            elif c in idx:
                self._buf[c].extend(vals[:, idx[c]].tolist())
            else:
                self._buf[c].extend([np.nan] * m)
        self.rows += m
        if len(self._buf["t"]) >= self.flush_rows:
            self.flush()

    def flush(self) -> None:
        """Write the buffered rows as one row group."""
        if not self.columns or not self._buf["t"]:
            return
        table = pa.table({c: pa.array(self._buf[c], type=pa.float64()) for c in self.columns})
        if self._writer is None:
            self.path.parent.mkdir(parents=True, exist_ok=True)
            self._writer = pq.ParquetWriter(self.path, table.schema, compression="zstd")
        self._writer.write_table(table)
        for c in self.columns:
            self._buf[c].clear()

    def close(self) -> None:
        """Flush and write the file footer; safe to call twice."""
        self.flush()
        if self._writer is not None:
            self._writer.close()
            self._writer = None
        elif self.columns is None and not self.path.exists():
            # no row at all: still leave a valid, empty log behind
            pq.write_table(pa.table({"t": pa.array([], type=pa.float64())}), self.path)

    def __enter__(self):
        return self

    def __exit__(self, *exc):
        self.close()
        return False


def read_log(path: str | Path, columns: list[str] | None = None):
    """Read a Parquet (or CSV) log as a pandas DataFrame; clear error if missing or unreadable."""
    import pandas as pd

    p = Path(path)
    if p.is_dir():
        p = p / "log.parquet"
    if not p.is_file():
        raise InputError(f"log not found: {p}")
    try:
        if p.suffix.lower() == ".csv":
            df = pd.read_csv(p)
        else:
            df = pq.read_table(p, columns=columns).to_pandas()
    except (pa.ArrowInvalid, OSError, ValueError) as e:
        raise InputError(f"cannot read log {p}: {e}") from None
    if columns:
        missing = [c for c in columns if c not in df.columns]
        if missing:
            raise InputError(f"log {p} has no column(s) {', '.join(missing)}; it has: {', '.join(df.columns[:30])}")
    return df
