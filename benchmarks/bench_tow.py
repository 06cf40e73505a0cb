"""Speed of long towed cables and of the tow scenarios (issue 16).

Prints, on one core (set NUMBA_NUM_THREADS=1):

1. a 100 m cable of 50 segments (table 2-6 properties), towed by the USV at ~1 m/s with the UUV on it
   (thrusters at a cruise setting), implicit integrator at the 10 ms control period: real-time factor of
   the plant advanced tick by tick (one compiled call per 10 ms tick, published to the bus every tick, as
   the simulator does) and of the plant alone (1 s per call);
2. the same with the winch on (paying out at 0.2 m/s: node insertions every 10 s) and a 20-m-deep seabed;
3. wall time of ``tow-deploy`` and of ``tow-survey-depth`` (Python control blocks at 100 Hz, Parquet log,
   no plots).

    NUMBA_NUM_THREADS=1 python benchmarks/bench_tow.py
"""

from __future__ import annotations

import os
import time

from oceangnc.environment import SeabedConfig
from oceangnc.models.cable import CableConfig
from oceangnc.models.combined import CombinedPlant
from oceangnc.models.usv import USVConfig
from oceangnc.models.uuv import UUVConfig
from oceangnc.models.winch import WinchConfig

from record import record


def towed(winch: bool = False) -> CombinedPlant:
    cc = CableConfig(
        length=100.0, segments=None if winch else 50, segment_length=2.0 if winch else None, integrator="imex"
    )
    kw = {"winch": WinchConfig(enabled=True, capacity=150.0), "seabed": SeabedConfig(depth=200.0)} if winch else {}
    pl = CombinedPlant(USVConfig(u0=1.0), UUVConfig(u0=0.8, z0=60.0, x0=-80.0), cc, top="usv", **kw)
    pl.u[0] = pl.u[1] = 0.5 * USVConfig().d11 * 1.0  # USV thrust for ~1 m/s
    pl.u[6] = pl.u[7] = 20.0
    if winch:
        pl.u[9] = 0.2
    return pl


def rtf(pl: CombinedPlant, t_sim: float = 60.0, tick: float = 0.01, dt: float = 0.01, publish: bool = True):
    bus: dict = {}
    pl.advance(0.0, dt, 10)
    pl.publish(bus)
    pl.reset()
    k = int(round(tick / dt))
    t = 0.0
    w0, c0 = time.perf_counter(), time.process_time()
    for _ in range(int(round(t_sim / tick))):
        t = pl.advance(t, dt, k)
        if publish:
            pl.publish(bus)
    w, c = time.perf_counter() - w0, time.process_time() - c0
    pl.publish(bus)
    return t_sim / w, t_sim / c, bus


def main() -> None:
    print(f"load average: {os.getloadavg()}")
    for winch in (False, True):
        lab = "winch paying out 0.2 m/s + seabed" if winch else "fixed length"
        pl = towed(winch)
        rw, rc, _ = rtf(pl)
        pl = towed(winch)
        rw1, rc1, bus = rtf(pl, tick=1.0, publish=False)
        extra = f", nodes {bus.get('cable.nodes', 51):.0f}" if winch else ""
        record(
            "tow: cable, winch, seabed",
            f"100 m / 50-segment cable, imex 10 ms, {lab}, ticks + publish",
            rw,
            "x",
            "",
            f"plant alone {rw1:.0f}x wall",
        )
        print(
            f"100 m / 50-segment towed cable, imex 10 ms, {lab}: ticks of 10 ms + publish: RTF {rw:.0f}x wall, "
            f"{rc:.0f}x CPU; plant alone: {rw1:.0f}x wall, {rc1:.0f}x CPU{extra}"
        )
    import tempfile

    import oceangnc

    with tempfile.TemporaryDirectory() as d:
        for name in ("tow-deploy", "tow-survey-depth"):
            oceangnc.run(name, duration=2.0, out=f"{d}/warm-{name}", plots=False)
            w0, c0 = time.perf_counter(), time.process_time()
            r = oceangnc.run(name, out=f"{d}/{name}", plots=False)
            wall, cpu = time.perf_counter() - w0, time.process_time() - c0
            T = r.summary["duration_s"]
            record("tow: cable, winch, seabed", f"`{name}` end to end ({T:.0f} s simulated)", T / wall, "x")
            print(
                f"{name:17s} {T:6.0f} s simulated: {wall:6.2f} s wall, {cpu:6.2f} s CPU "
                f"(RTF {T / wall:.0f}x wall, {T / cpu:.0f}x CPU)"
            )


if __name__ == "__main__":
    main()
