"""Speed of the tow at sea (issue 29): ``tow-sea-state`` and the cost of the waves.

Prints, on one core (NUMBA_NUM_THREADS=1):

1. ``tow-sea-state`` end to end (Hs 1 m, Tp 6 s, 128 components, 20-segment cable, imex at 10 ms,
   fused loop, Parquet log at 10 Hz, no plots), 1200 s simulated, after a short warm-up run that
   compiles: real-time factor (target >= 300x), with the USV's wave-frequency motions (the scenario's
   default, issue 29 part B) and without them (``environment.usv_motions.enabled = false``);
2. the plant alone (advanced tick by tick, 10 ms, published every tick, as the simulator does) towed at
   1 m/s in the same sea against the number of wave components (0 = calm, 32, 128, 512) and of
   segments (10, 20, 40): real-time factor, and the cost of one update of the expansions; and at 128
   components with the USV's wave-frequency motions (Cummins' equation, 6 x 12 radiation states).

3. with ``--sweep``: the operability sweep of 64 sea states (Hs 0.5-2 m x Tp 4-10 s x 4 headings,
   20-min records) on a local Dask cluster of two workers (both cores), report and diagram included:
   wall time (the issue's target: >= 60 sea states in under 10 minutes on 2 cores).

    NUMBA_NUM_THREADS=1 python benchmarks/bench_sea.py
    python benchmarks/bench_sea.py --sweep
"""

from __future__ import annotations

import os
import tempfile
import time

import numpy as np

from oceangnc.environment import USVMotionsConfig
from oceangnc.environment.waves import WaveConfig, WaveField
from oceangnc.models._combined_sea import sea_update
from oceangnc.models.cable import CableConfig
from oceangnc.models.combined import CombinedPlant
from oceangnc.models.usv import USVConfig
from oceangnc.models.uuv import UUVConfig

from record import record

CAP = "sea state: waves on the tow"


def towed(components: int, segments: int, motions: bool = False) -> CombinedPlant:
    sea = None
    if components:
        sea = WaveField.from_config(
            WaveConfig(kind="jonswap", hs=1.0, tp=6.0, components=components), np.random.default_rng(0)
        )
    cc = CableConfig(length=20.0, segments=segments, integrator="imex")
    heave = "surface" if sea and not motions else "none"
    mot = USVMotionsConfig(enabled=True) if motions else None
    pl = CombinedPlant(
        USVConfig(u0=1.0), UUVConfig(u0=0.8, z0=15.0, x0=-12.0), cc, top="usv", waves=sea, heave=heave, usv_motions=mot
    )
    pl.u[0] = pl.u[1] = 0.5 * USVConfig().d11 * 1.0  # USV thrust for ~1 m/s
    return pl


def rtf(pl: CombinedPlant, t_sim: float = 120.0, tick: float = 0.01) -> float:
    bus: dict = {}
    pl.advance(0.0, tick, 1)
    pl.publish(bus)
    pl.reset()
    t = 0.0
    w0 = time.perf_counter()
    for _ in range(int(round(t_sim / tick))):
        t = pl.advance(t, tick, 1)
        pl.publish(bus)
    return t_sim / (time.perf_counter() - w0)


def update_cost(pl: CombinedPlant, n: int = 2000) -> float:
    """Mean wall time (us) of one refresh of the expansions (all points)."""
    sea_update(0.0, pl.x, pl.p, 0.01)
    w0 = time.perf_counter()
    for k in range(n):
        sea_update(1.0 + k, pl.x, pl.p, 0.01)  # a new interval each call
    return (time.perf_counter() - w0) / n * 1e6


def sweep() -> None:
    from oceangnc.sweep import make_report
    from oceangnc.cli import main as cli

    print(f"load average: {os.getloadavg()}")
    with tempfile.TemporaryDirectory() as d:
        args = ["sweep", "tow-sea-state", "--grid", "environment.waves.hs=0.5,1,1.5,2"]
        args += ["--grid", "environment.waves.tp=5,6,8,10", "--grid", "environment.waves.direction_deg=0,90,135,180"]
        w0 = time.perf_counter()
        assert cli([*args, "--workers", "2", "--quiet", "--no-keep", "--out", f"{d}/ops"]) == 0
        rep = make_report(f"{d}/ops")
        wall = time.perf_counter() - w0
        n = len(rep.points)
    record(CAP, f"operability sweep of {n} sea states (20-min records), 2 local Dask workers, with the report",
           wall, "s", "< 600 s")  # fmt: skip
    print(f"{n} sea states: {wall:.0f} s wall on two workers, report and diagram included")


def main() -> None:
    import sys

    if "--sweep" in sys.argv:
        sweep()
        return
    import oceangnc

    print(f"load average: {os.getloadavg()}")
    for motions in (True, False):
        over = {"environment.usv_motions.enabled": motions}
        with tempfile.TemporaryDirectory() as d:
            oceangnc.run("tow-sea-state", duration=5.0, out=f"{d}/warm", plots=False, overrides=over)
            w0 = time.perf_counter()
            r = oceangnc.run("tow-sea-state", out=f"{d}/run", plots=False, overrides=over)
            wall = time.perf_counter() - w0
        T = r.summary["duration_s"]
        lab = "with the USV's wave-frequency motions" if motions else "USV as in calm water, heaving tow point"
        record(CAP, f"`tow-sea-state` end to end (Hs 1 m, 128 components, {T:.0f} s simulated), {lab}", T / wall, "x",
               ">= 300x")  # fmt: skip
        print(f"tow-sea-state {T:.0f} s simulated, {lab}: {wall:.2f} s wall, RTF {T / wall:.0f}x")
    for comps in (0, 32, 128, 512):
        pl = towed(comps, 20)
        r = rtf(pl)
        us = update_cost(pl) if comps else 0.0
        lab = "calm water" if comps == 0 else f"{comps} components"
        record(CAP, f"plant alone, 20 segments, {lab}, 10 ms ticks + publish", r, "x", "", f"update {us:.0f} us")
        print(f"20 segments, {lab:15s}: RTF {r:6.0f}x, one update of the expansions {us:7.1f} us")
    pl = towed(128, 20, motions=True)
    r = rtf(pl)
    us = update_cost(pl)
    record(CAP, "plant alone, 20 segments, 128 components, USV motions, 10 ms ticks + publish", r, "x", "",
           f"update {us:.0f} us")  # fmt: skip
    print(f"20 segments, 128 components + USV motions: RTF {r:6.0f}x, one update {us:7.1f} us")
    for segs in (10, 40):
        pl = towed(128, segs)
        r = rtf(pl)
        us = update_cost(pl)
        case = f"plant alone, {segs} segments, 128 components, 10 ms ticks + publish"
        record(CAP, case, r, "x", "", f"update {us:.0f} us")
        print(f"{segs} segments, 128 components: RTF {r:6.0f}x, one update {us:7.1f} us")


if __name__ == "__main__":
    main()
