"""The USV's wave-frequency motions in regular waves against the RAO of the same coefficients.

Simulates the combined plant (the USV lying still, a short cable) in one regular wave at a time, at
the frequencies of the committed coefficient file of 003's USV and two headings, measures the heave,
roll and pitch amplitudes (least-squares sinusoid over the last 20 s of 70 s) and draws them over the
frequency-domain RAO curves (docs/img/usv-rao-check.png; docs/sea-state.md).

    python examples/sea_usv_rao.py [--img docs/img]
"""

from __future__ import annotations

import argparse
import math
from pathlib import Path

import numpy as np

from oceangnc.environment import USVMotionsConfig
from oceangnc.environment.waves import WaveField
from oceangnc.hydro.coefficients import default_usv_coefficients
from oceangnc.io.plots import figure, save
from oceangnc.models._combined_layout import H_SEA
from oceangnc.models._sea_layout import S_WF, W_XO
from oceangnc.models._usv_waves import manoeuvring_damping
from oceangnc.models.cable import CableConfig
from oceangnc.models.combined import CombinedPlant
from oceangnc.models.usv import USVConfig
from oceangnc.models.uuv import UUVConfig


def amplitudes(omega: float, mu: float, a: float = 0.05, duration: float = 70.0, window: float = 20.0):
    """Simulated (heave m, roll rad, pitch rad) amplitudes in a regular wave (a, omega, heading mu)."""
    sea = WaveField(np.array([a]), np.array([omega]), np.array([mu]), np.array([0.0]), depth=1000.0)
    cc = CableConfig(length=4.0, segments=2, integrator="imex")
    pl = CombinedPlant(
        USVConfig(), UUVConfig(x0=0.0, z0=4.1), cc, top="usv", waves=sea, usv_motions=USVMotionsConfig(enabled=True)
    )
    o = int(pl.p[int(pl.p[int(pl.p[H_SEA]) + S_WF]) + W_XO])
    t, ts, xs = 0.0, [], []
    while t < duration - 1e-9:
        t = pl.advance(t, 0.01, 5)
        if t >= duration - window:
            ts.append(t)
            xs.append(pl.x[o + 2 : o + 5].copy())
    ts = np.array(ts)
    A = np.stack([np.cos(omega * ts), np.sin(omega * ts), np.ones_like(ts)], axis=1)
    c = np.linalg.lstsq(A, np.array(xs), rcond=None)[0]
    return np.hypot(c[0], c[1]) / a


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--img", default="img", help="folder of usv-rao-check.png")
    args = ap.parse_args()
    c = default_usv_coefficients()
    Bx, Cx = c.time_domain_extras(c.hull["roll_damping_ratio"])
    u = USVConfig()
    Bx = Bx + manoeuvring_damping(u.d11, u.d22, u.d33)  # the plant's default (usv_motions.manoeuvring_damping)
    raos = np.abs(c.raos(Bx, Cx))
    T = 2 * math.pi / c.omega
    heads = (2, 5)  # 60 and 150 deg: every one of heave, roll and pitch responds
    picks = [i for i in range(2, c.omega.size, 3) if T[i] < 12]
    fig = figure((12, 3.8), margins=(0.7, 0.55, 0.2, 0.35))
    axs = fig.subplots(1, 3)
    worst = 0.0
    for j, col in zip(heads, ("C0", "C3")):
        sim = np.array([amplitudes(c.omega[i], c.headings[j]) for i in picks])
        for k, ax in enumerate(axs):
            s = 1.0 if k == 0 else 180.0 / math.pi
            ax.plot(T, raos[:, j, 2 + k] * s, color=col, lw=1, label=f"RAO, {math.degrees(c.headings[j]):.0f} deg")
            ax.plot(T[picks], sim[:, k] * s, "o", color=col, mfc="none", label="simulated (Cummins)")
            worst = max(worst, float(np.max(np.abs(sim[:, k] / raos[picks, j, 2 + k] - 1.0))))
    for ax, name in zip(axs, ("heave (m/m)", "roll (deg/m)", "pitch (deg/m)")):
        ax.set_title(name, fontsize=9)
        ax.set_xlabel("wave period (s)")
        ax.set_xlim(0, 12)
        ax.legend(fontsize=7)
    out = Path(args.img)
    out.mkdir(parents=True, exist_ok=True)
    save(fig, out / "usv-rao-check.png")
    print(f"{len(picks) * len(heads)} regular waves: largest |simulated / RAO - 1| {100 * worst:.2f} %")
    print(f"wrote {out / 'usv-rao-check.png'}")


if __name__ == "__main__":
    main()
