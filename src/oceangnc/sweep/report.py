"""``oceangnc sweep-report DIR``: statistics per sweep point and plots of each metric against each swept key.

Per point (one combination of swept values; its rows differ only by ``sim.seed``), for every numeric
metric over the runs with ``status == "ok"``: ``n``, mean, sample standard deviation (``ddof = 1``;
empty with fewer than 2 runs), min and max, plus the counts of runs, ok runs and failed runs. They
are written to ``DIR/report/points.csv`` and ``DIR/report/report.md``. A sea-state sweep (a ``sea.pass``
column, two or more swept keys) also gets its operability table and diagram
(:mod:`oceangnc.sweep.operability`: ``operability.csv``, ``.md``, ``.png``).

Plots (``DIR/report/<metric>.png``, one panel per swept key): for keys with few distinct values
(a grid), the mean over seeds at each value with error bars of +-1 standard deviation across seeds,
one line per combination of the other keys (or, with more than 6 combinations, pooled over them),
and every run as a faint dot; for keys with many distinct values (random draws), every run as a dot
and the mean +-1 std in 8 equal-count bins. A sweep over seeds only gives a histogram.
"""

from __future__ import annotations

import json
import math
import re
from dataclasses import dataclass
from pathlib import Path

import numpy as np
import pandas as pd

from ..errors import InputError
from .table import FIXED_COLUMNS, PARAM, read_results
from ..core.files import LIMIT_JSON, read_text_bounded

MAX_GROUPS = 6
MAX_LEVELS = 20


@dataclass
class Report:
    """What :func:`make_report` returns: the per-point statistics and the files written."""

    points: pd.DataFrame
    metrics: list
    keys: list
    files: list


def metric_columns(df: pd.DataFrame) -> list[str]:
    """Numeric metric columns of a results table (not identity/param/bookkeeping columns)."""
    out = []
    for c in df.columns:
        if c in FIXED_COLUMNS or c.startswith(PARAM):
            continue
        if pd.api.types.is_numeric_dtype(df[c]) and not pd.api.types.is_bool_dtype(df[c]):
            out.append(c)
    return out


def point_stats(df: pd.DataFrame, metrics: list[str]) -> pd.DataFrame:
    """One row per point: swept values, run counts and n/mean/std/min/max of each metric."""
    params = [c for c in df.columns if c.startswith(PARAM)]
    rows = []
    for _, g in df.groupby("point_id", sort=False):
        first = g.iloc[0]
        row = {
            "point": int(first["point"]) if "point" in g else None,
            **{p: first[p] for p in params},
            "runs": len(g),
            "ok": int((g["status"] == "ok").sum()),
            "failed": int((g["status"] != "ok").sum()),
        }
        ok = g[g["status"] == "ok"]
        for m in metrics:
            v = ok[m].astype(float).dropna() if m in ok else pd.Series(dtype=float)
            row[f"{m}.n"] = len(v)
            row[f"{m}.mean"] = float(v.mean()) if len(v) else math.nan
            # identical values have exactly zero spread (not the rounding error of the mean)
            row[f"{m}.std"] = (0.0 if v.min() == v.max() else float(v.std(ddof=1))) if len(v) > 1 else math.nan
            row[f"{m}.min"] = float(v.min()) if len(v) else math.nan
            row[f"{m}.max"] = float(v.max()) if len(v) else math.nan
        rows.append(row)
    out = pd.DataFrame(rows)
    return out.sort_values("point").reset_index(drop=True) if len(out) else out


def _fmt(v) -> str:
    if isinstance(v, float):
        return "" if math.isnan(v) else f"{v:.4g}"
    return str(v)


def _markdown(points: pd.DataFrame, metrics: list[str], keys: list[str], df: pd.DataFrame, title: str) -> str:
    head = [*(k for k in keys), "ok/runs", *(f"{m} mean ± std" for m in metrics)]
    lines = [
        f"# {title}",
        "",
        f"{len(df)} runs, {int((df['status'] == 'ok').sum())} ok, "
        f"{int((df['status'] != 'ok').sum())} failed or diverged; statistics over seeds of the ok runs.",
        "",
        "| " + " | ".join(head) + " |",
        "|" + "---|" * len(head),
    ]
    for _, r in points.iterrows():
        cells = [_fmt(r[PARAM + k]) for k in keys] + [f"{int(r['ok'])}/{int(r['runs'])}"]
        for m in metrics:
            mean, std = r[f"{m}.mean"], r[f"{m}.std"]
            cells.append(_fmt(mean) + ("" if math.isnan(std) else f" ± {std:.2g}"))
        lines.append("| " + " | ".join(cells) + " |")
    bad = df[df["status"] != "ok"]
    if len(bad):
        lines += ["", "## Failed or diverged runs", ""]
        for _, r in bad.head(20).iterrows():
            where = ", ".join(f"{k}={_fmt(r[PARAM + k])}" for k in keys)
            lines.append(f"* {r['status']} ({where}, seed {r['seed']}): {r['error']}")
        if len(bad) > 20:
            lines.append(f"* ... and {len(bad) - 20} more (see results.parquet)")
    return "\n".join(lines) + "\n"


def _safe(name: str) -> str:
    return re.sub(r"[^A-Za-z0-9_.-]+", "_", name)


def _numeric(s: pd.Series) -> bool:
    return pd.api.types.is_numeric_dtype(s) and not pd.api.types.is_bool_dtype(s)


def _panel(ax, ok: pd.DataFrame, key: str, others: list[str], metric: str) -> None:
    col = PARAM + key
    x = ok[col]
    levels = list(pd.unique(x.dropna()))
    numeric = _numeric(x)
    if numeric:
        levels = sorted(levels)
    pos = (lambda s: s.astype(float)) if numeric else (lambda s: s.map({v: i for i, v in enumerate(levels)}))
    ax.plot(pos(x), ok[metric], ".", color="0.6", ms=3, alpha=0.6, label="runs")
    if len(levels) <= MAX_LEVELS:
        ocols = [PARAM + o for o in others]
        groups = list(ok.groupby(ocols, sort=True, dropna=False)) if ocols else [((), ok)]
        if len(groups) > MAX_GROUPS:
            groups = [(("all others",), ok)]
        for gkey, g in groups:
            st = g.groupby(col, sort=True)[metric].agg(["mean", "std"]).reindex(levels).dropna(subset=["mean"])
            gkey = gkey if isinstance(gkey, tuple) else (gkey,)
            if ocols and gkey != ("all others",):
                label = ", ".join(f"{o.split('.')[-1]}={_fmt(v)}" for o, v in zip(others, gkey))
            else:
                label = "mean ± std over seeds" if not ocols else "mean ± std (pooled)"
            xs = pos(pd.Series(st.index))
            ax.errorbar(xs, st["mean"], yerr=st["std"].fillna(0.0), marker="o", ms=4, capsize=3, lw=1.2, label=label)
    else:
        xv = x.astype(float).to_numpy()
        yv = ok[metric].astype(float).to_numpy()
        edges = np.unique(np.quantile(xv, np.linspace(0, 1, 9)))
        idx = np.clip(np.searchsorted(edges, xv, side="right") - 1, 0, len(edges) - 2)
        cx, my, sy = [], [], []
        for b in range(len(edges) - 1):
            sel = idx == b
            if sel.sum():
                cx.append(xv[sel].mean())
                my.append(yv[sel].mean())
                sy.append(yv[sel].std(ddof=1) if sel.sum() > 1 else 0.0)
        ax.errorbar(cx, my, yerr=sy, marker="o", ms=4, capsize=3, lw=1.2, label="binned mean ± std")
    if not numeric:
        ax.set_xticks(range(len(levels)), [_fmt(v) for v in levels])
    ax.set_xlabel(key)
    ax.set_ylabel(metric)
    ax.grid(True, alpha=0.3)
    ax.legend(fontsize=7, loc="best")


def plot_metric(df: pd.DataFrame, metric: str, keys: list[str], path: Path, title: str) -> Path:
    """One PNG: ``metric`` against each swept key (or its histogram over seeds if none is swept)."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    ok = df[(df["status"] == "ok") & df[metric].notna()]
    n = max(1, len(keys))
    fig, axes = plt.subplots(1, n, figsize=(4.6 * n + 0.4, 3.8), squeeze=False)
    if not keys:
        ax = axes[0, 0]
        ax.hist(ok[metric].astype(float), bins=min(30, max(5, len(ok) // 3)), color="C0", alpha=0.8)
        ax.set_xlabel(metric)
        ax.set_ylabel("runs")
        ax.grid(True, alpha=0.3)
    for ax, k in zip(axes[0], keys):
        _panel(ax, ok, k, [o for o in keys if o != k], metric)
    fig.suptitle(title, fontsize=10)
    fig.tight_layout()
    fig.savefig(path, dpi=100)
    plt.close(fig)
    return path


def make_report(sweep_dir: str | Path, metrics: list[str] | None = None, plots: bool = True) -> Report:
    """Statistics per point and plots for a sweep folder; see the module docstring."""
    d = Path(sweep_dir)
    df = read_results(d)
    try:
        spec = json.loads(read_text_bounded(d / "sweep.json", LIMIT_JSON, "sweep spec"))
    except (OSError, ValueError, RecursionError):
        spec = {}
    params = [c[len(PARAM) :] for c in df.columns if c.startswith(PARAM)]
    order = [*(spec.get("grid") or {}), *(spec.get("random") or {})]
    keys = [k for k in order if k in params] + [k for k in params if k not in order]
    available = metric_columns(df)
    if metrics:
        unknown = [m for m in metrics if m not in df.columns]
        if unknown:
            raise InputError(f"--metric {unknown[0]}: not a column of the results; metrics: {', '.join(available)}")
        chosen = list(metrics)
    else:
        chosen = [m for m in available if m != "duration_s"] or available
    points = point_stats(df, chosen)
    rep = d / "report"
    rep.mkdir(exist_ok=True)
    files = []
    points.to_csv(rep / "points.csv", index=False)
    files.append(rep / "points.csv")
    title = f"sweep of {spec.get('scenario', '?')}"
    (rep / "report.md").write_text(_markdown(points, chosen, keys, df, title))
    files.append(rep / "report.md")
    if plots:
        for m in chosen:
            if df.loc[df["status"] == "ok", m].notna().any():
                files.append(plot_metric(df, m, keys, rep / f"{_safe(m)}.png", f"{title}: {m}"))
    if "sea.pass" in df.columns and len(keys) >= 2:  # a sea-state sweep: the operability table and diagram
        from .operability import operability

        files += operability(df, rep, f"{title}: operability", plots)
    return Report(points, chosen, keys, files)
