"""A light column table for a run's summary and plots without pandas (start-up, issue 19).

Importing pandas costs 0.3-0.5 s, more than a cached simulation of the flagship. A scenario whose
``summarize`` and plot jobs only read columns declares ``frame = "columns"``
(:class:`oceangnc.scenarios.base.Scenario`); ``oceangnc run`` then hands them a :class:`Columns`
built straight from the log's Arrow table instead of a :class:`pandas.DataFrame`.

:class:`Columns` has the part of the DataFrame interface such code uses: ``df["col"]``,
``df[["a", "b"]].to_numpy()``, ``df[df["t"] > 5.0]`` (rows by a boolean mask), ``"col" in df``,
``len(df)``, ``df.copy()``, ``df["new"] = values``, ``df.columns``. A column is a :class:`Col`, a 1-D numpy array with the Series methods used on logs:
``.iloc[k]``, ``.to_numpy()``, ``.values`` and reductions that skip NaN as pandas does (``max``,
``min``, ``sum``, ``mean``, ``median``, ``std``/``var`` with ``ddof=1``). Arithmetic and numpy
functions work as on arrays. Anything else raises ``AttributeError``: a scenario that needs more
keeps the default ``frame = "pandas"``. A test runs every ``frame = "columns"`` scenario's summary
and plots on both tables and requires the same numbers and the same PNG bytes.
"""

from __future__ import annotations

import warnings
from collections.abc import Iterable, Iterator, Mapping

import numpy as np


class Col(np.ndarray):
    """One column: a 1-D numpy array with the pandas Series methods used on logs.

    As with a Series, a ufunc of columns is a column and any other numpy function gives a plain
    array (``np.column_stack([df["x"], df["y"]])`` is a 2-D ndarray, with numpy's reductions).
    """

    def __array_wrap__(self, arr, context=None, return_scalar=False):
        if return_scalar:
            return arr[()]
        return arr.view(Col) if arr.ndim == 1 else arr.view(np.ndarray)

    def __array_function__(self, func, types, args, kwargs):
        out = super().__array_function__(func, types, args, kwargs)
        return out.view(np.ndarray) if isinstance(out, Col) else out

    @property
    def iloc(self) -> np.ndarray:
        """Positional indexing, as ``Series.iloc`` (a plain array view)."""
        return self.view(np.ndarray)

    @property
    def values(self) -> np.ndarray:
        return self.view(np.ndarray)

    def to_numpy(self, dtype=None, copy: bool = False) -> np.ndarray:
        a = self.view(np.ndarray)
        return np.array(a, dtype=dtype, copy=True) if copy else np.asarray(a, dtype=dtype)

    def abs(self) -> Col:
        return np.abs(self)

    # reductions with pandas' defaults: NaN skipped, std/var with ddof = 1, a scalar
    def _reduce(self, name: str, **kw):
        a = self.view(np.ndarray)
        if a.dtype.kind != "f":
            return getattr(np, name)(a, **kw)
        if not len(a) and name in ("max", "min"):
            return np.nan
        with warnings.catch_warnings():
            warnings.simplefilter("ignore", RuntimeWarning)  # an all-NaN column gives NaN, as in pandas
            return getattr(np, "nan" + name)(a, **kw)

    def max(self, axis=None, out=None, keepdims=False, **kw):  # type: ignore[override]
        return self._reduce("max")

    def min(self, axis=None, out=None, keepdims=False, **kw):  # type: ignore[override]
        return self._reduce("min")

    def sum(self, axis=None, dtype=None, out=None, keepdims=False, **kw):  # type: ignore[override]
        return self._reduce("sum")

    def mean(self, axis=None, dtype=None, out=None, keepdims=False, **kw):  # type: ignore[override]
        return self._reduce("mean")

    def median(self):
        return self._reduce("median")

    def std(self, axis=None, dtype=None, out=None, ddof=1, keepdims=False, **kw):  # type: ignore[override]
        return self._reduce("std", ddof=ddof)

    def var(self, axis=None, dtype=None, out=None, ddof=1, keepdims=False, **kw):  # type: ignore[override]
        return self._reduce("var", ddof=ddof)


class Columns:
    """Named equal-length 1-D columns; see the module docstring for the DataFrame subset it offers."""

    def __init__(self, data: Mapping[str, Iterable]):
        self._d: dict[str, np.ndarray] = {str(k): np.asarray(v) for k, v in data.items()}
        n = {len(v) for v in self._d.values()}
        if len(n) > 1:
            raise ValueError(f"columns of different lengths: {sorted(n)}")
        self._n = n.pop() if n else 0

    @classmethod
    def from_table(cls, table) -> Columns:
        """From a pyarrow Table (a run's ``log.parquet``), column by column (nulls become NaN)."""
        return cls({name: _to_numpy(table.column(i)) for i, name in enumerate(table.column_names)})

    @property
    def columns(self) -> list[str]:
        return list(self._d)

    @property
    def shape(self) -> tuple[int, int]:
        return (self._n, len(self._d))

    def __len__(self) -> int:
        return self._n

    def __iter__(self) -> Iterator[str]:
        return iter(self._d)

    def __contains__(self, key) -> bool:
        return key in self._d

    def __getitem__(self, key):
        if isinstance(key, str):
            return self._d[key].view(Col)
        if isinstance(key, list):
            return Columns({k: self._d[k] for k in key})
        if isinstance(key, np.ndarray) and key.dtype == bool and key.shape == (self._n,):
            return Columns({k: v[key] for k, v in self._d.items()})  # rows, as df[df["t"] > 5]
        raise TypeError(f"Columns[{key!r}]: a column name, a list of names or a boolean row mask")

    def __setitem__(self, key: str, value) -> None:
        a = np.asarray(value)
        if a.ndim == 0:  # a scalar fills the column, as in pandas
            a = np.full(self._n, a[()])
        elif len(a) != self._n and self._d.keys() - {key}:
            raise ValueError(f"column {key!r}: {len(a)} values for {self._n} rows")
        self._d[key] = a.view(np.ndarray)
        self._n = len(a)

    def copy(self) -> Columns:
        return Columns({k: v.copy() for k, v in self._d.items()})

    def to_numpy(self) -> np.ndarray:
        """The columns side by side, rows x columns (as ``DataFrame.to_numpy``)."""
        if not self._d:
            return np.empty((self._n, 0))
        return np.column_stack(list(self._d.values()))


def _to_numpy(column) -> np.ndarray:
    """A pyarrow ChunkedArray as one writable numpy array, chunk by chunk; nulls become NaN.

    Numbers are read from the Arrow buffers directly: pyarrow's own ``to_numpy`` imports pandas.
    """
    parts = [_chunk_to_numpy(c) for c in column.chunks]
    if not parts:
        return np.empty(0, dtype=float)
    return parts[0] if len(parts) == 1 else np.concatenate(parts)


def _chunk_to_numpy(chunk) -> np.ndarray:
    from pyarrow import types

    t = chunk.type
    kind = (
        "f"
        if types.is_floating(t)
        else "i"
        if types.is_signed_integer(t)
        else "u"
        if types.is_unsigned_integer(t)
        else ""
    )
    if kind and chunk.null_count == 0:
        dtype = np.dtype(f"{kind}{t.bit_width // 8}")
        data = chunk.buffers()[1]
        return np.frombuffer(data, dtype=dtype, count=len(chunk), offset=chunk.offset * dtype.itemsize).copy()
    values = chunk.to_pylist()
    if kind or types.is_null(t):
        return np.array([np.nan if v is None else v for v in values], dtype=float)
    return np.array(values)


class Plain(dict):
    """A config as plain values (``cfg.model_dump()``) read by attribute or by key, nested, for code
    that only reads it: the light plot modules in a drawer process that imports no config classes."""

    def __init__(self, data: Mapping):
        super().__init__({k: _plain(v) for k, v in data.items()})

    def __getattr__(self, name: str):
        try:
            return self[name]
        except KeyError:
            raise AttributeError(name) from None


def _plain(v):
    if isinstance(v, Mapping):
        return Plain(v)
    if isinstance(v, (list, tuple)):
        return type(v)(_plain(x) for x in v)
    return v
