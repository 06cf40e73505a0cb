"""The field test of 003 ch. 6.2 on the three-point bridle of fig. 5-6: a sweep, with the project's own sweep
tool (:func:`oceangnc.sweep.sweep`), over the bridle's geometry (apex height = wire lengths, hull point
spacing) and the ch. 6 formation (l^d, R, UUV controller), and the single point for reference.

003 (003_486f48bcab6eec1d.txt ch. 6.2) reports the UUV's pitch at -2 to -4 deg while following the
waypoints and its depth going from 3 m to about 2.75 m; it prints neither the bridle's dimensions (fig.
5-6 is a photograph) nor the formation of the field test. Each run's pitch (median while the USV moves,
as the validation case) and its 10/90 % quantiles are read from the run's log; depth, distance and
heading error come from the summary.

``python -m oceangnc.validation.bridle_sweep OUT`` writes ``OUT/bridle_sweep.csv`` and
``OUT/bridle_sweep.png`` (51 runs of 214 s, about 1 min on one core once compiled).
"""

from __future__ import annotations

import math
import sys
import tempfile
from pathlib import Path

import numpy as np

#: wire lengths: the rigged apex's height above the centre of buoyancy (cable.bridle.apex_z, m, negative up)
APEX_Z = [-0.625, -1.0, -1.5, -2.0]
#: hull point spacing: fore and aft points at +-s of the centre of buoyancy (m)
SPACING = [0.3, 0.6, 0.85]
L_D = [0.5, 1.0, 1.5]
#: formation and controller on the default bridle
FORMATION = {"formation.R": [1.0, 2.0], "control.uuv.kind": ["pid", "backstepping"], "formation.l_d": L_D}
BAND = (-6.0, 0.0)  # 003 ch. 6.2's -2..-4 deg widened by 2 deg


def pitch_stats(df) -> dict:
    """Median, 10 % and 90 % quantiles of the UUV's pitch (deg) while the USV moves (> 0.3 m/s)."""
    moving = df["usv.speed"].to_numpy() > 0.3
    th = np.degrees(df["uuv.theta"].to_numpy()[moving])
    return {
        "pitch_median_deg": float(np.median(th)),
        "pitch_p10_deg": float(np.quantile(th, 0.1)),
        "pitch_p90_deg": float(np.quantile(th, 0.9)),
        "roll_max_deg": float(np.degrees(np.abs(df["uuv.phi"].to_numpy()).max())),
    }


def _rows(res, fixed: dict) -> list[dict]:
    import pandas as pd

    rows = []
    for _, r in res.table.iterrows():
        row = {**fixed, **{k[6:]: r[k] for k in res.table.columns if k.startswith("param.")}, "status": r["status"]}
        if r["status"] == "ok":
            df = pd.read_parquet(Path(r["out_dir"]) / "log.parquet", columns=["usv.speed", "uuv.theta", "uuv.phi"])
            row.update(pitch_stats(df))
            for k in ("uuv.depth_final_m", "uuv.rel_distance_mean_m", "uuv.heading_error_rms_deg"):
                row[k] = float(r[k])
        rows.append(row)
    return rows


def run(out: Path, workers: int = 0) -> list[dict]:
    """The three sweeps of ``field-test`` (module docstring), one row per run."""
    from ..sweep import sweep

    rows: list[dict] = []
    # on the 3 m cable of ch. 4 (field-test before the fit of docs/validation/bridle_fit.py hung the UUV at 3 m)
    bri = {"cable.attachment": "bridle", "cable.length": 3.0}
    for s in SPACING:
        fixed = {**bri, "cable.bridle.fore_x": s, "cable.bridle.aft_x": -s}
        grid = {"cable.bridle.apex_z": APEX_Z, "formation.l_d": L_D}
        res = sweep("field-test", grid=grid, overrides=fixed, workers=workers, out=out / f"geometry-{s:g}")
        rows += _rows(res, {"cable.attachment": "bridle", "spacing_m": s})
    res = sweep("field-test", grid=FORMATION, overrides={**bri, "cable.bridle.apex_z": -1.0}, workers=workers,
                out=out / "formation")  # fmt: skip
    rows += _rows(res, {"cable.attachment": "bridle", "spacing_m": 0.6})
    res = sweep("field-test", grid={"formation.l_d": L_D}, overrides={**bri, "cable.attachment": "single"}, workers=workers,
                out=out / "single")  # fmt: skip
    rows += _rows(res, {"cable.attachment": "single"})
    return rows


def plot(rows: list[dict], path: Path) -> Path:
    """(a) pitch median (10-90 % bars) against the apex height, one line per l^d, spacing 0.6 m; (b) the same
    against the hull point spacing at apex -1.0 m; (c) pitch against l^d per controller and R, and the
    single point; 003's band and the widened band shaded."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    ok = [r for r in rows if r["status"] == "ok"]
    fig, ax = plt.subplots(1, 3, figsize=(15, 4.5), sharey=True)
    for a in ax:
        a.axhspan(*BAND, color="0.9", label="003 band widened by 2 deg")
        a.axhspan(-4.0, -2.0, color="0.75", label="003 ch. 6.2: -2 to -4 deg")

    def errbar(a, pts, x, label, **kw):
        pts = sorted(pts, key=lambda r: r[x])
        xs = [r[x] for r in pts]
        med = np.array([r["pitch_median_deg"] for r in pts])
        lo = med - np.array([r["pitch_p10_deg"] for r in pts])
        hi = np.array([r["pitch_p90_deg"] for r in pts]) - med
        a.errorbar(xs, med, yerr=[lo, hi], marker="o", capsize=3, label=label, **kw)

    geo = [r for r in ok if "cable.bridle.apex_z" in r]
    for ld in L_D:
        errbar(ax[0], [r for r in geo if r["spacing_m"] == 0.6 and r["formation.l_d"] == ld],
               "cable.bridle.apex_z", f"l^d = {ld:g} m")  # fmt: skip
        errbar(ax[1], [r for r in geo if r["cable.bridle.apex_z"] == -1.0 and r["formation.l_d"] == ld],
               "spacing_m", f"l^d = {ld:g} m")  # fmt: skip
    ax[0].set_xlabel("rigged apex z (body, m; wires 0.5-1.9 m)")
    ax[1].set_xlabel("hull point spacing +-s (m), apex z = -1.0 m")
    form = [r for r in ok if "control.uuv.kind" in r]
    for kind in ("pid", "backstepping"):
        for R in (1.0, 2.0):
            pts = [r for r in form if r["control.uuv.kind"] == kind and r["formation.R"] == R]
            errbar(ax[2], pts, "formation.l_d", f"bridle, {kind}, R = {R:g} m")
    single = [r for r in ok if r["cable.attachment"] == "single"]
    errbar(ax[2], single, "formation.l_d", "single point, pid, R = 1 m", color="k", ls="--")
    ax[2].set_xlabel("formation target l^d (m)")
    ax[0].set_ylabel("UUV pitch while moving (deg): median, 10-90 %")
    for a, t in zip(ax, ("(a) wire length", "(b) hull point spacing", "(c) formation and controller"), strict=True):
        a.set_title(t)
        a.grid(alpha=0.3)
        a.legend(fontsize=7)
    ax[0].set_ylim(-60, 25)
    fig.suptitle("field-test (003 ch. 6.2) on the three-point bridle of 003 fig. 5-6")
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    plt.close(fig)
    return path


COLUMNS = [
    "cable.attachment", "spacing_m", "cable.bridle.apex_z", "formation.l_d", "formation.R", "control.uuv.kind",
    "status", "pitch_median_deg", "pitch_p10_deg", "pitch_p90_deg", "roll_max_deg", "uuv.depth_final_m",
    "uuv.rel_distance_mean_m", "uuv.heading_error_rms_deg",
]  # fmt: skip


def main(argv: list[str] | None = None) -> int:
    import csv

    argv = sys.argv[1:] if argv is None else argv
    out = Path(argv[0]) if argv else Path("docs/validation")
    out.mkdir(parents=True, exist_ok=True)
    with tempfile.TemporaryDirectory() as tmp:
        rows = run(Path(tmp))
    with open(out / "bridle_sweep.csv", "w", newline="") as f:
        w = csv.DictWriter(f, COLUMNS, extrasaction="ignore")
        w.writeheader()
        for r in rows:
            w.writerow({k: (f"{v:.4g}" if isinstance(v, float) and math.isfinite(v) else v) for k, v in r.items()})
    print(f"wrote {plot(rows, out / 'bridle_sweep.png')} and {out / 'bridle_sweep.csv'} ({len(rows)} runs)")
    return 0


if __name__ == "__main__":
    sys.exit(main())
