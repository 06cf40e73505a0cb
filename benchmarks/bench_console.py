"""Console benchmark: real-time headroom per live scenario, state stream rate, e-stop latency, pacing.

    NUMBA_NUM_THREADS=1 python benchmarks/bench_console.py [--seconds 10]

1. Headroom: each live scenario's simulation run unpaced for ``--sim`` simulated seconds, in
   the console's chunks (``sim.run`` of 0.05 s, with the console's logging); the real-time factor
   says how much faster than wall-clock time it could go (``--speed`` up to about that).
2. A real server (uvicorn on a free 127.0.0.1 port, ``usv-remote``) and a WebSocket client: state
   messages per second, emergency-stop latency (send -> first state message reporting the stop, and
   its thrust), and the pacing error (simulated vs wall time over ``--seconds``).
"""

from __future__ import annotations

import argparse
import asyncio
import json
import math
import socket
import tempfile
import threading
import time

import numpy as np


def headroom(name: str, sim_s: float) -> tuple[float, float]:
    from oceangnc.api import resolve_config
    from oceangnc.console.session import _TeeLog

    sc, cfg = resolve_config(name)
    sim = sc.build(cfg, np.random.default_rng(0))
    sim.run(1.0)  # warm-up (compilation)
    chunk = max(sim.tick * sim.dt, 0.05 // (sim.tick * sim.dt) * sim.tick * sim.dt)
    tee = _TeeLog(None)
    t0 = time.perf_counter()
    n = int(round(sim_s / chunk))
    for _ in range(n):
        sim.run(chunk, log=tee)
    wall = time.perf_counter() - t0
    return n * chunk / wall, sim.dt


def free_port() -> int:
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        return s.getsockname()[1]


async def client(url: str, seconds: float) -> dict:
    import websockets

    out: dict = {}
    async with websockets.connect(url) as ws:
        await ws.recv()  # role
        await ws.recv()  # hello
        first = None
        n = 0
        t0 = time.perf_counter()
        while time.perf_counter() - t0 < seconds:
            m = json.loads(await ws.recv())
            if m["type"] == "state":
                n += 1
                first = first or (m["t"], time.perf_counter())
                last = (m["t"], time.perf_counter())
        out["stream_hz"] = n / (time.perf_counter() - t0)
        out["pacing_rel_err"] = ((last[0] - first[0]) - (last[1] - first[1])) / (last[1] - first[1])
        lat = []
        zero = []
        for _ in range(5):
            await ws.send(json.dumps({"type": "estop", "engaged": True}))
            ts = time.perf_counter()
            while True:
                m = json.loads(await ws.recv())
                if m["type"] == "state" and m["estop"]:
                    lat.append(time.perf_counter() - ts)
                    zero.append(m["signals"]["usv.thrust_port"] == 0.0 and m["signals"]["usv.thrust_stbd"] == 0.0)
                    break
            await ws.send(json.dumps({"type": "estop", "engaged": False}))
            t1 = time.perf_counter()
            while time.perf_counter() - t1 < 2.0:
                await ws.recv()
        out["estop_latency_ms"] = [round(1000 * x, 1) for x in lat]
        out["estop_thrust_zero_in_first_report"] = all(zero)
    return out


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--seconds", type=float, default=10.0)
    ap.add_argument("--sim", type=float, default=30.0, help="simulated seconds for the headroom runs")
    a = ap.parse_args()
    from oceangnc.console.session import Session

    print("## real-time headroom (unpaced, console chunks and logging)")
    for name in Session.live_scenarios():
        try:
            rtf, dt = headroom(name, a.sim)
        except Exception as e:  # noqa: BLE001 - report and go on
            print(f"  {name:<22} failed: {e}")
            continue
        print(f"  {name:<22} dt = {dt * 1000:g} ms   real-time factor {rtf:7.1f}x")

    import uvicorn

    from oceangnc.console.server import create_app

    port = free_port()
    with tempfile.TemporaryDirectory() as d:
        session = Session("usv-remote", out_root=d)
        server = uvicorn.Server(
            uvicorn.Config(create_app(session, token="bench-token-1"), host="127.0.0.1", port=port, log_level="warning")
        )
        th = threading.Thread(target=server.run, daemon=True)
        th.start()
        while not server.started:
            time.sleep(0.05)
        res = asyncio.run(client(f"ws://127.0.0.1:{port}/ws?token=bench-token-1", a.seconds))
        server.should_exit = True
        th.join(10)
    print("## live server (usv-remote, 1x)")
    print(f"  state stream          {res['stream_hz']:.1f} Hz over {a.seconds:g} s")
    print(f"  pacing error          {100 * res['pacing_rel_err']:+.2f} % (simulated vs wall time)")
    print(f"  e-stop latency        {res['estop_latency_ms']} ms (send -> first state reporting it)")
    print(f"  thrust zero in it     {res['estop_thrust_zero_in_first_report']}")
    if not math.isfinite(res["pacing_rel_err"]):
        raise SystemExit(1)


if __name__ == "__main__":
    main()
