"""Combined USV-cable-UUV survey (003 ch. 4, figs 4-7 to 4-15): PID vs backstepping for the UUV.

Runs the flagship scenario twice, prints the comparison table of docs/combined-vehicle.md and draws
the comparison figure (relative distance, UUV heading, UUV depth):

    python examples/combined_survey.py [out_dir]

The same from the shell: ``oceangnc run combined-survey --set control.uuv=pid``.
"""

import math
import sys
from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402

import oceangnc  # noqa: E402

out = Path(sys.argv[1] if len(sys.argv) > 1 else "runs/combined_survey_example")
keys = ["usv.waypoints_reached", "usv.cross_track_rms_m", "uuv.rel_distance_mean_m", "uuv.rel_distance_max_m",
        "uuv.depth_final_m", "uuv.heading_error_rms_deg", "usv.heading_error_rms_deg"]
res = {}
for ctrl in ("pid", "backstepping"):
    res[ctrl] = oceangnc.run("combined-survey", overrides={"control.uuv": ctrl}, out=out / ctrl)

print("| metric | PID | backstepping |")
print("|---|---|---|")
for k in keys:
    a, b = res["pid"].summary[k], res["backstepping"].summary[k]
    print(f"| `{k}` | {a:.3g} | {b:.3g} |")

fig, axes = plt.subplots(3, 1, figsize=(8, 7.5), sharex=True)
for ctrl, style in (("pid", "C1"), ("backstepping", "C0")):
    df = res[ctrl].df
    d = np.hypot(df["usv.x"] - df["uuv.x"], df["usv.y"] - df["uuv.y"])
    axes[0].plot(df["t"], d, style, label=ctrl)
    axes[1].plot(df["t"], np.degrees(np.unwrap(df["uuv.psi"])), style, label=f"UUV heading ({ctrl})")
    axes[2].plot(df["t"], df["uuv.z"], style, label=ctrl)
df = res["backstepping"].df
axes[1].plot(df["t"], np.degrees(np.unwrap(df["usv.psi"])), "k--", lw=0.8, label="USV heading")
axes[0].set_ylabel("rel. distance [m]")
axes[1].set_ylabel("heading [deg]")
axes[2].set_ylabel("UUV depth [m]")
axes[2].invert_yaxis()
axes[2].set_xlabel("time t [s]")
for ax in axes:
    ax.grid(True, alpha=0.3)
    ax.legend(fontsize=7)
axes[0].set_title("combined-survey: PID vs backstepping (cf. 003 figs 4-13 to 4-15)")
fig.tight_layout()
fig.savefig(out / "pid_vs_backstepping.png", dpi=100)
print("figures in", out)
