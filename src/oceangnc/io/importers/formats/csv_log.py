"""CSV with a column map: ``signal=column[:unit]`` pairs name the columns and their units."""

from __future__ import annotations

import math
from pathlib import Path


from ....errors import InputError
from ._common import north_east, pwm


# -- CSV with a column map ------------------------------------------------------------------------------------

UNIT_SCALE = {
    "": 1.0,
    "si": 1.0,
    "s": 1.0,
    "ms": 1e-3,
    "us": 1e-6,
    "ns": 1e-9,
    "m": 1.0,
    "cm": 0.01,
    "mm": 1e-3,
    "rad": 1.0,
    "deg": math.pi / 180,
    "cdeg": math.pi / 18000,
    "m/s": 1.0,
    "cm/s": 0.01,
    "kn": 1852.0 / 3600.0,
    "km/h": 1 / 3.6,
    "rad/s": 1.0,
    "deg/s": math.pi / 180,
    "1": 1.0,
    "pwm": None,
    "n": 1.0,
    "kgf": 9.80665,
}


def parse_column_map(items) -> dict:
    """``["t=time_s", "usv.psi=heading:deg", ...]`` (or one comma-separated string) -> {signal: (column, unit)}."""
    if isinstance(items, dict):
        return {k: (v if isinstance(v, tuple) else tuple((str(v).split(":", 1) + [""])[:2])) for k, v in items.items()}
    out = {}
    for it in items if isinstance(items, (list, tuple)) else [items]:
        for part in str(it).split(","):
            part = part.strip()
            if not part:
                continue
            if "=" not in part:
                raise InputError(f"--map {part!r}: expected signal=column[:unit]")
            sig, rhs = part.split("=", 1)
            col, _, unit = rhs.partition(":")
            if unit.lower() not in UNIT_SCALE:
                raise InputError(
                    f"--map {part!r}: unknown unit {unit!r}; known: {', '.join(k for k in UNIT_SCALE if k)}"
                )
            out[sig.strip()] = (col.strip(), unit.lower())
    return out


def read_csv(path: Path, allow_truncated: bool = False, column_map=None, origin=None, **_):
    """CSV with a column map: ``t`` (time) and any standard signal; ``lat``/``lon`` (deg) become usv.x/y."""
    import pandas as pd

    cmap = parse_column_map(column_map or {})
    if "t" not in cmap:
        raise InputError(f"{path}: the column map needs the time column (--map t=COLUMN[:unit])")
    try:
        df = pd.read_csv(path)
    except Exception as e:  # noqa: BLE001
        raise InputError(f"{path}: cannot read CSV: {type(e).__name__}: {e}") from None
    missing = [f"{c} (for {s})" for s, (c, _) in cmap.items() if c not in df.columns]
    if missing:
        raise InputError(f"{path}: no column {', '.join(missing)}; it has: {', '.join(map(str, df.columns[:20]))}")
    if len(df) == 0:
        raise InputError(f"{path}: CSV has a header but no rows")

    def val(sig):
        c, unit = cmap[sig]
        v = pd.to_numeric(df[c], errors="coerce").to_numpy(float)
        return pwm(v) if unit == "pwm" else v * UNIT_SCALE[unit]

    t = val("t")
    out: dict = {}
    meta: dict = {"column_map": {k: ":".join(v).rstrip(":") for k, v in cmap.items()}}
    if "lat" in cmap and "lon" in cmap:
        x, y, o = north_east(df[cmap["lat"][0]].to_numpy(float), df[cmap["lon"][0]].to_numpy(float), origin)
        if x is not None:
            out["usv.x"], out["usv.y"] = (t, x), (t, y)
            meta["origin_deg"] = list(o)
    for sig in cmap:
        if sig in ("t", "lat", "lon"):
            continue
        out[sig] = (t, val(sig))
    return out, meta
