"""The towed UUV and its cable (003 ch. 2.2-2.4 and ch. 4): equilibrium in current and the straight tow.

Runs

1. ``cable-current`` for currents 0 ... 1 m/s (top fixed, UUV hanging, thrusters off) and plots the
   settled top/bottom tension, the cable angle and the UUV's offset against the current
   (003 fig 2-10: the cable is pushed back, the tension grows);
2. ``tow-straight`` with the USV at 0.5 m/s and the UUV commanded 0.27 m/s and 0.48 m/s, and plots
   the UUV depth of both (003 figs 4-3 and 4-5: large vs small depth change).

    python examples/cable_and_uuv.py [out_dir]

Writes ``cable_vs_current.png`` and ``tow_depth.png`` (and each run's own plots) into ``out_dir``
(default ``runs/cable_example``).
"""

from __future__ import annotations

import sys
from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402

import oceangnc  # noqa: E402


def main(out: Path) -> None:
    out.mkdir(parents=True, exist_ok=True)
    currents = [0.0, 0.25, 0.5, 0.75, 1.0]
    rows = []
    for vc in currents:
        r = oceangnc.run("cable-current", overrides={"environment.current.speed": vc}, out=out / f"current-{vc}")
        s = r.summary
        rows.append(s)
        print(f"current {vc:4.2f} m/s: top {s['cable.top_tension_N']:6.1f} N, bottom {s['cable.bottom_tension_N']:6.1f} N,"
              f" angle {s['cable.angle_deg']:5.1f} deg, offset {s['uuv.offset_m']:.2f} m, depth {s['uuv.depth_m']:.2f} m,"
              f" pitch {s['uuv.pitch_deg']:6.1f} deg, settled {s['cable.settled']}")
    fig, ax = plt.subplots(1, 3, figsize=(11, 3.4))
    ax[0].plot(currents, [s["cable.top_tension_N"] for s in rows], "o-", label="top")
    ax[0].plot(currents, [s["cable.bottom_tension_N"] for s in rows], "s-", label="bottom (on UUV)")
    ax[0].plot(currents, [s["cable.top_tension_peak_N"] for s in rows], "^--", label="top, peak")
    ax[0].set_ylabel("tension [N]")
    ax[0].legend(fontsize=7)
    ax[1].plot(currents, [s["cable.angle_deg"] for s in rows], "o-")
    ax[1].set_ylabel("cable angle from vertical [deg]")
    ax[2].plot(currents, [s["uuv.offset_m"] for s in rows], "o-", label="offset")
    ax[2].plot(currents, [s["uuv.depth_m"] for s in rows], "s-", label="depth")
    ax[2].set_ylabel("UUV [m]")
    ax[2].legend(fontsize=7)
    for a in ax:
        a.set_xlabel("current [m/s]")
        a.grid(True, alpha=0.3)
    fig.suptitle("cable-current: settled equilibrium against current (003 fig 2-10)")
    fig.tight_layout()
    fig.savefig(out / "cable_vs_current.png", dpi=110)
    plt.close(fig)

    fig, ax = plt.subplots(2, 1, figsize=(7, 5), sharex=True)
    for vu in (0.27, 0.48):
        r = oceangnc.run("tow-straight", overrides={"command.uuv_speed": vu}, out=out / f"tow-{vu}")
        df = r.log.to_pandas()
        s = r.summary
        print(f"tow USV 0.5 m/s, UUV {vu} m/s: depth change max {s['uuv.depth_change_max_m']:.3f} m, final depth"
              f" {s['uuv.depth_final_m']:.2f} m, top tension max {s['cable.top_tension_max_N']:.1f} N")
        ax[0].plot(df["t"], df["uuv.z"], label=f"UUV command {vu} m/s")
        ax[1].plot(df["t"], df["uuv.u"], label=f"UUV u ({vu})")
    ax[1].plot(df["t"], df["usv.speed"], "k--", label="USV")
    ax[0].invert_yaxis()
    ax[0].set_ylabel("UUV depth [m]")
    ax[1].set_ylabel("speed [m/s]")
    ax[1].set_xlabel("time [s]")
    for a in ax:
        a.grid(True, alpha=0.3)
        a.legend(fontsize=7)
    ax[0].set_title("tow-straight: USV 0.5 m/s, UUV 0.27 vs 0.48 m/s (003 figs 4-3, 4-5)")
    fig.tight_layout()
    fig.savefig(out / "tow_depth.png", dpi=110)
    plt.close(fig)


if __name__ == "__main__":
    main(Path(sys.argv[1]) if len(sys.argv) > 1 else Path("runs/cable_example"))
