"""The operability table and diagram of a sea-state sweep (issue 29).

A sweep of ``tow-sea-state`` (or any scenario whose summary has a 0/1 ``sea.pass`` and ``limits.*``
columns) over the significant wave height, the peak period and other keys (the wave heading relative
to the line, the tow speed) gives, per sea state, the fraction of its runs (seeds) that pass every
limit. A run that failed or diverged counts as not passing: a tow that blows up is not operable.

* ``report/operability.csv``: one row per sea state and panel (the swept keys other than Hs and Tp),
  with the runs, the pass fraction and, per limit, the fraction of runs that met it;
* ``report/operability.md``: per panel, a table of Hs (rows) against Tp (columns): ``pass``, or the
  limits that failed (T tension, S snap, D depth std, P pitch std), with the pass fraction if it is
  neither 0 nor 1;
* ``report/operability.png``: per panel a heat map of the pass fraction (green: every run passes,
  red: none) over Hs x Tp, each cell labelled with the failed limits' letters.

The rows and columns are the first two swept keys (Hs and Tp when both are swept, else e.g. Hs and the wave
heading), named and labelled from the keys themselves (:func:`axis`), never as Hs and Tp by position.

**Reading it**: the operable envelope at a heading is the green region; its upper edge is the
limiting Hs at each Tp. Short periods at a given Hs are steeper and faster seas (larger particle
accelerations a ~ (2 pi / T)^2 Hs / 2), so the envelope usually rises with Tp.
"""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pandas as pd

from .table import PARAM

#: limit column -> letter in the diagram
LIMITS = {
    "limits.tension_ok": "T",
    "limits.no_snap": "S",
    "limits.depth_std_ok": "D",
    "limits.pitch_std_ok": "P",
}
PASS = "sea.pass"
#: the diagram's shade of a verdict (green pass, yellow marginal, red fail; issue 40)
VERDICT_SHADE = {"pass": 1.0, "marginal": 0.5, "fail": 0.0, "outside model": np.nan}  # nan: left blank (white)


#: axis names of the usual swept keys (by the key's ending): (name, unit)
AXES = {"waves.hs": ("Hs", "m"), "waves.tp": ("Tp", "s"), "waves.direction_deg": ("wave heading", "deg")}
#: units of a key by its name's ending (the project's config names carry their unit: ``speed_mps``...)
UNIT_SUFFIXES = {"_deg": "deg", "_mps": "m/s", "_m": "m", "_s": "s", "_n": "N", "_hz": "Hz"}


def axis(key: str | None) -> tuple[str, str]:
    """(name, unit) of a swept key for the table's and the diagram's axes: :data:`AXES`, else the key's last
    part with its unit suffix (:data:`UNIT_SUFFIXES`) split off; ``("", "")`` for no key."""
    if key is None:
        return "", ""
    for end, nu in AXES.items():
        if key.endswith(end):
            return nu
    last = key.split(".")[-1]
    for suf, unit in UNIT_SUFFIXES.items():
        if last.endswith(suf):
            return last[: -len(suf)], unit
    return last, ""


def _fmt(v, unit: str) -> str:
    return f"{v:g} {unit}".rstrip() if isinstance(v, (int, float, np.number)) else str(v)


def _key(params: list[str], suffix: str) -> str | None:
    for p in params:
        if p.endswith(suffix):
            return p
    return None


def operability_table(df: pd.DataFrame, hs_key: str | None = None, tp_key: str | None = None):
    """(table, hs key, tp key, panel keys): the pass fraction per sea state and panel, and per limit
    (module docstring). The Hs and Tp keys default to the swept keys ending in ``waves.hs``/``waves.tp``."""
    params = [c[len(PARAM) :] for c in df.columns if c.startswith(PARAM)]
    hs_key = hs_key or _key(params, "waves.hs")
    tp_key = tp_key or _key(params, "waves.tp")
    if hs_key is None or tp_key is None:
        rest = [p for p in params if p not in (hs_key, tp_key)]
        hs_key = hs_key or (rest.pop(0) if rest else None)
        tp_key = tp_key or (rest.pop(0) if rest else None)
    panels = [p for p in params if p not in (hs_key, tp_key)]
    d = df.copy()
    if tp_key is None:  # one swept key: a single column
        tp_key = "_one"
        d[PARAM + tp_key] = 0.0
    ok = d["status"] == "ok"
    d["_pass"] = np.where(ok, d[PASS].fillna(0).astype(float) if PASS in d else 0.0, 0.0)
    for c in LIMITS:
        d[c] = np.where(ok, d[c].fillna(0).astype(float), 0.0) if c in d else np.where(ok, 1.0, 0.0)
    by = [PARAM + k for k in [*panels, hs_key, tp_key] if k is not None]
    agg = {"_pass": "mean", "status": "size", **{c: "mean" for c in LIMITS}}
    others = [c for c in LIMITS if c != "limits.tension_ok"]
    d["_other"] = np.where(ok, np.all([d[c].to_numpy() >= 1.0 for c in others], axis=0), False).astype(float)
    t = d.groupby(by, sort=True, dropna=False).agg(agg).reset_index()
    t = t.merge(_extremes(d, by), on=by, how="left")
    t = t.rename(columns={"_pass": "pass_fraction", "status": "runs", **{PARAM + k: k for k in [*params, tp_key]}})
    return t, hs_key, tp_key, panels


def _extremes(d: pd.DataFrame, by: list[str]) -> pd.DataFrame:
    """Per sea state: the most probable maximum top tension and its interval from the seeds' maxima
    (:func:`.extremes.gumbel_mpm`), the tension limit, and the verdict (:func:`.extremes.cell_verdict`)."""
    from .extremes import cell_verdict, gumbel_mpm, tension_verdict

    rows = []
    for key, g in d.groupby(by, sort=True, dropna=False):
        key = key if isinstance(key, tuple) else (key,)
        okg = g[g["status"] == "ok"]
        mx = okg["cable.top_max_N"].to_numpy(float) if "cable.top_max_N" in okg else np.zeros(0)
        win = float(okg["analysis.window_s"].mean()) if "analysis.window_s" in okg and len(okg) else 0.0
        mpm, lo, hi, _ = gumbel_mpm(mx, win)
        lim = float(okg["limits.tension_limit_N"].iloc[0]) if "limits.tension_limit_N" in okg and len(okg) else np.nan
        if np.isfinite(lim) and len(okg) == len(g):
            tv = tension_verdict(mpm, lo, hi, lim)
        else:  # no limit in the summaries, or runs that failed: the per-run tension checks decide
            f = float(g["limits.tension_ok"].mean())
            tv = "pass" if f >= 1.0 else ("fail" if f <= 0.0 else "marginal")
        verdict = cell_verdict(tv, float(g["_other"].mean())) if len(okg) == len(g) else "fail"  # a run blew up
        if "sea.in_model" in okg and (okg["sea.in_model"].fillna(1) < 1).any():
            verdict = "outside model"  # never "pass" where the model does not hold (._sea_validity)
        rows.append((*key, mpm, lo, hi, lim, tv, verdict))
    cols = [*by, "tension_mpm_N", "tension_lo_N", "tension_hi_N", "tension_limit_N", "tension_verdict", "verdict"]
    return pd.DataFrame(rows, columns=cols)


def _label(row) -> str:
    """``pass``, ``marginal: <limits>`` or the failed limits' letters (pass fraction if neither 0 nor 1)."""
    failed = "".join(
        letter
        for c, letter in LIMITS.items()
        if (row.get("tension_verdict", "pass") != "pass" if c == "limits.tension_ok" else row[c] < 1.0)
    )
    v = row.get("verdict")
    if v == "outside model":
        return v
    if v == "pass" or (v is None and row["pass_fraction"] >= 1.0):
        return "pass"
    if v == "marginal":
        return f"marginal {failed}".strip()
    f = row["pass_fraction"]
    return (failed or "fail") + ("" if f == 0.0 else f" ({f:.0%})")


def _panel_groups(t: pd.DataFrame, panels: list[str]):
    if not panels:
        return [("all runs", t)]
    out = []
    for key, g in t.groupby(panels, sort=True, dropna=False):
        key = key if isinstance(key, tuple) else (key,)
        out.append((", ".join(f"{p.split('.')[-1]} = {v:g}" if isinstance(v, (int, float)) else f"{p} = {v}"
                              for p, v in zip(panels, key)), g))  # fmt: skip
    return out


def operability_markdown(t, hs_key, tp_key, panels) -> str:
    lines = [
        "# Operability",
        "",
        "Per sea state: `pass`, `marginal` (the extreme tension's interval straddles its limit, or the seeds "
        "disagree on another limit) or the failed limits (T tension, S snap, D UUV depth std, P UUV pitch std) "
        "with the pass fraction over the runs. Below each table: the most probable maximum top tension over the "
        "record and its 90 % interval (Gumbel fit of the seeds' maxima; one seed: its maximum, no interval).",
    ]
    tps = sorted(t[tp_key].unique())
    (rn, ru), (cn, cu) = axis(hs_key), axis(None if tp_key == "_one" else tp_key)
    for title, g in _panel_groups(t, panels):
        lines += ["", f"## {title}", "", f"| {rn} \\ {cn or '-'} | " + " | ".join(_fmt(v, cu) for v in tps) + " |"]
        lines.append("|---" * (len(tps) + 1) + "|")
        for hs in sorted(g[hs_key].unique()):
            cells = []
            for tp in tps:
                r = g[(g[hs_key] == hs) & (g[tp_key] == tp)]
                cells.append(_label(r.iloc[0]) if len(r) else "")
            lines.append(f"| {_fmt(hs, ru)} | " + " | ".join(cells) + " |")
        head = f"| {rn} \\ {cn or '-'} (MPM [interval] N) | " + " | ".join(_fmt(v, cu) for v in tps) + " |"
        lines += ["", head]
        lines.append("|---" * (len(tps) + 1) + "|")
        for hs in sorted(g[hs_key].unique()):
            cells = []
            for tp in tps:
                r = g[(g[hs_key] == hs) & (g[tp_key] == tp)]
                cells.append(_estimate(r.iloc[0]) if len(r) else "")
            lines.append(f"| {_fmt(hs, ru)} | " + " | ".join(cells) + " |")
    return "\n".join(lines) + "\n"


def _estimate(row) -> str:
    mpm, lo, hi = (row.get(k, np.nan) for k in ("tension_mpm_N", "tension_lo_N", "tension_hi_N"))
    if not np.isfinite(mpm):
        return ""
    return f"{mpm:.0f}" if not np.isfinite(lo) else f"{mpm:.0f} [{lo:.0f}, {hi:.0f}]"


def plot_operability(t, hs_key, tp_key, panels, path: Path, title: str) -> Path:
    """Heat maps of the pass fraction over Hs x Tp, one panel per combination of the other keys."""
    import matplotlib.pyplot as plt

    fig = operability_figure(t, hs_key, tp_key, panels, title)
    fig.savefig(path, dpi=100)
    plt.close(fig)
    return path


def operability_figure(t, hs_key, tp_key, panels, title: str):
    """The figure of :func:`plot_operability`: rows and columns named from the swept keys (:func:`axis`),
    the title wrapped to the figure's width."""
    import textwrap

    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    groups = _panel_groups(t, panels)
    n = len(groups)
    ncol = min(n, 4)
    nrow = math.ceil(n / ncol)
    fig, axes = plt.subplots(
        nrow, ncol, figsize=(3.4 * ncol + 1.2, 3.2 * nrow + 0.7), squeeze=False, layout="constrained"
    )
    tps = sorted(t[tp_key].unique())
    hss = sorted(t[hs_key].unique())
    (rn, ru), (cn, cu) = axis(hs_key), axis(None if tp_key == "_one" else tp_key)
    ylab, xlab = f"{rn} [{ru}]" if ru else rn, (f"{cn} [{cu}]" if cu else cn)
    im = None
    for ax, (name, g) in zip(axes.ravel(), groups):
        grid = np.full((len(hss), len(tps)), np.nan)
        for _, r in g.iterrows():
            i = hss.index(r[hs_key])
            j = tps.index(r[tp_key])
            grid[i, j] = VERDICT_SHADE.get(r.get("verdict"), r["pass_fraction"])
            lab = _label(r)
            txt = {"marginal": lab.replace("marginal", "marg."), "outside model": "outside\nmodel"}.get(
                r.get("verdict"), lab.split(" ")[0]
            )
            ax.text(j, i, "" if lab == "pass" else txt, ha="center", va="center", fontsize=7)
        im = ax.imshow(grid, origin="lower", cmap="RdYlGn", vmin=0.0, vmax=1.0, aspect="auto")
        ax.set_xticks(range(len(tps)), [f"{v:g}" for v in tps])
        ax.set_yticks(range(len(hss)), [f"{v:g}" for v in hss])
        ax.set_xlabel(xlab)
        ax.set_ylabel(ylab)
        ax.set_title(name, fontsize=9)
    for ax in axes.ravel()[n:]:
        ax.axis("off")
    if im is not None:
        fig.colorbar(im, ax=axes.ravel().tolist(), label="fraction of runs passing", fraction=0.03)
    text = title + "  (letters: failed limits - T tension, S snap, D depth std, P pitch std)"
    width = fig.get_size_inches()[0] * 72 / (0.6 * 9)  # characters of 9 pt (about 0.6 em wide) per line
    fig.suptitle(textwrap.fill(text, max(20, int(width) - 4)), fontsize=9)
    return fig


def operability(df: pd.DataFrame, out_dir: str | Path, title: str = "operability", plots: bool = True) -> list[Path]:
    """Write the operability table (CSV, Markdown) and diagram (PNG) of a sweep's results into
    ``out_dir``; returns the files."""
    out = Path(out_dir)
    out.mkdir(parents=True, exist_ok=True)
    t, hs_key, tp_key, panels = operability_table(df)
    files = [out / "operability.csv", out / "operability.md"]
    t.drop(columns=["_one"], errors="ignore").to_csv(files[0], index=False)
    files[1].write_text(operability_markdown(t, hs_key, tp_key, panels))
    if plots:
        files.append(plot_operability(t, hs_key, tp_key, panels, out / "operability.png", title))
    return files
