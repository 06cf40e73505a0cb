"""A run streamed to Foxglove / Lichtblick over the Foxglove WebSocket protocol
(``foxglove.websocket.v1``): ``oceangnc view RUN --foxglove [--port 8765] [--speed 1] [--once]``.

The channels and messages are those of the MCAP export (:func:`oceangnc.view.mcap_export.build_channels`:
poses, ``/tf``, ``/scene``, GPS fixes, ``/signals/<prefix>``), played in time at ``speed`` x the
logged rate, from the start again at the end unless ``once``. The protocol, as the server uses it:

* the client asks for the subprotocol ``foxglove.websocket.v1``; the server answers with a
  ``serverInfo`` (capability ``time``: the stream's clock is the run's time) and one ``advertise``
  of every channel (``encoding`` json, ``schemaEncoding`` jsonschema, the JSON Schema as text);
* the client sends ``subscribe`` (``{"id": SUB, "channelId": CH}``) and ``unsubscribe``;
* for every log row the server sends a binary *Time* (0x02, uint64 ns) and, on every subscribed
  channel with a message at that row, a *Message Data* (0x01, uint32 subscription id, uint64 ns, the
  JSON payload); integers little-endian.

Safety: the server binds 127.0.0.1 only (this machine); it is read-only (no client publishing,
parameters or services); a connection presenting a browser ``Origin`` is accepted only from the
Foxglove web app, a page on this machine, or an origin listed with ``--allow-origin``; a client
that does not read fast enough is dropped rather than buffered without bound. Needs the optional
package ``websockets`` (``pip install 'oceangnc[console]'``).
"""

from __future__ import annotations

import asyncio
import contextlib
import json
import math
import secrets
import struct
import sys
import time
from pathlib import Path
from urllib.parse import urlsplit

import numpy as np

from .mcap_export import Channel, build_channels, stamps_ns
from .run_data import RunData, load_run

SUBPROTOCOL = "foxglove.websocket.v1"
OP_MESSAGE, OP_TIME = 0x01, 0x02
#: browser origins accepted besides pages of this machine (http(s)://127.0.0.1, localhost, [::1])
APP_ORIGINS = ("https://app.foxglove.dev", "https://studio.foxglove.dev")
MAX_QUEUE = 2000  # messages waiting for one client before it is dropped
FIRST_STATE_S = 60.0  # a console that sends no state within this is an error


def origin_allowed(origin: str | None, extra: tuple[str, ...] = ()) -> bool:
    """No Origin (a native client), the Foxglove web app, a page of this machine or ``extra``."""
    if origin is None or origin == "file://" or origin in APP_ORIGINS or origin in extra:
        return True
    host = urlsplit(origin).hostname or ""
    return host in ("127.0.0.1", "localhost", "::1")


class _Client:
    def __init__(self, ws):
        self.ws = ws
        self.subs: dict[int, int] = {}  # channel id -> subscription id
        self.queue: asyncio.Queue = asyncio.Queue(MAX_QUEUE)


class FoxgloveRunServer:
    """Plays the channels of a run to every connected client (module docstring)."""

    def __init__(self, rd: RunData, speed: float = 1.0, loop: bool = True, allow_origins: tuple[str, ...] = ()):
        if not speed > 0:
            raise ValueError("speed must be > 0")
        self.rd = rd
        self.name = rd.path.name
        self.channels: list[Channel] = build_channels(rd)
        self.ns = stamps_ns(rd).tolist()
        self.speed = speed
        self.loop = loop
        self.allow_origins = allow_origins
        self.clients: set[_Client] = set()
        self.rows_sent = 0
        self.done = asyncio.Event()

    #: the session token every connection must present (None: none asked; a recorded run's stream)
    token: str | None = None
    _throttle = None

    def process_request(self, connection, request):
        """The token check of the WebSocket handshake (before the protocol): None lets the connection
        through; else an HTTP 401 (missing or wrong token) or 429 (too many failed tries from that peer,
        :func:`oceangnc.console.access.token_refusal`: the right token always gets through)."""
        if not self.token:
            return None
        from urllib.parse import parse_qs

        from ..console.access import Throttle, token_refusal

        if self._throttle is None:
            self._throttle = Throttle()
        peer = str((connection.remote_address or ("?",))[0])
        tok = (parse_qs(urlsplit(request.path).query).get("token") or [""])[0]
        tok = tok or request.headers.get("X-Oceangnc-Token", "")
        auth = request.headers.get("Authorization", "")
        if not tok and auth.lower().startswith("bearer "):
            tok = auth[7:].strip()
        bad = token_refusal(self._throttle, peer, tok, self.token)
        if bad is None:
            return None
        status, msg, secs = bad
        if status == 401:
            return connection.respond(401, msg + " (the URL printed at start has it)\n")
        resp = connection.respond(429, msg + "\n")
        resp.headers["Retry-After"] = str(secs)
        return resp

    # -- protocol ----------------------------------------------------------------------------------
    def server_info(self) -> str:
        return json.dumps(
            {
                "op": "serverInfo",
                "name": f"oceangnc {self.name}",
                "capabilities": ["time"],
                "supportedEncodings": [],
                "metadata": {"run": self.name, "frames": "world ENU, vehicles FLU (REP 103)"},
                "sessionId": str(time.time_ns()),
            }
        )

    def advertise(self) -> str:
        chans = [
            {
                "id": i + 1,
                "topic": c.topic,
                "encoding": "json",
                "schemaName": c.schema_name,
                "schema": c.schema.decode(),
                "schemaEncoding": "jsonschema",
            }
            for i, c in enumerate(self.channels)
        ]
        return json.dumps({"op": "advertise", "channels": chans})

    def _status(self, level: int, message: str) -> str:
        return json.dumps({"op": "status", "level": level, "message": message})

    async def handler(self, ws) -> None:
        origin = ws.request.headers.get("Origin") if ws.request is not None else None
        if not origin_allowed(origin, self.allow_origins):
            await ws.close(1008, f"origin {origin} not allowed")
            return
        if ws.subprotocol != SUBPROTOCOL:
            await ws.close(1002, f"subprotocol {SUBPROTOCOL} required")
            return
        client = _Client(ws)
        await ws.send(self.server_info())
        await ws.send(self.advertise())
        self.clients.add(client)
        sender = asyncio.create_task(self._send_loop(client))
        try:
            async for raw in ws:
                if isinstance(raw, bytes):
                    continue  # no client publishing
                try:
                    msg = json.loads(raw)
                except json.JSONDecodeError:
                    await ws.send(self._status(2, "not JSON"))
                    continue
                op = msg.get("op")
                if op == "subscribe":
                    for s in msg.get("subscriptions", []):
                        ch, sid = s.get("channelId"), s.get("id")
                        if isinstance(ch, int) and isinstance(sid, int) and 1 <= ch <= len(self.channels):
                            client.subs[ch] = sid
                        else:
                            await ws.send(self._status(1, f"unknown channel {ch}"))
                elif op == "unsubscribe":
                    gone = set(msg.get("subscriptionIds", []))
                    client.subs = {c: s for c, s in client.subs.items() if s not in gone}
                else:
                    await ws.send(self._status(1, f"operation {op!r} not supported (read-only stream)"))
        except Exception:  # the client went away
            pass
        finally:
            self.clients.discard(client)
            sender.cancel()

    async def _send_loop(self, client: _Client) -> None:
        try:
            while True:
                await client.ws.send(await client.queue.get())
        except Exception:
            self.clients.discard(client)

    def _offer(self, client: _Client, frame: bytes) -> None:
        try:
            client.queue.put_nowait(frame)
        except asyncio.QueueFull:  # a client too slow: dropped, not buffered without bound
            self.clients.discard(client)
            asyncio.ensure_future(client.ws.close(1008, "client too slow"))

    # -- playback ----------------------------------------------------------------------------------
    def _emit(self, i: int) -> None:
        self.emit(self.ns[i], [c.payloads[i] for c in self.channels])

    def emit(self, ts: int, payloads: list[bytes | None]) -> None:
        """Send a Time frame and, to every subscriber of channel k, ``payloads[k - 1]`` (None: nothing)."""
        tframe = struct.pack("<BQ", OP_TIME, ts)
        for client in list(self.clients):
            self._offer(client, tframe)
            for ch, sid in list(client.subs.items()):
                data = payloads[ch - 1]
                if data is not None:
                    self._offer(client, struct.pack("<BIQ", OP_MESSAGE, sid, ts) + data)
        self.rows_sent += 1

    async def play(self) -> None:
        """Emit the rows paced by their times / speed; again from the start unless ``loop`` is False."""
        t = self.rd.t
        while True:
            w0 = time.monotonic()
            for i in range(self.rd.rows):
                wait = w0 + (t[i] - t[0]) / self.speed - time.monotonic()
                if wait > 0:
                    await asyncio.sleep(wait)
                self._emit(i)
            if not self.loop:
                break
        await asyncio.sleep(0.5)  # let the queues drain
        self.done.set()


@contextlib.asynccontextmanager
async def _listening(srv, port: int, source: str, how: str, ready):
    """The Foxglove WebSocket server of ``srv`` on 127.0.0.1:``port`` (0: any free port), announced on
    stdout with its URL and ``how`` (``ready(port)`` told the bound port) while the block runs."""
    from websockets.asyncio.server import serve
    from websockets.typing import Subprotocol

    async with serve(
        srv.handler,
        "127.0.0.1",
        port,
        subprotocols=[Subprotocol(SUBPROTOCOL)],
        max_size=2**20,
        compression=None,
        process_request=srv.process_request,
    ) as server:
        bound = server.sockets[0].getsockname()[1]
        url = f"ws://127.0.0.1:{bound}" + (f"/?token={srv.token}" if srv.token else "")
        print(f"Foxglove WebSocket stream of {source} at {url} ({len(srv.channels)} channels{how})", flush=True)
        if ready is not None:
            ready(bound)
        yield server


async def _serve(rd: RunData, port: int, speed: float, loop: bool, allow_origins, ready) -> int:
    srv = FoxgloveRunServer(rd, speed=speed, loop=loop, allow_origins=allow_origins)
    how = f", {speed:g}x{', once' if not loop else ''}; Ctrl-C to stop"
    async with _listening(srv, port, f"{rd.path}", how, ready):
        await srv.play()
    return 0


def serve_foxglove(run, port: int = 8765, speed: float = 1.0, loop: bool = True, allow_origins=(), ready=None) -> int:
    """Stream the run folder ``run`` on ws://127.0.0.1:PORT until interrupted (or its end, ``loop=False``).
    Exit code 2 with a one-line message without the ``websockets`` package."""
    try:
        import websockets.asyncio.server  # noqa: F401
    except ImportError:
        print(
            "error: the Foxglove stream needs the optional package 'websockets': install oceangnc[console]",
            file=sys.stderr,
        )
        return 2
    rd = run if isinstance(run, RunData) else load_run(run)
    try:
        return asyncio.run(_serve(rd, port, speed, loop, tuple(allow_origins), ready))
    except KeyboardInterrupt:
        print("stopped", file=sys.stderr)
        return 0


# ---- a live console session ---------------------------------------------------------------------


def state_run(hello: dict, state: dict) -> RunData:
    """One console state message as a one-row :class:`RunData` (the console's ``hello`` gives the
    vehicles' sizes and the route): what :func:`build_channels` turns into the stream's messages."""
    import math

    import numpy as np

    from .run_data import describe

    cols = {"t": np.array([float(state.get("t", 0.0))])}
    for k, v in (state.get("signals") or {}).items():
        if isinstance(v, bool) or k == "t":
            continue
        if isinstance(v, (int, float)) or v is None:
            cols[k] = np.array([math.nan if v is None else float(v)])
    view = hello.get("view") or {}
    cfg: dict = {}
    for b in view.get("bodies", []):
        length, beam = b.get("length"), b.get("beam")
        cfg[b["name"]] = {"length": length, "length_oa": length, "beam": beam, "diameter": beam}
    if view.get("route"):
        cfg["guidance"] = {"waypoints": [list(p) for p in view["route"]]}
    return describe(Path(f"console-{hello.get('run', 'live')}"), cols, cfg, {"scenario": hello.get("scenario", "")})


class FoxgloveLiveServer(FoxgloveRunServer):
    """Republishes a live simulation on the Foxglove WebSocket protocol. ``states`` is its source: an
    async iterable of the console's messages (``{"type": "hello", "run", "scenario", "view"}`` then
    ``{"type": "state", "run", "t", "signals"}``): a running console read as a viewer
    (:func:`console_states`) or a MAVLink vehicle (:class:`VehicleStates`). The channels are those of
    the first state, one message each per state with a new time (a console repeats a state while
    paused); a new run's states are stamped with its own time, from 0 again. ``token`` (the console's
    token rules): every connection must present it (``?token=``, header ``X-Oceangnc-Token`` or
    ``Authorization: Bearer``), failed tries throttled per peer (:class:`oceangnc.console.access.Throttle`)."""

    def __init__(self, states, name: str = "live", allow_origins: tuple[str, ...] = (), token: str | None = None):
        self.states = states
        self.name = name
        self.channels = []
        self.speed, self.loop, self.allow_origins = 1.0, False, allow_origins
        self.token = token
        self.clients = set()
        self.rows_sent = 0
        self.done = asyncio.Event()
        self.ready = asyncio.Event()
        self.error: str | None = None

    async def play(self) -> None:
        hello = None
        last_t: float | None = None
        index: dict[str, int] = {}
        try:
            async for m in self.states:
                if m.get("type") == "hello":
                    hello, last_t = m, None
                elif m.get("type") == "state" and hello is not None:
                    t = float(m.get("t", 0.0))
                    if m.get("run") != hello.get("run"):
                        continue  # a new run starts with its hello
                    if last_t is not None and t <= last_t:
                        continue  # the console repeats its last state while paused or between steps
                    last_t = t
                    chans = build_channels(state_run(hello, m))
                    if not self.channels:
                        self.channels = chans
                        index = {c.topic: k for k, c in enumerate(chans)}
                        self.ready.set()
                    payloads: list[bytes | None] = [None] * len(self.channels)
                    for c in chans:  # a topic that appears later than the first state is left out
                        if c.topic in index and c.schema_name == self.channels[index[c.topic]].schema_name:
                            payloads[index[c.topic]] = c.payloads[0]
                    self.emit(int(round(t * 1e9)), payloads)
        except Exception as e:  # the source went away or refused us
            self.error = f"{type(e).__name__}: {e}"
        finally:
            self.ready.set()
            self.done.set()


async def console_states(ws_url: str):
    """The messages of a running console's viewer WebSocket ``ws_url`` (:func:`console_ws_url`), decoded."""
    from websockets.asyncio.client import connect

    async with connect(ws_url, open_timeout=30, max_size=2**22) as ws:
        async for raw in ws:
            yield json.loads(raw)


def bus_signals(bus: dict) -> dict[str, float]:
    """The numeric scalars of a simulation bus (what a console state's ``signals`` carries for
    :func:`state_run`): private keys (``_...``), flags, strings and arrays left out."""
    out = {}
    for k, v in bus.items():
        if k.startswith("_") or isinstance(v, bool) or not isinstance(v, (int, float, np.floating, np.integer)):
            continue
        out[k] = float(v)
    return out


class VehicleStates:
    """A :class:`~oceangnc.mavlink.vehicle.MavlinkVehicle` as a source of console messages for
    :class:`FoxgloveLiveServer`: :meth:`hook` (appended to the vehicle's ``state_hooks``, called by
    its loop after every pass) takes a copy of the bus at most ``rate_hz`` times a wall second and
    only when the simulated time moved; the hello's view is the console's (:func:`oceangnc.console.view.infer_view`).
    The copies cross to the server's event loop through a bounded queue (a stalled loop loses states,
    it never blocks the vehicle); :meth:`close` ends the stream."""

    QUEUE = 256

    def __init__(self, loop: asyncio.AbstractEventLoop, rate_hz: float = 25.0, clock=time.monotonic):
        self.loop = loop
        self.period = 1.0 / float(rate_hz)
        self.clock = clock
        self.queue: asyncio.Queue = asyncio.Queue(self.QUEUE)
        self._hello: dict | None = None
        self._wall = -math.inf
        self._t = -math.inf
        self.dropped = 0
        self.error: str | None = None

    def _put(self, item) -> None:  # on the event loop
        try:
            self.queue.put_nowait(item)
        except asyncio.QueueFull:
            self.dropped += 1

    def hook(self, vehicle) -> None:
        """Called from the vehicle's loop (under its lock): cheap unless a state is due; never raises
        (a failure is kept in ``error`` and ends the stream, not the vehicle)."""
        if self.error is not None:
            return
        try:
            self._take(vehicle)
        except Exception as e:  # noqa: BLE001
            self.error = f"{type(e).__name__}: {e}"
            self.close()

    def _take(self, vehicle) -> None:
        sim = vehicle.sim
        t, now = float(sim.t), self.clock()
        if t <= self._t or now - self._wall < self.period:
            return
        if self._hello is None:
            from ..console.view import infer_view

            run = vehicle.run_dir.name if vehicle.run_dir is not None else f"mavlink-{vehicle.scenario.name}"
            view = infer_view(vehicle.scenario, vehicle.cfg, sim.bus)
            self._hello = {"type": "hello", "run": run, "scenario": vehicle.scenario.name, "view": view}
            self.loop.call_soon_threadsafe(self._put, self._hello)
        self._t, self._wall = t, now
        state = {"type": "state", "run": self._hello["run"], "t": t, "signals": bus_signals(sim.bus)}
        self.loop.call_soon_threadsafe(self._put, state)

    def close(self) -> None:
        """End the stream (any thread)."""
        with contextlib.suppress(RuntimeError):  # the loop already closed
            self.loop.call_soon_threadsafe(self._put, None)

    def __aiter__(self):
        return self

    async def __anext__(self):
        item = await self.queue.get()
        if item is None:
            raise StopAsyncIteration
        return item


def console_ws_url(url: str) -> str:
    """``http://127.0.0.1:8050/?token=T`` (the URL ``oceangnc console`` prints) -> its viewer WebSocket."""
    u = urlsplit(url)
    token = url_token(url)
    scheme = "wss" if u.scheme in ("https", "wss") else "ws"
    return f"{scheme}://{u.netloc}/ws?token={token}&role=viewer"


def url_token(url: str) -> str:
    """The ``token`` query parameter of ``url`` ("" when it has none)."""
    from urllib.parse import parse_qs

    return (parse_qs(urlsplit(url).query).get("token") or [""])[0]


async def _serve_live(srv: FoxgloveLiveServer, source: str, port: int, ready, wait_s: float = FIRST_STATE_S) -> int:
    """Wait for the first state of ``srv``'s source (its channels), then serve until the source ends."""
    player = asyncio.create_task(srv.play())
    print(f"waiting for the first state of {source}", file=sys.stderr, flush=True)
    try:  # the channels are known once the first state arrived
        await asyncio.wait_for(srv.ready.wait(), wait_s)
    except TimeoutError:
        srv.error = f"no state within {wait_s:g} s"
        player.cancel()
    if not srv.channels:
        print(f"error: no state from {source}: {srv.error}", file=sys.stderr)
        return 2
    async with _listening(srv, port, source, "; Ctrl-C to stop", ready):
        await player
    if srv.error:
        print(f"live stream ended: {srv.error}", file=sys.stderr)
    return 0


def serve_console_foxglove(console_url: str, port: int = 8765, allow_origins=(), ready=None) -> int:
    """Stream a running ``oceangnc console`` (its URL with the token) on ws://127.0.0.1:PORT."""
    try:
        import websockets.asyncio.server  # noqa: F401
    except ImportError:
        print(
            "error: the Foxglove stream needs the optional package 'websockets': install oceangnc[console]",
            file=sys.stderr,
        )
        return 2
    try:
        ws_url = console_ws_url(console_url)
        srv = FoxgloveLiveServer(
            console_states(ws_url), "console", allow_origins=tuple(allow_origins), token=url_token(console_url) or None
        )
        return asyncio.run(_serve_live(srv, f"the console {console_url.split('?')[0]}", port, ready))
    except KeyboardInterrupt:
        print("stopped", file=sys.stderr)
        return 0


class VehicleStream:
    """The live Foxglove stream of a MAVLink vehicle, served from a thread of its own: see
    :func:`start_vehicle_foxglove`. ``port`` is the bound port once listening (``listening`` set)."""

    def __init__(self, vehicle, port: int, token: str, allow_origins=(), rate_hz: float = 25.0):
        import threading

        self.loop = asyncio.new_event_loop()
        self.states = VehicleStates(self.loop, rate_hz)
        name = f"mavlink {vehicle.scenario.name}"
        self.server = FoxgloveLiveServer(self.states, name, allow_origins=tuple(allow_origins), token=token)
        self.vehicle = vehicle
        self.listening = threading.Event()
        self.port: int | None = None
        self.code: int | None = None
        vehicle.state_hooks.append(self.states.hook)
        self.thread = threading.Thread(target=self._run, args=(port,), name="oceangnc-foxglove", daemon=True)
        self.thread.start()

    def _ready(self, port: int) -> None:
        self.port = port
        self.listening.set()

    def _run(self, port: int) -> None:
        asyncio.set_event_loop(self.loop)
        try:
            self.code = self.loop.run_until_complete(_serve_live(self.server, "the MAVLink vehicle", port, self._ready))
        except Exception as e:  # noqa: BLE001 (a port in use): the vehicle goes on without its stream
            print(f"error: the Foxglove stream stopped: {type(e).__name__}: {e}", file=sys.stderr, flush=True)
            self.code = 2
        finally:
            self.listening.set()
            self.loop.close()

    def stop(self, timeout: float = 5.0) -> None:
        """End the stream (the vehicle's hook is removed) and wait for its thread."""
        with contextlib.suppress(ValueError):
            self.vehicle.state_hooks.remove(self.states.hook)
        if not self.loop.is_closed():
            self.states.close()
        self.thread.join(timeout)


def start_vehicle_foxglove(
    vehicle, port: int = 8765, token: str | None = None, allow_origins=(), rate_hz: float = 25.0
):
    """Publish the running MAVLink ``vehicle`` (``oceangnc mavlink --foxglove [PORT]``) on
    ws://127.0.0.1:PORT/?token=TOKEN: :class:`FoxgloveLiveServer` fed by :class:`VehicleStates` (the
    vehicle's bus after its passes, at most ``rate_hz`` a second), in a thread of its own; ``token``
    None draws a random one (128 bits, URL-safe, as the console's). Returns the
    :class:`VehicleStream` (``stop()`` ends it), or None without the ``websockets`` package (after a
    one-line message)."""
    try:
        import websockets.asyncio.server  # noqa: F401
    except ImportError:
        print(
            "error: the Foxglove stream needs the optional package 'websockets': install oceangnc[console]",
            file=sys.stderr,
        )
        return None
    return VehicleStream(vehicle, port, token or secrets.token_urlsafe(16), allow_origins, rate_hz)
