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
    "cable.top_x": [-0.75, 0.0, 0.75],
    "uuv.weight_in_water_kgf": [12.0, 4.0, 1.0],
    "control.uuv": ["pid", "backstepping"],
}


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
        "rel_mean_m": summary["uuv.rel_distance_mean_m"], "rel_max_m": summary["uuv.rel_distance_max_m"],
        "rel_growth_25_30_m": float(rd[turn].max() - rd[turn].min()) if turn.any() else float("nan"),
        "depth_final_m": summary["uuv.depth_final_m"], "depth_start_m": float(df["uuv.z"].iloc[0]),
        "pitch_late_deg": float(np.degrees(df["uuv.theta"].to_numpy()[late].mean())),
        "heading_err_rms_deg": summary["uuv.heading_error_rms_deg"], "t_end_s": summary["t_end_s"],
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


def sweep(grid: dict | None = None, progress: bool = True) -> list[dict]:
    """Full factorial over ``grid`` (dotted keys -> values); one row per run."""
    import itertools

    grid = grid or GRID
    keys = list(grid)
    rows = []
    combos = list(itertools.product(*grid.values()))
    for i, vals in enumerate(combos):
        over = dict(zip(keys, vals))
        try:
            rows.append(run_point(over))
        except Exception as e:  # a diverged point is a result too
            rows.append({**over, "error": f"{type(e).__name__}: {e}"})
        if progress:
            print(f"[{i + 1}/{len(combos)}] {over} -> "
                  f"{ {k: round(v, 3) for k, v in rows[-1].items() if isinstance(v, float) and k not in over} }",
                  file=sys.stderr, flush=True)
    return rows


def plot_sweep(rows: list[dict], path: Path) -> Path:
    """Three panels against the attachment point, one line per (weight, controller): mean relative
    distance, final depth, late pitch; the published values as bands."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, axs = plt.subplots(1, 3, figsize=(13, 4.2))
    weights = sorted({r["uuv.weight_in_water_kgf"] for r in rows}, reverse=True)
    colors = dict(zip(weights, ["C0", "C1", "C2", "C3", "C4"]))
    for w in weights:
        for ctrl, ls in (("pid", "--"), ("backstepping", "-")):
            sel = sorted([r for r in rows if r["uuv.weight_in_water_kgf"] == w and r["control.uuv"] == ctrl
                          and "error" not in r], key=lambda r: r["cable.top_x"])
            if not sel:
                continue
            x = [r["cable.top_x"] for r in sel]
            lab = f"{w:g} kgf, {'BS' if ctrl == 'backstepping' else 'PID'}"
            axs[0].plot(x, [r["rel_mean_m"] for r in sel], ls, marker="o", color=colors[w], label=lab)
            axs[1].plot(x, [r["depth_final_m"] for r in sel], ls, marker="o", color=colors[w], label=lab)
            axs[2].plot(x, [r["pitch_late_deg"] for r in sel], ls, marker="o", color=colors[w], label=lab)
    axs[0].axhline(PUBLISHED["rel_distance_bs_m"], color="k", lw=3, alpha=0.3, label="003 ch. 4: BS ≈ 0.4 m")
    axs[1].axhspan(2.75, 2.8, color="k", alpha=0.2, label="003 ch. 4 / 6.2: 2.75-2.8 m")
    axs[2].axhspan(*PUBLISHED["field_pitch_deg"], color="k", alpha=0.2, label="003 ch. 6.2: -2..-4 deg")
    for ax, yl in zip(axs, ("mean USV-UUV distance [m]", "final UUV depth [m]", "UUV pitch, last 10 s [deg]")):
        ax.set_xlabel("cable attachment on the USV, x forward of CG [m]")
        ax.set_ylabel(yl)
        ax.grid(alpha=0.3)
    axs[1].invert_yaxis()
    axs[0].legend(fontsize=7)
    axs[2].legend(fontsize=7)
    fig.suptitle("combined-survey sensitivity: attachment point x submerged weight x controller (dashed PID, "
                 "solid backstepping)", fontsize=10)
    fig.tight_layout()
    fig.savefig(path, dpi=90)
    plt.close(fig)
    return path


def main(argv=None) -> int:
    import csv

    out = Path((argv or sys.argv[1:] or ["flagship-sweep"])[0])
    out.mkdir(parents=True, exist_ok=True)
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
