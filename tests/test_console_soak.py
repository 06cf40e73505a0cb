"""Soak test of the console (issue 20): one operator and 20 viewers on 127.0.0.1 for 60 s.

The real ``oceangnc console`` runs in a subprocess. Each client must receive the state stream at
>= 20 Hz, the simulation's pacing error must stay under 2 %, the server's memory must be flat over
the last 30 s (within 5 %), and a client that stops reading must be dropped (bounded send queue, a
message in the event log) without slowing the others.
"""

from __future__ import annotations

import asyncio
import json
import os
import socket
import time

import pytest
from console_server import console_server

psutil = pytest.importorskip("psutil")
websockets_client = pytest.importorskip("websockets.asyncio.client")

pytestmark = pytest.mark.slow

TOKEN = "soak-token-123456"
DURATION = 60.0
VIEWERS = 20


@pytest.fixture
def console(tmp_path):
    with console_server(tmp_path, TOKEN, start_timeout_s=120) as (port, proc):
        yield port, proc


async def _soak(port: int, pid: int) -> dict:
    uri = f"ws://127.0.0.1:{port}/ws?token={TOKEN}"
    counts = [0] * (VIEWERS + 1)
    op_states: list[tuple[float, float]] = []  # (wall, sim t)
    events: list[str] = []
    mem: list[tuple[float, int]] = []
    stop = asyncio.Event()
    t_start = time.monotonic()
    proc = psutil.Process(pid)

    async def operator():
        async with websockets_client.connect(uri, max_size=1 << 22) as ws:
            await ws.send(json.dumps({"type": "mode", "mode": "remote"}))

            async def sticks():
                k = 0
                while not stop.is_set():
                    k += 1
                    surge = 0.6 if (k // 200) % 2 == 0 else 0.3
                    await ws.send(json.dumps({"type": "stick", "surge": surge, "yaw": 0.2}))
                    await asyncio.sleep(0.05)

            task = asyncio.create_task(sticks())
            try:
                while not stop.is_set():
                    raw = await ws.recv()
                    m = json.loads(raw)
                    if m["type"] == "state":
                        counts[0] += 1
                        op_states.append((time.monotonic(), m["t"]))
                        events.extend((e["wall"], e["text"]) for e in m.get("events", []))
            finally:
                task.cancel()

    async def viewer(i):
        async with websockets_client.connect(uri + "&role=viewer", max_size=1 << 22) as ws:
            while not stop.is_set():
                raw = await ws.recv()
                if raw.startswith('{"type":"state"'):
                    counts[i] += 1

    async def slow_reader():
        """Opens a viewer WebSocket by hand and never reads from it (small receive buffer)."""
        import base64

        loop = asyncio.get_running_loop()
        s = socket.socket()
        s.setsockopt(socket.SOL_SOCKET, socket.SO_RCVBUF, 4096)
        s.setblocking(False)
        await loop.sock_connect(s, ("127.0.0.1", port))
        key = base64.b64encode(os.urandom(16)).decode()
        await loop.sock_sendall(
            s,
            (
                f"GET /ws?token={TOKEN}&role=viewer HTTP/1.1\r\nHost: 127.0.0.1:{port}\r\n"
                f"Upgrade: websocket\r\nConnection: Upgrade\r\nSec-WebSocket-Key: {key}\r\n"
                f"Sec-WebSocket-Version: 13\r\n\r\n"
            ).encode(),
        )
        head = await loop.sock_recv(s, 64)
        assert head.startswith(b"HTTP/1.1 101"), head
        try:
            await stop.wait()  # never reads again
        finally:
            s.close()

    async def memory():
        while not stop.is_set():
            mem.append((time.monotonic() - t_start, proc.memory_info().rss))
            await asyncio.sleep(1.0)

    tasks = [
        asyncio.create_task(operator()),
        *[asyncio.create_task(viewer(i + 1)) for i in range(VIEWERS)],
        asyncio.create_task(slow_reader()),
        asyncio.create_task(memory()),
    ]
    await asyncio.sleep(2.0)  # everybody connected; the count starts now
    c0 = list(counts)
    w0 = time.monotonic()
    wall0 = time.time()
    await asyncio.sleep(DURATION)
    c1 = list(counts)
    w1 = time.monotonic()
    stop.set()
    for t in tasks:
        t.cancel()
    await asyncio.gather(*tasks, return_exceptions=True)
    return {
        "rates": [(b - a) / (w1 - w0) for a, b in zip(c0, c1)],
        "op_states": op_states,
        "events": events,
        "mem": mem,
        "w0": w0,
        "w1": w1,
        "wall0": wall0,
    }


def test_one_operator_and_20_viewers_for_60_s(console):
    port, proc = console
    r = asyncio.run(_soak(port, proc.pid))
    rates = r["rates"]
    assert min(rates) >= 20.0, rates
    st = [(w, t) for w, t in r["op_states"] if r["w0"] <= w <= r["w1"]]
    pacing = (st[-1][1] - st[0][1]) / (st[-1][0] - st[0][0]) - 1.0
    assert abs(pacing) < 0.02, pacing
    late = [m for t, m in r["mem"] if t >= r["mem"][-1][0] - 30.0]
    growth = max(late) / min(late) - 1.0
    assert growth < 0.05, (growth, r["mem"])
    texts = [e for _, e in r["events"]]
    dropped = [e for e in texts if "dropped: it stopped reading" in e]
    assert len(dropped) == 1, texts[-20:]
    lags = [e for w, e in r["events"] if w >= r["wall0"] and "fell" in e and "behind" in e]
    assert not lags, lags  # no re-anchoring while the 21 clients were streaming
    print(
        f"soak: rates {min(rates):.1f}-{max(rates):.1f} Hz, pacing {100 * pacing:+.2f} %, memory over the "
        f"last 30 s {100 * growth:.2f} %, {dropped[0]}"
    )
