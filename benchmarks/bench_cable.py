"""Speed of the coupled USV + cable + UUV plant (issue 4).

Prints, on one core (set NUMBA_NUM_THREADS=1):

1. the real-time factor of the coupled USV + 20-segment cable (3 m, table 2-6) + UUV plant at its
   automatic physics step (90 % of the RK4 axial stability limit, dividing the 10 ms control period;
   ``--figure PATH`` instead draws the error-vs-step figure of the three integrators,
   docs/img/cable-error-vs-step.png),
   integrated tick by tick (10 ms, one compiled call per tick) and published to the bus every tick,
   as the simulator does;
2. for 10, 20, 40 and 80 segments: the stability limit, the chosen step, the cost of one RK4 step
   (must grow linearly with the number of segments) and the real-time factor at that step;
3. the wall time of the two scenarios (with their Python control blocks and Parquet logging).

Both wall-clock and CPU (process) time are reported: the sandbox is shared, so wall time depends on
the load (printed).

    NUMBA_NUM_THREADS=1 python benchmarks/bench_cable.py
"""

from __future__ import annotations

import math
import os
import sys
import time

import numpy as np

from oceangnc.models.cable import CableConfig, stable_step
from oceangnc.models.combined import CombinedPlant
from oceangnc.models.usv import USVConfig
from oceangnc.models.uuv import UUVConfig

from record import record


def make_plant(n: int, length: float = 3.0, integrator: str = "rk4") -> CombinedPlant:
    pl = CombinedPlant(
        USVConfig(u0=0.5), UUVConfig(u0=0.5), CableConfig(segments=n, length=length, integrator=integrator), top="usv"
    )
    pl.u[0] = pl.u[1] = 0.5 * 735.5 * 0.5  # USV thrust for 0.5 m/s
    pl.u[2] = 0.2  # some current, so drag is active everywhere
    pl.u[6] = pl.u[7] = 2.0
    return pl


def run_ticks(pl: CombinedPlant, dt: float, t_sim: float, tick: float = 0.01):
    """Integrate ``t_sim`` s in ticks of ``tick`` s with a publish per tick; returns (wall, cpu) s."""
    n_tick = int(round(tick / dt))
    bus: dict = {}
    pl.advance(0.0, dt, n_tick)  # compile / warm up
    pl.publish(bus)
    pl.reset()
    t = 0.0
    w0, c0 = time.perf_counter(), time.process_time()
    for _ in range(int(round(t_sim / tick))):
        t = pl.advance(t, dt, n_tick)
        pl.publish(bus)
    return time.perf_counter() - w0, time.process_time() - c0


def step_cost(pl: CombinedPlant, dt: float, n_steps: int = 20000):
    """(wall, cpu) microseconds per RK4 step, no publishing."""
    pl.advance(0.0, dt, 10)
    w0, c0 = time.perf_counter(), time.process_time()
    pl.advance(0.0, dt, n_steps)
    return (time.perf_counter() - w0) / n_steps * 1e6, (time.process_time() - c0) / n_steps * 1e6


def accuracy(integrator: str, dt: float, t_sim: float = 20.0) -> np.ndarray:
    """UUV depth and top tension every 0.1 s during the onset of a 0.5 m/s current (top fixed)."""
    pl = CombinedPlant(USVConfig(), UUVConfig(psi0_deg=180.0, z0=3.25), CableConfig(integrator=integrator), top="fixed")
    pl.u[2] = 0.5
    out = []
    t = 0.0
    bus: dict = {}
    for _ in range(int(round(t_sim / 0.1))):
        t = pl.advance(t, dt, int(round(0.1 / dt)))
        pl.publish(bus)
        out.append((bus["uuv.z"], bus["cable.top_tension"], bus["cable.angle_deg"]))
    return np.array(out)


def error_vs_step(out_png: str | None = None, t_sim: float = 20.0) -> dict:
    """Error against step for each integrator: max |error| of the UUV depth and the top tension every 0.1 s
    over the onset of a 0.5 m/s current (top fixed, 20 segments), against RK4 at 1/16 of its limit.

    Returns {integrator: [(dt, depth error m, tension error N), ...]}; plots log-log if ``out_png``.
    """
    lim = {
        k: CombinedPlant(USVConfig(), UUVConfig(), CableConfig(integrator=k)).stability_limit
        for k in ("rk4", "rk4-split")
    }
    ref = accuracy("rk4", 0.1 / math.ceil(0.1 / (lim["rk4"] / 16)), t_sim)
    steps = {
        "rk4": [f * lim["rk4"] for f in (0.95, 0.5, 0.25, 0.125)],
        "rk4-split": [f * lim["rk4-split"] for f in (0.95, 0.5, 0.25, 0.125)],
        "imex": [0.05, 0.02, 0.01, 0.005, 0.002, 0.001, 0.0005],
    }
    res: dict = {}
    for integ, hs in steps.items():
        rows = []
        for h in hs:
            h = 0.1 / math.ceil(0.1 / h - 1e-9)  # divides the 0.1 s sampling period
            a = accuracy(integ, h, t_sim)
            err = np.max(np.abs(a - ref), axis=0)
            rows.append((h, float(err[0]), float(err[1])))
            print(f"   {integ:9s} dt {h * 1e3:8.4f} ms: depth {err[0]:.3e} m, top tension {err[1]:.3e} N")
        res[integ] = rows
    if out_png:
        import matplotlib

        matplotlib.use("Agg")
        import matplotlib.pyplot as plt

        fig, axs = plt.subplots(1, 2, figsize=(10, 4))
        for integ, rows in res.items():
            r = np.array(rows)
            axs[0].loglog(r[:, 0] * 1e3, r[:, 1], "o-", label=integ)
            axs[1].loglog(r[:, 0] * 1e3, r[:, 2], "o-", label=integ)
        for ax, lab in zip(axs, ("max |UUV depth error| [m]", "max |top tension error| [N]")):
            ax.set_xlabel("physics step [ms]")
            ax.set_ylabel(lab)
            ax.grid(True, which="both", alpha=0.3)
            ax.axvline(10.0, color="k", lw=0.8, ls=":")
            ax.legend()
        fig.suptitle("20-segment cable, onset of a 0.5 m/s current (20 s), error vs RK4 at limit/16")
        fig.tight_layout()
        fig.savefig(out_png, dpi=110)
        plt.close(fig)
    return res


def main() -> None:
    print(f"load average: {os.getloadavg()}")
    t_sim = 60.0
    for integ in ("rk4", "rk4-split"):
        pl = make_plant(20, integrator=integ)
        dt = stable_step(pl.stability_limit)
        wall, cpu = run_ticks(pl, dt, t_sim)
        print(
            f"\n1. coupled USV + 20-segment 3 m cable + UUV, integrator {integ}: limit "
            f"{pl.stability_limit * 1e3:.3f} ms, dt {dt * 1e3:.3f} ms"
        )
        record(
            "cable + UUV (003)",
            f"coupled USV + 20-segment cable + UUV, {integ}, 60 s, published every 10 ms",
            t_sim / wall,
            "x",
            ">= 200x" if integ == "rk4-split" else "",
            f"dt {dt * 1e3:.3f} ms",
        )
        print(
            f"   {t_sim:.0f} s simulated in {wall:.3f} s wall / {cpu:.3f} s CPU: "
            f"real-time factor {t_sim / wall:.0f}x (wall), {t_sim / cpu:.0f}x (CPU)"
        )

    for integ in ("rk4", "rk4-split"):
        print(f"\n2. scaling with the number of segments ({integ}, automatic step)")
        print("   n   limit[ms]  dt[ms]  us/step(cpu)  us/step/segment  RTF(wall)  RTF(cpu)")
        for n in (10, 20, 40, 80):
            pl = make_plant(n, integrator=integ)
            dt = stable_step(pl.stability_limit)
            _, c_us = step_cost(pl, dt)
            pl.reset()
            wall, cpu = run_ticks(pl, dt, 20.0)
            if integ == "rk4-split":
                record(
                    "cable + UUV (003)",
                    f"cost per RK4 step, {n} segments, {integ}",
                    c_us,
                    "us",
                    "linear in n",
                    f"{c_us / n:.2f} us per segment; real-time factor {20.0 / wall:.0f}x at dt {dt * 1e3:.2f} ms",
                )
            print(
                f"   {n:<3d} {pl.stability_limit * 1e3:9.3f} {dt * 1e3:7.3f} {c_us:13.2f} {c_us / n:16.3f}"
                f" {20.0 / wall:10.0f} {20.0 / cpu:9.0f}"
            )

    print("\n2b. implicit (imex) integrator, fixed top, UUV hanging in 0.5 m/s current: cost per simulated second")
    print("   n   dt[ms]  us/step(cpu)  RTF plant alone (cpu)  RTF ticks of 10 ms + publish (cpu)")
    for n in (10, 20, 40, 80):
        for dt in (0.01, 0.02):
            pl = CombinedPlant(
                USVConfig(), UUVConfig(psi0_deg=180.0, z0=3.25), CableConfig(segments=n, integrator="imex"), top="fixed"
            )
            pl.u[2] = 0.5
            _, c_us = step_cost(pl, dt, 5000)
            pl.reset()
            pl.advance(0.0, dt, 10)
            c0 = time.process_time()
            t = 0.0
            for _ in range(60):
                t = pl.advance(t, dt, int(round(1.0 / dt)))
            c1 = time.process_time() - c0
            line = f"   {n:<3d} {dt * 1e3:6.1f} {c_us:13.2f} {60.0 / c1:22.0f}"
            if dt == 0.01:
                record(
                    "cable + UUV (003)",
                    f"implicit (imex) cable, {n} segments, dt 10 ms, plant alone",
                    60.0 / c1,
                    "x CPU",
                    "",
                    "fixed top, UUV hanging in 0.5 m/s current",
                )
                pl.reset()
                _, cpu = run_ticks(pl, dt, 20.0)
                line += f" {20.0 / cpu:30.0f}"
            print(line)

    print("\n4. accuracy during the onset of a 0.5 m/s current (20 s), against RK4 at 1/8 of its step")
    ref = accuracy("rk4", stable_step(CombinedPlant(USVConfig(), UUVConfig(), CableConfig()).stability_limit) / 8)
    for integ in ("rk4", "rk4-split", "imex"):
        pl = CombinedPlant(USVConfig(), UUVConfig(), CableConfig(integrator=integ))
        dt = stable_step(pl.stability_limit)
        a = accuracy(integ, dt)
        err = np.max(np.abs(a - ref), axis=0)
        print(
            f"   {integ:9s} dt {dt * 1e3:.3f} ms: max error depth {err[0] * 1e3:.3f} mm, top tension "
            f"{err[1]:.3f} N (peak {ref[:, 1].max():.1f} N), angle {err[2]:.4f} deg"
        )

    print("\n3. scenarios (python blocks at 100 Hz, Parquet log at 10 Hz, no plots)")
    import tempfile

    import oceangnc

    with tempfile.TemporaryDirectory() as d:
        for name, over in (("cable-current", {}), ("tow-straight", {})):
            oceangnc.run(name, overrides=over, duration=2.0, out=f"{d}/warm-{name}", plots=False)
            w0, c0 = time.perf_counter(), time.process_time()
            r = oceangnc.run(name, overrides=over, out=f"{d}/{name}", plots=False)
            wall, cpu = time.perf_counter() - w0, time.process_time() - c0
            T = r.summary["duration_s"]
            print(
                f"   {name:14s} {T:5.0f} s simulated: {wall:6.2f} s wall, {cpu:6.2f} s CPU "
                f"(RTF {T / wall:.0f}x wall, {T / cpu:.0f}x CPU)"
            )


if __name__ == "__main__":
    if "--figure" in sys.argv:
        error_vs_step(sys.argv[sys.argv.index("--figure") + 1])
    else:
        main()
