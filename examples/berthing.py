"""Joystick berthing (document 001): the five-trial channel comparison and a berth approach.

Runs ``berthing-channel`` with the open-loop, PID and nonlinear joystick controllers (``--runs``
trials each, 001: 5), optionally in a steady current and wind, prints the comparison table and draws
bar charts like 001 figs 8-10 and the tracks; then berths the ship with each controller.

    python examples/berthing.py                 # calm water, 5 runs, writes docs/img/berthing_*.png
    python examples/berthing.py --disturbed     # 0.2 m/s cross current and 10 m/s beam wind
    python examples/berthing.py --gusty         # 0.2 m/s cross current, 15 m/s gusty wind from 045 deg
    python examples/berthing.py --runs 2 --seed 1 --out /tmp/berthing
"""

from __future__ import annotations

import argparse
import json
import math
from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402

import oceangnc  # noqa: E402

MODES = ("open", "pid", "nonlinear")
DISTURBANCE = {"environment.current.speed": 0.2, "environment.current.direction_deg": 270.0,
               "environment.wind.speed": 10.0, "environment.wind.direction_deg": 90.0}
#: gusty wind on the starboard bow (a yaw moment, unlike a beam wind), and the same cross current
GUSTY = {"environment.current.speed": 0.2, "environment.current.direction_deg": 270.0,
         "environment.wind.speed": 15.0, "environment.wind.direction_deg": 45.0,
         "environment.wind.gust_sigma": 4.0, "environment.wind.gust_time_constant": 10.0}


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--runs", type=int, default=5)
    ap.add_argument("--disturbed", action="store_true", help="steady cross current and beam wind")
    ap.add_argument("--gusty", action="store_true", help="cross current and gusty wind on the bow")
    ap.add_argument("--seed", type=int, default=0, help="sim.seed (the runs' random streams)")
    ap.add_argument("--modes", default=",".join(MODES))
    ap.add_argument("--out", default="runs/berthing-example")
    ap.add_argument("--img", default="docs/img", help="folder for the PNG figures")
    ap.add_argument("--no-dock", action="store_true")
    ap.add_argument("--dock-only", action="store_true")
    a = ap.parse_args()
    tag = "gusty" if a.gusty else "disturbed" if a.disturbed else "calm"
    env = GUSTY if a.gusty else DISTURBANCE if a.disturbed else {}
    out = Path(a.out) / tag
    img = Path(a.img)
    img.mkdir(parents=True, exist_ok=True)
    modes = a.modes.split(",")
    if a.dock_only:
        return dock(a, modes, out, img, tag, env)
    res = {}
    for m in modes:
        over = {"control.mode": m, "runs": a.runs, "sim.seed": a.seed, **env}
        r = oceangnc.run("berthing-channel", overrides=over, out=out / m, plots=True)
        res[m] = r
        print(m, json.dumps({k: round(v, 4) for k, v in r.summary.items() if isinstance(v, float)}))
    keys = [("error_index", "error index (44) [m^2]", 1.0), ("rudder_index_deg", "rudder index [deg]", 1.0),
            ("bow_thruster_index_rpm", "bow thruster index [rpm]", 1.0),
            ("propeller_index_rpm", "propeller index [rpm]", 1.0)]
    print(f"\n| controller ({tag}, {a.runs} runs) | " + " | ".join(k[1] for k in keys)
          + " | min margin [m] | mean speed [kn] |")
    print("|---" * (len(keys) + 3) + "|")
    for m in modes:
        s = res[m].summary
        print(f"| {m} | " + " | ".join(f"{s[k]:.4g}" for k, _, _ in keys)
              + f" | {s['min_channel_margin_m']:.1f} | {s['mean_speed_kn']:.2f} |")
    paired = "pid" in res and "nonlinear" in res
    fig, axes = plt.subplots(1, 4 if paired else 3, figsize=(13 if paired else 10, 3.2))
    colors = {"open": "tab:red", "pid": "tab:blue", "nonlinear": "tab:green"}
    if paired:  # the runs share their seeds: the per-run difference removes the pilot's scatter
        d = np.array(res["nonlinear"].summary["error_index_runs"]) - np.array(res["pid"].summary["error_index_runs"])
        ax = axes[3]
        ax.axhline(0.0, color="k", lw=0.8)
        ax.plot(np.arange(1, d.size + 1), d, "o", color="tab:green")
        ax.set_xticks(np.arange(1, d.size + 1))
        ax.set_xlabel("run (same seed for both)", fontsize=8)
        ax.set_title("error index: nonlinear - PID [m^2]", fontsize=9)
        ax.grid(True, alpha=0.3)
        print(f"nonlinear - PID error index per run: {np.round(d).tolist()} m^2")
    for ax, (k, lab, _) in zip(axes, keys[:3]):
        vals = [res[m].summary[k] for m in modes]
        ax.bar(modes, vals, color=[colors.get(m, "gray") for m in modes])
        if k == "error_index":
            for i, m in enumerate(modes):
                runs = res[m].summary.get("error_index_runs") or []
                ax.plot([i] * len(runs), runs, "k.", ms=4)
        ax.set_title(lab, fontsize=9)
        ax.grid(True, axis="y", alpha=0.3)
    fig.suptitle(f"berthing-channel, {tag}: mean of {a.runs} runs (cf. 001 figs 8-10)", fontsize=10)
    fig.tight_layout()
    if a.seed == 0:
        fig.savefig(img / f"berthing_bars_{tag}.png", dpi=100)
    plt.close(fig)
    # tracks of every run, all controllers
    from oceangnc.api import resolve_config

    sc, cfg = resolve_config("berthing-channel")
    g = sc.geometry(cfg)
    fig, axes = plt.subplots(1, len(modes), figsize=(3.3 * len(modes), 5.2), sharey=True)
    for ax, m in zip(np.atleast_1d(axes), modes):
        for bank in g["banks"]:
            b = np.array(bank)
            ax.plot(b[:, 1], b[:, 0], color="saddlebrown", lw=1.5)
        rt = np.array(g["route"])
        ax.plot(rt[:, 1], rt[:, 0], "k--", lw=0.7)
        df = res[m].df
        for run, d in df.groupby("run"):
            ax.plot(d["ship.y"], d["ship.x"], lw=0.9)
        ax.set_title(m, fontsize=9)
        ax.set_aspect("equal")
        ax.set_xlabel("east [m]")
        ax.grid(True, alpha=0.3)
    np.atleast_1d(axes)[0].set_ylabel("north [m]")
    fig.suptitle(f"tracks in the Z channel ({tag}, {a.runs} runs each)", fontsize=10)
    fig.tight_layout()
    if a.seed == 0:
        fig.savefig(img / f"berthing_tracks_{tag}.png", dpi=100)
    plt.close(fig)
    if not a.no_dock:
        dock(a, modes, out, img, tag, env)


def dock(a, modes, out, img, tag, env) -> None:
    """Berth with every controller; table and a figure (whole approach and a zoom on the berth)."""
    from oceangnc.api import resolve_config

    colors = {"open": "tab:red", "pid": "tab:blue", "nonlinear": "tab:green"}
    print("\n| controller | final distance [m] | final speed [m/s] | heading error [deg] | time [s] |")
    print("|---|---|---|---|---|")
    dock_runs = {}
    for m in modes:
        r = oceangnc.run("berthing-dock", overrides={"control.mode": m, **env},
                         out=out / f"dock-{m}", plots=True)
        s = r.summary
        dock_runs[m] = r
        print(f"| {m} | {s['final_distance_m']:.2f} | {s['final_speed_mps']:.3f} | "
              f"{s['final_heading_error_deg']:.2f} | {s['time_to_berth_s']:.0f} |")
    sc, cfg = resolve_config("berthing-dock")
    g = sc.geometry(cfg)
    fig, axes = plt.subplots(1, 2, figsize=(9, 5.5), gridspec_kw={"width_ratios": [1, 1.6]})
    for k, ax in enumerate(axes):
        q = np.array(g["quay"])
        ax.plot(q[:, 1], q[:, 0], color="saddlebrown", lw=3, label="quay")
        rt = np.array(g["route"])
        ax.plot(rt[:, 1], rt[:, 0], "k--", lw=0.7, label="route")
        for m, r in dock_runs.items():
            d = r.df
            ax.plot(d["ship.y"], d["ship.x"], lw=1, label=m, color=colors.get(m))
            if k == 1:
                last = d.iloc[-1]
                L, B = cfg.ship.length, cfg.ship.beam
                c, s_ = math.cos(last["ship.psi"]), math.sin(last["ship.psi"])
                hull = np.array([[L / 2, 0], [L / 2 - 15, B / 2], [-L / 2, B / 2], [-L / 2, -B / 2],
                                 [L / 2 - 15, -B / 2], [L / 2, 0]])
                ax.plot(last["ship.y"] + hull[:, 0] * s_ + hull[:, 1] * c,
                        last["ship.x"] + hull[:, 0] * c - hull[:, 1] * s_, color=colors.get(m), lw=0.8)
        ax.plot(0, 0, "kx", ms=8, label="berth")
        ax.grid(True, alpha=0.3)
        ax.set_xlabel("east [m]")
    axes[0].set_ylabel("north [m]")
    axes[0].set_title("approach", fontsize=9)
    axes[1].set_xlim(-60, 40)
    axes[1].set_ylim(-160, 130)
    axes[1].set_aspect("equal")
    axes[1].set_title("at the berth (final hull outlines)", fontsize=9)
    axes[1].legend(fontsize=7, loc="lower left")
    fig.suptitle(f"berthing-dock ({tag})", fontsize=10)
    fig.tight_layout()
    fig.savefig(img / f"berthing_dock_{tag}.png", dpi=100)
    plt.close(fig)


if __name__ == "__main__":
    main()
