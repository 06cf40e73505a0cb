"""MAVLink vehicle and log import benchmarks.

1. Vehicle throughput: the served loop (receive, watchdog, bus, simulation, telemetry to one peer, .tlog)
   stepped as fast as it goes for ``usv-remote`` and ``combined-survey``: the highest ``--speed`` the
   machine sustains (simulated s per wall s).
2. Link: a pymavlink GCS over 127.0.0.1: COMMAND_LONG arm -> COMMAND_ACK round trip (median, p95), and
   the failsafe delay after the GCS goes silent in MANUAL (8 trials).
3. Import: rows per second for a DataFlash .bin, a .tlog and a .ulg of a 600 s run.

Run: ``PYTHONPATH=src python benchmarks/bench_mavlink.py``.
"""

from __future__ import annotations

import statistics
import sys
import tempfile
import time
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "tests"))


def vehicle_throughput(scenario: str, sim_s: float) -> float:
    from oceangnc.mavlink.vehicle import MavlinkVehicle

    now = [0.0]
    with tempfile.TemporaryDirectory() as d:
        v = MavlinkVehicle(
            scenario,
            listen="udp:127.0.0.1:0",
            out_root=d,
            clock=lambda: now[0],
            speed=100.0,
            tlog=Path(d) / "x.tlog",
            gcs=["udp:127.0.0.1:9"],
        )
        v._arm(True)
        v._set_mode(10, "bench")
        t0 = time.perf_counter()
        while v.sim.t < sim_s and not v.ended:
            now[0] += 0.01
            v.step_once()
        wall = time.perf_counter() - t0
        v.close()
    return v.sim.t / wall


def link_latency() -> tuple[float, float, list[float]]:
    from mavlink_gcs import GCS
    from oceangnc.mavlink.protocol import mavlink as M
    from oceangnc.mavlink.vehicle import MavlinkVehicle

    v = MavlinkVehicle("usv-remote", listen="udp:127.0.0.1:0", speed=2.0, out_root=None).start()
    g = GCS(v.address)
    g.wait("HEARTBEAT", 3.0)
    rtt = []
    for i in range(50):
        t0 = time.perf_counter()
        g.mav.command_long_send(1, 1, M.MAV_CMD_COMPONENT_ARM_DISARM, 0, float(i % 2), 0, 0, 0, 0, 0, 0)
        g.ack(M.MAV_CMD_COMPONENT_ARM_DISARM)
        rtt.append(time.perf_counter() - t0)
    fs = []
    for _ in range(8):
        g.send_heartbeats = True
        g.mav.set_mode_send(1, M.MAV_MODE_FLAG_CUSTOM_MODE_ENABLED, 0)
        g.pump(0.5, stick=(300, 0))
        t_last = g._t_last_stick if hasattr(g, "_t_last_stick") else time.monotonic()
        g.send_heartbeats = False
        while v.mode != 4 and time.monotonic() < t_last + 3:
            time.sleep(0.001)
        fs.append(time.monotonic() - t_last)
    g.close()
    v.stop()
    rtt.sort()
    return statistics.median(rtt), rtt[int(0.95 * len(rtt))], fs


def import_rate() -> dict:
    import oceangnc
    from log_writers import write_dataflash, write_ulog
    from oceangnc.io.importers import import_log

    out = {}
    with tempfile.TemporaryDirectory() as d:
        res = oceangnc.run("usv-remote", duration=600.0, out=Path(d) / "r", plots=False)
        df = res.df
        write_dataflash(Path(d) / "a.bin", df, 60.0, 10.0, 355.0, 135.0)
        write_ulog(Path(d) / "a.ulg", df, 355.0, 135.0)
        for name in ("a.bin", "a.ulg"):
            t0 = time.perf_counter()
            r = import_log(Path(d) / name, rate=10.0, origin=(60.0, 10.0))
            out[name] = (len(df), time.perf_counter() - t0, len(r.df))
    return out


def main() -> None:
    import os

    print(time.strftime("%Y-%m-%d %H:%M UTC", time.gmtime()), "load", os.getloadavg())
    for sc, dur in (("usv-remote", 120.0), ("combined-survey", 30.0)):
        print(f"vehicle {sc}: {vehicle_throughput(sc, dur):.1f}x real time (loop + telemetry + tlog + log)")
    med, p95, fs = link_latency()
    print(f"arm COMMAND_LONG -> COMMAND_ACK: median {med * 1e3:.1f} ms, p95 {p95 * 1e3:.1f} ms")
    print("failsafe after the last stick packet (s):", " ".join(f"{x:.3f}" for x in fs))
    for name, (rows, wall, out) in import_rate().items():
        print(f"import {name}: {rows} source rows in {wall:.2f} s ({rows / wall:.0f} rows/s) -> {out} rows")


if __name__ == "__main__":
    main()
