"""The flagship of 003 ch. 4 (combined-survey): why PID and backstepping come out nearly equal and why the
UUV does not rise to 2.77 m; a small sensitivity sweep over the parameters 003 does not print.

What 003 (003_486f48bcab6eec1d.txt ch. 4, figs 4-7 to 4-15; ch. 6.2, figs 6-13 to 6-19) shows: a 3 m
cable, the UUV starting 3 m deep, tow speed 0.6 m/s; backstepping keeps the relative distance near
0.4 m and the depth converges near 2.77 m; PID overshoots; the UUV's desired heading switches at
about 25 s and the distance grows over 25-30 s; in the field test the UUV rises from 3 m to about
2.75 m with a pitch of -2 to -4 deg.

The two pieces of physics this module measures:

* **Geometry of the depth.** On a taut cable of effective length L_e (unstretched length + stretch +
  the tow point's height above the centre of buoyancy) the UUV's centre sits
  ``z = sqrt(L_e^2 - d^2) + ...`` below the attachment, d the horizontal offset between the USV's
  attachment point and the UUV's tow point. The rise from the hanging equilibrium is
  ``L_e - sqrt(L_e^2 - d^2)``: 0.23 m (3 -> 2.77 m) needs d = 1.15 m on a 3 m cable.
  :func:`depth_rise` gives it.
* **Pendulum stiffness of the cable.** A cable carrying the UUV's submerged weight W_s pulls the UUV
  back under the attachment with a horizontal stiffness ``k_c = T / L ~ W_s / L`` (50 N/m for 12 kgf on
  3 m), as large as the controllers' own position stiffness (PID K_p 40 N/m; backstepping
  ``m11 (1 + k1 k6)`` 51 N/m). Where the formation target sits near the hanging point, the cable does
  most of the holding and any stable controller gives nearly the same distance.

:func:`sweep` runs ``combined-survey`` over a small grid (attachment point on the USV, the UUV's
submerged weight, controller) and :func:`plot_sweep` draws it; ``python -m
oceangnc.validation.flagship OUT`` writes ``flagship_sweep.csv`` and ``flagship_sweep.png``.
"""

from __future__ import annotations

import math
import sys
import tempfile
from pathlib import Path

import numpy as np

from ..units import G

#: printed numbers of 003 ch. 4 / 6.2 used by the flagship cases (source in each comment)
PUBLISHED = {
    "rel_distance_bs_m": 0.4,  # 003 ch. 4, figs 4-14/4-15 text: backstepping keeps about 0.4 m
    "depth_final_bs_m": 2.77,  # 003 ch. 4, fig 4-14 text: depth converges near 2.77 m
    "depth_start_m": 3.0,  # 003 ch. 4: the UUV starts 3 m deep
    "field_depth_final_m": 2.75,  # 003 ch. 6.2, fig 6-17: 3 m -> about 2.75 m
    "field_pitch_deg": (-4.0, -2.0),  # 003 ch. 6.2: UUV pitch -2 to -4 deg
}

GRID = {
    "cable.top_x": [-1.15, -0.75, 0.0, 0.75, 1.15],
    "uuv.weight_in_water_kgf": [12.0, 4.0],
    "formation.l_d": [0.5, 1.3],
    "control.uuv": ["pid", "backstepping"],
}

#: extra points: other gains (backstepping 2.5x stiffer; the PID's first tuning with an integral heading term;
#: a stiffer PID position loop), and a draggier UUV
EXTRA = [
    {
        "control.uuv": "backstepping",
        "control.backstepping.k1": 1.0,
        "control.backstepping.k2": 1.0,
        "control.backstepping.k6": 3.0,
        "control.backstepping.k7": 4.0,
    },
    {"control.uuv": "pid", "control.uuv_pid.angle_ki": 2.0},
    {"control.uuv": "pid", "control.uuv_pid.range_kp": 120.0, "control.uuv_pid.range_kd": 60.0},
    # all quadratic drag and lift x5 / x15 (not one physical parameter: it also scales the Munk moment folded
    # into M_uw), and the appendage drag area x3 / x7 (a draggier UUV with external thrusters)
    *[{"control.uuv": c, "uuv.drag_scale": k} for k in (5.0, 15.0) for c in ("pid", "backstepping")],
    *[{"control.uuv": c, "uuv.appendage_drag_area": a} for a in (0.1, 0.2) for c in ("pid", "backstepping")],
    # attachment 1.15 m forward with the tow point 5 cm ahead of the CB (trims the towed UUV's pitch)
    *[{"control.uuv": c, "cable.top_x": 1.15, "uuv.x0": 1.10, "cable.tow_x": 0.05} for c in ("pid", "backstepping")],
]


def depth_rise(d: float, L_e: float) -> float:
    """Rise (m) of the UUV above its hanging point when its tow point is d (m) aft/ahead of the attachment
    on a straight taut cable of effective length L_e (m): ``L_e - sqrt(L_e^2 - d^2)``."""
    return L_e - math.sqrt(max(L_e * L_e - d * d, 0.0))


def offset_for_rise(rise: float, L_e: float) -> float:
    """Horizontal offset (m) that gives a rise (m) on a taut cable of effective length L_e (m)."""
    return math.sqrt(max(L_e * L_e - (L_e - rise) ** 2, 0.0))


def cable_stiffness(weight_in_water_kgf: float, cable_weight_n: float, length: float) -> float:
    """Horizontal restoring stiffness (N/m) of a hanging UUV on a cable, pendulum small-angle: T / L with
    T the bottom tension plus half the cable's submerged weight."""
    return (weight_in_water_kgf * G + 0.5 * cable_weight_n) / length


def survey_metrics(summary: dict, df) -> dict:
    """Distance, depth and pitch numbers of one combined-survey run (true signals)."""
    from ..scenarios.combined import rel_distance

    rd = rel_distance(df)
    t = df["t"].to_numpy()
    late = t > t[-1] - 10.0
    turn = (t >= 25.0) & (t <= 30.0)
    return {
        "rel_mean_m": summary["uuv.rel_distance_mean_m"],
        "rel_max_m": summary["uuv.rel_distance_max_m"],
        "rel_growth_25_30_m": float(rd[turn].max() - rd[turn].min()) if turn.any() else float("nan"),
        "depth_final_m": summary["uuv.depth_final_m"],
        "depth_start_m": float(df["uuv.z"].iloc[0]),
        "pitch_late_deg": float(np.degrees(df["uuv.theta"].to_numpy()[late].mean())),
        "heading_err_rms_deg": summary["uuv.heading_error_rms_deg"],
        "t_end_s": summary["t_end_s"],
    }


def run_point(over: dict, runner=None) -> dict:
    """One ``combined-survey`` run with ``over`` (the UUV starts under the attachment point)."""
    from ..api import run

    o = dict(over)
    if "cable.top_x" in o and "uuv.x0" not in o:
        o["uuv.x0"] = o["cable.top_x"]  # start hanging under the attachment, not on a stretched cable
    if runner is not None:
        s, df = runner.run("combined-survey", **o)
    else:
        with tempfile.TemporaryDirectory() as d:
            res = run("combined-survey", overrides=o, out=d, plots=False)
            s, df = res.summary, res.df
    return {**over, **survey_metrics(s, df)}


class _Rows:
    def __init__(self):
        self.rows = []

    def append(self, t, row):
        self.rows.append(dict(t=t, **row))


def run_uncontrolled(over: dict | None = None) -> dict:
    """``combined-survey`` with the UUV's thrusters held at zero (the controller still runs, its thrust
    never reaches the UUV): the UUV only hangs on the cable. Same metrics as :func:`run_point`."""
    import pandas as pd

    from ..api import resolve_config
    from ..scenarios.combined import build_simulation

    sc, cfg = resolve_config("combined-survey", overrides=dict(over or {}))
    sim = build_simulation(cfg, np.random.default_rng(cfg.sim.seed))
    for b in sim.blocks:
        if getattr(b, "name", "") == "uuv_thrusters":
            b.hi = b.lo = 0.0
    log = _Rows()
    sim.run(cfg.sim.duration, log=log)
    df = pd.DataFrame(log.rows)
    return survey_metrics(sc.summarize(df, cfg), df)


def sweep(
    grid: dict | None = None, extra: list | None = None, passive: bool = True, progress: bool = True
) -> list[dict]:
    """Full factorial over ``grid`` (dotted keys -> values), then the ``extra`` points, then (``passive``)
    the UUV with its thrusters at zero at each attachment point; one row per run (``kind`` says which)."""
    import itertools

    grid = GRID if grid is None else grid
    extra = EXTRA if extra is None else extra
    keys = list(grid)
    points = [("grid", dict(zip(keys, vals))) for vals in itertools.product(*grid.values())]
    points += [("extra", dict(e)) for e in extra]
    if passive:
        points += [("passive", {"cable.top_x": x, "control.uuv": "pid"}) for x in grid.get("cable.top_x", [0.0])]
    rows = []
    for i, (kind, over) in enumerate(points):
        try:
            if kind == "passive":
                o = {**over, "uuv.x0": over["cable.top_x"]}
                rows.append({"kind": kind, **over, **run_uncontrolled(o)})
            else:
                rows.append({"kind": kind, **run_point(over)})
        except Exception as e:  # a diverged point is a result too
            rows.append({"kind": kind, **over, "error": f"{type(e).__name__}: {e}"})
        if progress:
            print(
                f"[{i + 1}/{len(points)}] {kind} {over} -> "
                f"{ {k: round(v, 3) for k, v in rows[-1].items() if isinstance(v, float) and k not in over} }",
                file=sys.stderr,
                flush=True,
            )
    return rows


def plot_sweep(rows: list[dict], path: Path) -> Path:
    """(a) final depth against mean USV-UUV distance for every run, colour = UUV pitch, with 003's box
    (0.3-0.5 m, 2.72-2.82 m); (b) pitch against the attachment point; (c) PID minus backstepping mean
    distance per (attachment, weight, l^d)."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    from matplotlib.patches import Rectangle

    ok = [r for r in rows if "error" not in r and math.isfinite(r.get("depth_final_m", math.nan))]
    fig, axs = plt.subplots(1, 3, figsize=(15, 4.6))
    ax = axs[0]
    mk = {"pid": "s", "backstepping": "o"}
    for kind in ("grid", "extra", "passive"):
        sel = [r for r in ok if r["kind"] == kind]
        if not sel:
            continue
        for ctrl in ("pid", "backstepping"):
            ss = [r for r in sel if r.get("control.uuv") == ctrl]
            if not ss:
                continue
            lab = {"grid": "grid", "extra": "other gains", "passive": "thrusters off"}[kind]
            sc = ax.scatter(
                [r["rel_mean_m"] for r in ss],
                [min(max(r["depth_final_m"], -0.5), 4.0) for r in ss],
                c=[min(abs(r["pitch_late_deg"]), 60) for r in ss],
                cmap="viridis_r",
                vmin=0,
                vmax=60,
                marker="x" if kind == "passive" else mk[ctrl],
                s=40 if kind != "extra" else 90,
                edgecolors="k" if kind == "extra" else None,
                label=f"{lab}: {'PID' if ctrl == 'pid' else 'backstepping'}"
                if kind != "passive"
                else "thrusters off (towed)",
            )
    ax.add_patch(Rectangle((0.3, 2.72), 0.2, 0.10, fill=False, ec="C3", lw=2, label="003: ≈0.4 m, ≈2.77 m"))
    fig.colorbar(sc, ax=ax, label="|UUV pitch|, last 10 s [deg] (003: 2-4)")
    ax.set_xlabel("mean USV-UUV horizontal distance [m]")
    ax.set_ylabel("final UUV depth [m] (clipped to -0.5)")
    ax.invert_yaxis()
    ax.legend(fontsize=7, loc="lower right")
    ax.grid(alpha=0.3)
    ax.set_title("(a) every run: no point in 003's box with small pitch", fontsize=9)
    ax = axs[1]
    for w, col in zip(
        sorted({r.get("uuv.weight_in_water_kgf", 12.0) for r in ok if r["kind"] == "grid"}, reverse=True),
        ("C0", "C1", "C2"),
    ):
        for ld, ls in ((0.5, "-"), (1.3, ":")):
            for ctrl, m in mk.items():
                ss = sorted(
                    [
                        r
                        for r in ok
                        if r["kind"] == "grid"
                        and r["uuv.weight_in_water_kgf"] == w
                        and r["formation.l_d"] == ld
                        and r["control.uuv"] == ctrl
                    ],
                    key=lambda r: r["cable.top_x"],
                )
                if ss:
                    ax.plot(
                        [r["cable.top_x"] for r in ss],
                        [r["pitch_late_deg"] for r in ss],
                        ls,
                        marker=m,
                        color=col,
                        ms=4,
                        label=f"{w:g} kgf, l^d {ld:g}, {'PID' if ctrl == 'pid' else 'BS'}",
                    )
    pas = sorted([r for r in ok if r["kind"] == "passive"], key=lambda r: r["cable.top_x"])
    if pas:
        ax.plot([r["cable.top_x"] for r in pas], [r["pitch_late_deg"] for r in pas], "kx--", label="thrusters off")
    ax.axhspan(*PUBLISHED["field_pitch_deg"], color="C3", alpha=0.3, label="003 ch. 6.2: -2..-4 deg")
    ax.set_xlabel("cable attachment on the USV, x forward of CG [m]")
    ax.set_ylabel("UUV pitch, last 10 s [deg]")
    ax.set_ylim(-90, 90)
    ax.grid(alpha=0.3)
    ax.legend(fontsize=6, ncol=2)
    ax.set_title("(b) pitch: only the towed (thrusters off) UUV stays near 003's", fontsize=9)
    ax = axs[2]
    for w, col in zip(
        sorted({r.get("uuv.weight_in_water_kgf", 12.0) for r in ok if r["kind"] == "grid"}, reverse=True),
        ("C0", "C1", "C2"),
    ):
        for ld, ls in ((0.5, "-"), (1.3, ":")):
            xs, ds = [], []
            for x in sorted({r["cable.top_x"] for r in ok if r["kind"] == "grid"}):
                pair = {
                    r["control.uuv"]: r
                    for r in ok
                    if r["kind"] == "grid"
                    and r["cable.top_x"] == x
                    and r["uuv.weight_in_water_kgf"] == w
                    and r["formation.l_d"] == ld
                }
                if len(pair) == 2:
                    xs.append(x)
                    ds.append(pair["pid"]["rel_mean_m"] - pair["backstepping"]["rel_mean_m"])
            if xs:
                ax.plot(xs, ds, ls, marker="o", color=col, label=f"{w:g} kgf, l^d {ld:g}")
    ax.axhline(0, color="k", lw=0.8)
    ax.set_xlabel("cable attachment on the USV, x forward of CG [m]")
    ax.set_ylabel("mean distance PID - backstepping [m]")
    ax.grid(alpha=0.3)
    ax.legend(fontsize=7)
    ax.set_title("(c) > 0: backstepping nearer the USV (x > 0: pulled under the bow)", fontsize=9)
    fig.suptitle(
        "combined-survey sensitivity (003 ch. 4): attachment point, UUV submerged weight, formation "
        "offset l^d, controller and gains",
        fontsize=10,
    )
    fig.tight_layout()
    fig.savefig(path, dpi=80)
    plt.close(fig)
    return path


def read_rows(path: Path) -> list[dict]:
    """Rows of a ``flagship_sweep.csv`` with numbers as floats (to re-plot without re-running)."""
    import csv

    rows = []
    with open(path, newline="") as f:
        for r in csv.DictReader(f):
            row = {}
            for k, v in r.items():
                if v == "":
                    continue
                try:
                    row[k] = float(v)
                except ValueError:
                    row[k] = v
            rows.append(row)
    return rows


def main(argv=None) -> int:
    """``python -m oceangnc.validation.flagship OUT [--replot]``: run the sweep (or re-plot OUT's CSV)."""
    import csv

    args = list(argv if argv is not None else sys.argv[1:])
    replot = "--replot" in args
    args = [a for a in args if a != "--replot"]
    out = Path((args or ["flagship-sweep"])[0])
    out.mkdir(parents=True, exist_ok=True)
    if replot:
        print(plot_sweep(read_rows(out / "flagship_sweep.csv"), out / "flagship_sweep.png"))
        return 0
    rows = sweep()
    keys = sorted({k for r in rows for k in r})
    with open(out / "flagship_sweep.csv", "w", newline="") as f:
        w = csv.DictWriter(f, fieldnames=keys)
        w.writeheader()
        w.writerows(rows)
    print(plot_sweep(rows, out / "flagship_sweep.png"))
    return 0


if __name__ == "__main__":
    sys.exit(main())
