"""A scripted operator for the oceangnc console: drive the USV over the WebSocket, stop it, get the log.

Start the console in one terminal::

    export OCEANGNC_CONSOLE_TOKEN=my-secret-token   # not --token: a command line shows in ps
    oceangnc console usv-remote                      # http://127.0.0.1:8050/?token=my-secret-token

and run this script in another (it reads the same variable, or ``--token``)::

    python examples/console_client.py [--url ws://127.0.0.1:8050/ws] [--out console_log.parquet]

(without a token the console prints a random one in its URL: pass that). The script connects as
the operator (it takes control if a page holds it: an explicit, logged take-over).

It switches to remote mode, sends the stick at 20 Hz (10 s ahead, 10 s ahead and to starboard),
pulls the emergency stop and checks that the thrust is zero in the next state update, resets it,
hands the boat back to the autopilot, and downloads the run's Parquet log (the same format as
``oceangnc run``). Messages are JSON objects; see ``docs/console.md`` for the protocol.
"""

from __future__ import annotations

import argparse
import asyncio
import json
import math
import os
import time
from urllib.request import urlopen


async def operate(url: str, out: str, token: str) -> None:
    import websockets  # pip install 'oceangnc[console]'

    async with websockets.connect(f"{url}?token={token}") as ws:
        role = json.loads(await ws.recv())
        if role["role"] != "operator":
            await ws.send(json.dumps({"type": "control", "take": True, "force": True}))
        hello = json.loads(await ws.recv())
        while hello["type"] != "hello":
            hello = json.loads(await ws.recv())
        print(f"connected: scenario {hello['scenario']}, gains {', '.join(hello['gains'])}")
        latest: dict = {}
        stick = {"surge": 0.0, "yaw": 0.0}

        async def receive():
            async for raw in ws:
                m = json.loads(raw)
                if m["type"] == "state":
                    latest.clear()
                    latest.update(m)
                    for e in m.get("events", []):
                        print(f"  [{e['level']}] t={e['t']:.1f} s  {e['text']}")
                elif m["type"] == "rejected":
                    print(f"  rejected: {m['reason']}")

        async def stick_sender():  # the console's watchdog wants a stick message at least every 1 s
            while True:
                await ws.send(json.dumps({"type": "stick", "source": "script", **stick}))
                await asyncio.sleep(0.05)

        rx = asyncio.create_task(receive())
        await ws.send(json.dumps({"type": "mode", "mode": "remote"}))
        tx = asyncio.create_task(stick_sender())

        def show(what):
            s = latest.get("signals", {})
            print(f"{what:<28} t={latest.get('t', 0):6.1f} s  u={s.get('usv.u', math.nan):5.2f} m/s  "
                  f"r={math.degrees(s.get('usv.r', math.nan)):6.1f} deg/s  "
                  f"thrust {s.get('usv.thrust_port', math.nan):6.1f} / {s.get('usv.thrust_stbd', math.nan):6.1f} N")

        stick.update(surge=1.0, yaw=0.0)
        await asyncio.sleep(10)
        show("full ahead")
        stick.update(surge=1.0, yaw=0.5)
        await asyncio.sleep(10)
        show("ahead, half starboard")

        # a malformed command is rejected; the run goes on
        await ws.send(json.dumps({"type": "stick", "surge": 5.0, "yaw": 0.0}))

        await ws.send(json.dumps({"type": "estop", "engaged": True}))
        t0 = time.monotonic()
        while not latest.get("estop"):
            await asyncio.sleep(0.005)
        s = latest["signals"]
        print(f"emergency stop acknowledged after {1000 * (time.monotonic() - t0):.0f} ms; thrust "
              f"{s['usv.thrust_port']:.1f} / {s['usv.thrust_stbd']:.1f} N")
        await asyncio.sleep(5)
        show("stopped (latched)")
        stick.update(surge=0.0, yaw=0.0)
        await ws.send(json.dumps({"type": "estop", "engaged": False}))
        await ws.send(json.dumps({"type": "mode", "mode": "auto"}))
        await asyncio.sleep(5)
        show("autopilot again")
        tx.cancel()
        rx.cancel()

    http = url.replace("ws://", "http://").replace("wss://", "https://").rsplit("/ws", 1)[0]
    with urlopen(f"{http}/api/log.parquet?token={token}") as r:
        data = r.read()
    with open(out, "wb") as f:
        f.write(data)
    import pandas as pd

    df = pd.read_parquet(out)
    print(f"log: {out}, {len(df)} rows x {len(df.columns)} columns, t = {df['t'].iloc[0]:.1f}..{df['t'].iloc[-1]:.1f} s")


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--url", default="ws://127.0.0.1:8050/ws")
    ap.add_argument("--out", default="console_log.parquet")
    env = os.environ.get("OCEANGNC_CONSOLE_TOKEN")
    ap.add_argument(
        "--token",
        default=env,
        required=not env,
        help="the console's session token (printed in its URL; default $OCEANGNC_CONSOLE_TOKEN)",
    )
    a = ap.parse_args()
    asyncio.run(operate(a.url, a.out, a.token))


if __name__ == "__main__":
    main()
