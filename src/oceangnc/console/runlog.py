"""The console run's log sink: rows go to the run's Parquet file and to column arrays in memory, from which
the page's log download is written."""

from __future__ import annotations

import io
import math
from array import array

from ..io.logs import LogWriter


class _TeeLog:
    """Log sink for ``sim.run``: forwards rows to a LogWriter and keeps them as column arrays."""

    def __init__(self, writer: LogWriter | None):
        self.writer = writer
        self.columns: list[str] | None = None
        self.t = array("d")
        self.data: dict[str, array] = {}

    def append(self, t: float, row: dict) -> None:
        if self.writer is not None:
            self.writer.append(t, row)
        if self.columns is None:
            self.columns = list(row)
            self.data = {c: array("d") for c in self.columns}
        self.t.append(float(t))
        for c in self.columns:
            self.data[c].append(float(row.get(c, math.nan)))

    def __len__(self) -> int:
        return len(self.t)

    def columns_copy(self, n: int | None = None) -> tuple[array, dict[str, array]]:
        """The first ``n`` rows (default all): time and every column (copies)."""
        n = len(self) if n is None else n
        return self.t[:n], {c: self.data[c][:n] for c in (self.columns or [])}


def parquet_bytes(t, data: dict) -> bytes:
    """Columns ``t`` and ``data`` as Parquet bytes (float64, zstd; the format of ``oceangnc run``)."""
    import pyarrow as pa
    import pyarrow.parquet as pq

    table = pa.table(
        {"t": pa.array(t, type=pa.float64()), **{c: pa.array(v, type=pa.float64()) for c, v in data.items()}}
    )
    buf = io.BytesIO()
    pq.write_table(table, buf, compression="zstd")
    return buf.getvalue()
