"""Resampling, derived signals, gap / time-jump report and the format dispatch (see the package docstring)."""

from __future__ import annotations

import json
import math
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np

from ...cli_options import needs_package
from ...errors import InputError

#: suffix -> format name
FORMATS = {
    ".bin": "dataflash",
    ".log": "dataflash",
    ".tlog": "tlog",
    ".ulg": "ulog",
    ".csv": "csv",
    ".db3": "rosbag2",
    ".mcap": "rosbag2",
}
#: signals held (zero-order) between samples instead of interpolated: commands
HELD = ("act.",)
ANGLES = ("usv.psi", "usv.phi", "usv.theta")


@dataclass
class ImportResult:
    """A resampled log and what happened on the way."""

    df: Any  # pandas DataFrame, time column t (s)
    source: str
    format: str
    rate: float
    report: dict[str, Any] = field(default_factory=dict)

    def summary_line(self) -> str:
        r = self.report
        return (
            f"{self.source}: {self.format}, {len(self.df)} rows at {self.rate:g} Hz over "
            f"{r.get('duration_s', 0):.1f} s, {len(r.get('gaps', []))} gap(s), "
            f"{r.get('time_jumps', 0)} time jump(s)"
        )


def detect_format(path: Path, fmt: str | None = None) -> str:
    if fmt:
        if fmt not in set(FORMATS.values()):
            raise InputError(f"--format {fmt}: allowed {', '.join(sorted(set(FORMATS.values())))}")
        return fmt
    if path.is_dir():
        if (path / "metadata.yaml").is_file():
            return "rosbag2"
        # a run folder, or a log.parquet dataset folder (crash-safe logs are folders of parts)
        if path.suffix.lower() == ".parquet" or (path / "log.parquet").exists():
            return "parquet"
        raise InputError(f"{path}: a folder that is neither a ROS 2 bag (no metadata.yaml) nor a run (no log.parquet)")
    suf = path.suffix.lower()
    if suf == ".parquet":
        return "parquet"
    if suf not in FORMATS:
        raise InputError(
            f"{path}: unknown log format '{suf}'; known: .bin .tlog .ulg .db3 .mcap (ROS 2 bag) .csv .parquet"
        )
    return FORMATS[suf]


def _monotone(t: np.ndarray, v: np.ndarray, jump_s: float):
    """Keep strictly increasing time stamps; returns (t, v, dropped, jumps list, duplicate stamps). A stamp
    equal to the latest so far is a duplicate (counted, not a jump); one before it is a backwards jump."""
    t = np.asarray(t, float)
    v = np.asarray(v, float)
    ok = np.isfinite(t) & np.isfinite(v)
    t, v = t[ok], v[ok]
    if t.size == 0:
        return t, v, 0, []
    run = np.maximum.accumulate(t)
    keep = np.ones(t.size, bool)
    keep[1:] = t[1:] > run[:-1]
    dup = np.zeros(t.size, bool)
    dup[1:] = t[1:] == run[:-1]  # a repeated stamp (two messages in one tick): no jump, the later sample dropped
    jumps = []
    back = np.nonzero(~keep & ~dup)[0]
    if back.size:
        jumps.append({"kind": "backwards", "at_s": float(run[back[0] - 1]), "samples_dropped": int(back.size)})
    t, v = t[keep], v[keep]
    dt = np.diff(t)
    for i in np.nonzero(dt > jump_s)[0][:20]:
        jumps.append({"kind": "forward", "at_s": float(t[i]), "length_s": float(dt[i])})
    return t, v, int((~keep).sum()), jumps, int(dup.sum())


def resample(
    series: dict, rate: float, gap_s: float | None = None, source: str = "log", t_origin: float | None = None
) -> tuple[dict, dict]:
    """Put raw series ``{name: (t, v)}`` on one grid at ``rate`` Hz over their common span.

    The time column ``t`` counts from ``t_origin`` (source time, s; default the start of the common span).
    Angles are unwrapped before and wrapped after linear interpolation; ``act.*`` commands are held
    (zero-order). A grid point with no sample within ``gap_s`` (default max(1 s, 5 / rate)) on either
    side stays NaN and the gap is reported. Returns (columns dict with ``t``, report dict).
    """
    if not (rate > 0 and math.isfinite(rate)):
        raise InputError(f"--rate {rate}: must be > 0 Hz")
    gap_s = gap_s if gap_s is not None else max(1.0, 5.0 / rate)
    clean = {}
    report: dict[str, Any] = {"gaps": [], "time_jumps": 0, "jumps": [], "dropped_samples": {}, "signals": {}}
    for k, (t, v) in series.items():
        t, v, dropped, jumps, dups = _monotone(t, v, gap_s)
        if t.size < 2:
            continue
        clean[k] = (t, v)
        if dropped:
            report["dropped_samples"][k] = dropped
        if dups:
            report.setdefault("duplicate_stamps", {})[k] = dups
        for j in jumps:
            report["jumps"].append({"signal": k, **j})
        report["signals"][k] = {
            "samples": int(t.size),
            "start_s": float(t[0]),
            "end_s": float(t[-1]),
            "mean_rate_hz": float((t.size - 1) / (t[-1] - t[0])) if t[-1] > t[0] else 0.0,
        }
    if not clean:
        raise InputError(f"{source}: no signal with at least 2 samples")
    t0 = max(t[0] for t, _ in clean.values())
    t1 = min(t[-1] for t, _ in clean.values())
    if t1 - t0 < 1.0 / rate:
        spans = ", ".join(f"{k} {t[0]:.1f}-{t[-1]:.1f} s" for k, (t, _) in clean.items())
        raise InputError(f"{source}: the signals do not overlap in time ({spans})")
    grid = t0 + np.arange(math.floor((t1 - t0) * rate + 1e-9) + 1) / rate
    origin = t0 if t_origin is None else float(t_origin)
    out = {"t": grid - origin}
    for k, (t, v) in clean.items():
        if k in ANGLES:
            v = np.unwrap(v)
        if k.startswith(HELD):
            idx = np.clip(np.searchsorted(t, grid, side="right") - 1, 0, t.size - 1)
            g = v[idx]
        else:
            g = np.interp(grid, t, v)
        j = np.clip(np.searchsorted(t, grid), 1, t.size - 1)
        hole = (t[j] - t[j - 1]) > gap_s
        if hole.any():
            g = g.copy()
            g[hole] = np.nan
            edges = np.flatnonzero(np.diff(np.concatenate([[0], hole.astype(int), [0]])))
            for a, b in zip(edges[::2], edges[1::2]):
                report["gaps"].append(
                    {
                        "signal": k,
                        "from_s": float(grid[a] - origin),
                        "to_s": float(grid[b - 1] - origin),
                        "rows_left_nan": int(b - a),
                    }
                )
        if k in ANGLES:
            g = (g + np.pi) % (2 * np.pi) - np.pi
        out[k] = g
    report["time_jumps"] = len(report["jumps"])
    report["t0_source_s"] = float(origin)
    report["duration_s"] = float(t1 - t0)
    report["rate_hz"] = float(rate)
    report["gap_s"] = float(gap_s)
    return out, report


def span_start(series: dict) -> float | None:
    """Source time at which every signal has started (what :func:`resample` counts ``t`` from)."""
    firsts = []
    for t, v in series.values():
        t = np.asarray(t, float)
        ok = np.isfinite(t) & np.isfinite(np.asarray(v, float))
        if ok.sum() >= 2:
            firsts.append(float(t[ok][0]))
    return max(firsts) if firsts else None


def _window(start, end) -> str:
    if start is not None and end is not None:
        return f"between --start {start:g} and --end {end:g} s"
    return f"after --start {start:g} s" if start is not None else f"before --end {end:g} s"


def trim(series: dict, t0: float, start: float | None, end: float | None, source: str) -> dict:
    """The samples between ``start`` and ``end`` (s on the imported time axis: source time - ``t0``)."""
    lo = -math.inf if start is None else float(start)
    hi = math.inf if end is None else float(end)
    for name, v in (("--start", start), ("--end", end)):
        if v is not None and not math.isfinite(float(v)):
            raise InputError(f"{name} {v}: must be a finite time, s")
    if not lo < hi:
        raise InputError(f"--start {start} --end {end}: the start must come before the end")
    out = {}
    for k, (t, v) in series.items():
        t = np.asarray(t, float)
        keep = (t - t0 >= lo - 1e-9) & (t - t0 <= hi + 1e-9)
        out[k] = (t[keep], np.asarray(v, float)[keep])
    if not any(t.size >= 2 for t, _ in out.values()):
        ends = [float(np.nanmax(np.asarray(t, float))) - t0 for t, _ in series.values() if len(t)]
        raise InputError(
            f"{source}: nothing {_window(start, end)} (the log runs from 0 to {max(ends):.1f} s on the imported "
            "time axis)"
        )
    return out


#: plausible height (up, m) of a vehicle: the deepest ocean to the ceiling of anything the project logs
HEIGHT_LIMITS_M = (-11000.0, 10000.0)
#: a height step between two samples is a jump when it exceeds HEIGHT_STEP_M + (HEIGHT_RATE_MPS + speed) dt
HEIGHT_STEP_M, HEIGHT_RATE_MPS = 2.0, 5.0


def check_heights(series: dict, source: str, t0: float | None = None) -> None:
    """Refuse an implausible height or depth (signals ``*.z``, down positive): outside
    :data:`HEIGHT_LIMITS_M`, or a step between two samples that no motion at the logged speed explains.
    Times in the message are on the imported axis (source time - ``t0``)."""
    speed = None
    if "usv.vn" in series and "usv.ve" in series:
        (tn, vn), (te, ve) = series["usv.vn"], series["usv.ve"]
        if len(tn) == len(te) and len(tn) and np.array_equal(np.asarray(tn, float), np.asarray(te, float)):
            speed = (np.asarray(tn, float), np.hypot(np.asarray(vn, float), np.asarray(ve, float)))
    for k, (t, z) in series.items():
        if not k.endswith(".z"):
            continue
        t = np.asarray(t, float)
        z = np.asarray(z, float)
        ok = np.isfinite(t) & np.isfinite(z)
        t, z = t[ok], z[ok]
        if not t.size:
            continue
        o = t[0] if t0 is None else t0
        h = -z
        lo, hi = HEIGHT_LIMITS_M
        bad = np.flatnonzero((h < lo) | (h > hi))
        if bad.size:
            i = int(bad[0])
            raise InputError(
                f"{source}: column {k}: height {h[i]:.1f} m at t = {t[i] - o:.2f} s is outside the "
                f"plausible {lo:.0f} to {hi:.0f} m ({bad.size} sample(s))"
            )
        if t.size < 2:
            continue
        dt = np.diff(t)
        dz = np.abs(np.diff(z))
        v = np.zeros(dt.size)
        if speed is not None and speed[0].size:
            st, sv = speed
            ok2 = np.isfinite(sv)
            if ok2.any():
                v = np.maximum(np.interp(t[:-1], st[ok2], sv[ok2]), np.interp(t[1:], st[ok2], sv[ok2]))
        allowed = HEIGHT_STEP_M + (HEIGHT_RATE_MPS + v) * np.maximum(dt, 0.0)
        jump = np.flatnonzero(dz > allowed)
        if jump.size:
            i = int(jump[0])
            raise InputError(
                f"{source}: column {k}: height jumps from {-z[i]:.1f} m to {-z[i + 1]:.1f} m in {dt[i]:.2f} s at "
                f"t = {t[i] - o:.2f} s (speed {v[i]:.1f} m/s allows {allowed[i]:.1f} m): "
                f"implausible; --start/--end to leave it out"
            )


def derive(cols: dict, report: dict) -> dict:
    """Derived standard signals: u, v, speed from (vn, ve, psi); r from psi; throttle / steer from left / right."""
    notes = report.setdefault("notes", [])
    if "usv.vn" in cols and "usv.ve" in cols:
        vn, ve = cols["usv.vn"], cols["usv.ve"]
        cols.setdefault("usv.speed", np.hypot(vn, ve))
        if "usv.psi" in cols:
            c, s = np.cos(cols["usv.psi"]), np.sin(cols["usv.psi"])
            cols["usv.u"] = c * vn + s * ve
            cols["usv.v"] = -s * vn + c * ve
    elif "usv.x" in cols and "usv.y" in cols and len(cols["t"]) > 2:
        t = cols["t"]
        cols["usv.vn"] = np.gradient(cols["usv.x"], t)
        cols["usv.ve"] = np.gradient(cols["usv.y"], t)
        notes.append("usv.vn/ve/speed differentiated from the position (no velocity in the log)")
        return derive(cols, report)
    if "usv.r" not in cols and "usv.psi" in cols and len(cols["t"]) > 2:
        cols["usv.r"] = np.gradient(np.unwrap(cols["usv.psi"]), cols["t"])
        notes.append("usv.r differentiated from the heading (no yaw rate in the log)")
    if "act.left" in cols and "act.right" in cols:
        cols["act.throttle"] = 0.5 * (cols["act.left"] + cols["act.right"])
        cols["act.steer"] = 0.5 * (cols["act.left"] - cols["act.right"])
    return cols


def _to_df(cols: dict):
    import pandas as pd

    order = ["t"] + sorted(k for k in cols if k != "t")
    return pd.DataFrame({k: np.asarray(cols[k], float) for k in order})


def import_log(
    path,
    rate: float = 10.0,
    fmt: str | None = None,
    gap_s: float | None = None,
    allow_truncated: bool = False,
    body: str = "usv",
    require_marine: bool = False,
    start: float | None = None,
    end: float | None = None,
    **opts,
) -> ImportResult:
    """Read a field log (any of :data:`FORMATS`) into a resampled DataFrame with standard signals.

    ``body`` names the vehicle's signals (``usv.*`` by default, ``uuv`` for a UUV's log). ``opts`` go
    to the format's reader: ``system`` (MAVLink system id, tlog), ``origin`` ((lat, lon)
    deg, default the first fix), ``topics`` (ROS 2: role -> topic), ``column_map`` (CSV:
    signal -> "column[:unit]"), ``servos`` (ArduPilot: outputs 1 and 3 as "skid" or "rudder" instead of
    the log's SERVOn_FUNCTION), ``ros_distro`` (ROS 2 bag without message definitions).

    The report's ``vehicle`` says what the log is of (``type``, ``from`` where it was read, ``marine``);
    ``require_marine`` (boat identification) refuses a log whose vehicle is known to be neither a boat nor
    a submarine. ``start`` / ``end`` (s) keep a stretch of the log, on the time axis of the untrimmed import
    (0 where every signal has started); the trimmed log keeps that axis. Heights and depths are checked
    (:func:`check_heights`) on the samples kept.
    """
    from . import formats
    from .formats._common import vehicle

    p = Path(path)
    if not p.exists():
        raise InputError(f"log not found: {p}")
    kind = detect_format(p, fmt)
    if kind == "parquet":
        raise InputError(f"{p}: already a Parquet log; identification reads it directly")
    if opts.get("instances") and kind != "dataflash":
        raise InputError(f"{p}: --instance picks a sensor of an ArduPilot .bin log; this is a {kind} log")
    reader = getattr(formats, f"read_{kind}")
    try:
        series, meta = reader(p, allow_truncated=allow_truncated, **opts)
    except ModuleNotFoundError as e:
        raise InputError(needs_package(f"{p}: reading a {kind} log", e.name, "field")) from None
    veh = meta.setdefault("vehicle", vehicle(None, f"a {kind} log does not say"))
    if require_marine and veh["marine"] is False:
        raise InputError(
            f"{p}: the log is of a {veh['type']} ({veh['from']}), not a boat; refused for boat identification "
            "(--force-vehicle to identify it anyway)"
        )
    if not series:
        raise InputError(f"{p}: no usable signal (no position, attitude or actuator messages)")
    t0 = span_start(series)
    if t0 is not None and (start is not None or end is not None):
        series = trim(series, t0, start, end, str(p))
        meta["trim"] = {"start_s": start, "end_s": end}
    check_heights(series, str(p), t0)
    cols, report = resample(series, rate, gap_s, source=str(p), t_origin=t0)
    report["notes"] = list(meta.pop("notes", []))
    cols = derive(cols, report)
    if body != "usv":  # e.g. the UUV of a .tlog (--system 2 --body uuv)
        if not body.isidentifier():
            raise InputError(f"--body {body!r}: expected a name such as usv or uuv")
        cols = {(body + k[3:] if k.startswith("usv.") else k): v for k, v in cols.items()}
    report = {"source": str(p), "format": kind, "body": body, **meta, **report}
    offset = report.pop("unix_offset_s", None)
    if offset is not None and "t0_source_s" in report:  # the log's own wall clock at t = 0 (MCAP log times)
        report["start_unix_s"] = float(report["t0_source_s"] + offset)
    return ImportResult(_to_df(cols), str(p), kind, rate, report)


def read_any(path, **opts):
    """A log of any supported format as a DataFrame: Parquet / CSV logs as they are, field logs
    (.bin, .tlog, .ulg, ROS 2 bag, or CSV with ``column_map``) imported with :func:`import_log` (its
    vehicle, notes, typestore and instances in ``df.attrs["import"]``)."""
    from ..logs import read_log

    p = Path(path)
    if not p.exists():
        raise InputError(f"log not found: {p}")
    kind = detect_format(p, opts.pop("fmt", None))
    if kind == "parquet" or (kind == "csv" and not opts.get("column_map")):
        if kind == "parquet" and opts.get("require_marine"):
            _imported_vehicle(p)
        return trim_rows(read_log(p), "t", opts.get("start"), opts.get("end"), str(p))
    res = import_log(p, **opts)
    res.df.attrs["import"] = {k: res.report.get(k) for k in ("vehicle", "notes", "typestore", "instances")}
    return res.df


def trim_rows(df, time_col: str, start=None, end=None, source: str = "log"):
    """The rows of a log between ``start`` and ``end`` (s, its own time column); refused if none is left."""
    if (start is None and end is None) or time_col not in df.columns:
        return df
    t = df[time_col].to_numpy(float)
    lo = -math.inf if start is None else float(start)
    hi = math.inf if end is None else float(end)
    if not lo < hi:
        raise InputError(f"--start {start} --end {end}: the start must come before the end")
    keep = (t >= lo - 1e-9) & (t <= hi + 1e-9)
    if keep.sum() < 2:
        span = f"{np.nanmin(t):.1f} to {np.nanmax(t):.1f} s" if t.size else "no rows"
        raise InputError(f"{source}: nothing {_window(start, end)} (its {time_col} runs {span})")
    return df[keep].reset_index(drop=True)


def _imported_vehicle(p: Path) -> None:
    """A run folder written by ``oceangnc import`` keeps the log's vehicle in import.json: refuse a non-boat."""
    folder = p if p.is_dir() else p.parent
    try:
        rep = json.loads((folder / "import.json").read_text())
    except (OSError, ValueError):
        return  # a simulated run, or no import record: nothing says it is not a boat
    v = rep.get("vehicle") or {}
    if v.get("marine") is False:
        raise InputError(
            f"{p}: imported from {rep.get('source', 'a field log')}, a {v.get('type')} ({v.get('from')}), not a "
            "boat; refused for boat identification (--force-vehicle to identify it anyway)"
        )


def write_run(res: ImportResult, out_dir) -> Path:
    """Write ``log.parquet`` and ``import.json`` into the run folder ``out_dir``."""
    from ..logs import LogWriter

    d = Path(out_dir)
    d.mkdir(parents=True, exist_ok=True)
    df = res.df
    cols = [c for c in df.columns if c != "t"]
    w = LogWriter(d / "log.parquet", flush_rows=50000)
    t = df["t"].to_numpy()
    arr = df[cols].to_numpy()
    for i in range(len(df)):
        w.append(float(t[i]), dict(zip(cols, arr[i])))
    w.close()
    rep = dict(res.report)
    rep["columns"] = {c: _UNITS.get(c, "") for c in df.columns}
    (d / "import.json").write_text(json.dumps(rep, indent=2, default=float))
    return d / "log.parquet"


_UNITS = {
    "t": "s",
    "usv.x": "m",
    "usv.y": "m",
    "usv.z": "m",
    "usv.psi": "rad",
    "usv.phi": "rad",
    "usv.theta": "rad",
    "usv.r": "rad/s",
    "usv.vn": "m/s",
    "usv.ve": "m/s",
    "usv.speed": "m/s",
    "usv.u": "m/s",
    "usv.v": "m/s",
    "act.left": "1",
    "act.right": "1",
    "act.throttle": "1",
    "act.steer": "1",
    "cable.top_tension": "N",
    "uuv.z": "m",
}
