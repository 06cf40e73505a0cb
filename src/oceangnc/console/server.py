"""The console's web server: FastAPI on uvicorn, one WebSocket per page, static files, log download.

Routes
------
``GET /``                 the console page (``static/index.html``); open it as ``/?token=TOKEN``
``GET /static/...``       its script and style sheet
``GET /vendor/...``       three.js and the 3D panel's shared module (``oceangnc.view.replay.vendor_file``)
``GET /api/state``        the latest state message (JSON), for scripts and health checks
``GET /api/scenarios``    the scenarios that run live
``GET /api/log.parquet``  the current run's log, a single Parquet file (same columns as ``oceangnc run``)
``WS  /ws``               state stream (``role`` on connect and on every change of control, ``hello`` on
                          connect and on every new run, then ``state`` messages at ``stream_hz``, with
                          new events attached) and commands back (:mod:`oceangnc.console.messages`); a
                          rejected command gets ``{"type": "rejected", "reason": ...}``.

Who can connect (docs/reliability.md)
-------------------------------------
* **Token.** Every ``/api/...`` request and every WebSocket must present the session token (query
  ``?token=``, header ``X-Oceangnc-Token`` or ``Authorization: Bearer``); the page takes it from its
  own URL. Without it: HTTP 401 (WebSocket: refused at the handshake with HTTP 401). A peer address
  that failed the check 20 times in a minute gets HTTP 429 for every further wrong or missing token
  until a try comes back (:class:`oceangnc.console.access.Throttle`); the right token always gets
  through (every local user shares 127.0.0.1: a process guessing there must not lock the operator out).
* **Refusals** are counted by kind, not logged one by one: at most one summary event per 10 s, in a
  history of their own (:class:`oceangnc.console.access.AccessLog`), so a flood without the token
  cannot push an operator's event out.
* **Origin.** A request that carries an ``Origin`` header must come from the page's own origin
  (scheme, host and port equal to the request's ``Host``), else HTTP 403 (WebSocket: refused at the
  handshake with HTTP 403: a page of another web site cannot open a WebSocket to the console,
  cross-site WebSocket hijacking). Requests without ``Origin`` (scripts) still need the token.
  Every request other than GET/HEAD (a state change) is checked the same way.
* **Host.** On a loopback binding, a ``Host`` header that is not a loopback name is refused (HTTP
  403), which defeats DNS rebinding.
* **Roles.** One client at a time is the *operator* (the first that asks for control; a take-over
  from another operator is explicit, ``{"type": "control", "take": true, "force": true}``, and logged);
  every other client is a *viewer*: it receives the stream, and only ``ping`` and ``control`` are
  accepted from it.
* **Slow clients.** Each connection has a bounded send queue (``send_queue`` messages); a client
  that stops reading fills it and is dropped, with an event in the log, so it cannot slow the others
  or grow the server's memory.

Every message is validated for type, range and rate before it reaches the simulation.
"""

from __future__ import annotations

import asyncio
import contextlib
import ipaddress
import json
import secrets
import sys
from pathlib import Path
from typing import NamedTuple
from urllib.parse import urlparse

from fastapi import FastAPI, Request, WebSocket, WebSocketDisconnect
from fastapi.responses import FileResponse, JSONResponse, PlainTextResponse, Response
from fastapi.staticfiles import StaticFiles

from .access import Throttle, token_refusal
from .messages import RateLimiter, Rejected, parse_message
from .session import Session

STATIC = Path(__file__).parent / "static"
LOOPBACK_NAMES = ("127.0.0.1", "localhost", "::1")
SEND_QUEUE = 64  #: messages queued per client before it counts as not reading (2.5 s at 25 Hz)


def is_loopback(host: str) -> bool:
    """True for 127.0.0.0/8, ::1 and ``localhost``."""
    if host == "localhost":
        return True
    try:
        return ipaddress.ip_address(host.strip("[]")).is_loopback
    except ValueError:
        return False


def new_token() -> str:
    """A random session token (128 bits, URL-safe)."""
    return secrets.token_urlsafe(16)


class Refusal(NamedTuple):
    """A refused request: HTTP ``status``, ``reason`` (the response body), ``kind`` (``host``,
    ``origin``, ``throttled`` or ``token``: what :class:`~oceangnc.console.access.AccessLog` counts)
    and, for 429, ``retry_after`` seconds."""

    status: int
    reason: str
    kind: str
    retry_after: int = 0


class Guard:
    """The checks of the module docstring, for HTTP requests and WebSocket handshakes alike; failed
    token checks are throttled per peer (:class:`oceangnc.console.access.Throttle`)."""

    def __init__(self, token: str, loopback_only: bool, throttle: Throttle | None = None):
        self.token = token
        self.loopback_only = loopback_only
        self.throttle = throttle if throttle is not None else Throttle()

    def presented_token(self, conn) -> str:
        tok = conn.query_params.get("token") or conn.headers.get("x-oceangnc-token") or ""
        auth = conn.headers.get("authorization", "")
        if not tok and auth.lower().startswith("bearer "):
            tok = auth[7:].strip()
        return tok

    def check(self, conn, need_token: bool = True) -> Refusal | None:
        """None when allowed, else the :class:`Refusal`."""
        host = conn.headers.get("host", "")
        hostname = urlparse("//" + host).hostname or ""
        if self.loopback_only and not is_loopback(hostname):
            return Refusal(403, f"host {host!r} not allowed (the console listens on loopback only)", "host")
        origin = conn.headers.get("origin")
        if origin is not None:
            scheme = conn.url.scheme.replace("ws", "http")
            o = urlparse(origin)
            if origin == "null" or o.netloc != host or o.scheme != scheme:
                return Refusal(403, f"origin {origin!r} not allowed (only pages served by this console)", "origin")
        if need_token:
            peer = conn.client.host if conn.client is not None else "?"
            bad = token_refusal(self.throttle, peer, self.presented_token(conn), self.token)
            if bad is not None:
                status, msg, secs = bad
                if status == 429:
                    return Refusal(429, msg, "throttled", secs)
                return Refusal(401, msg + " (open the URL printed by 'oceangnc console')", "token")
        return None


def _refusal(bad: Refusal) -> PlainTextResponse:
    headers = {"Retry-After": str(bad.retry_after)} if bad.status == 429 else None
    return PlainTextResponse(bad.reason, status_code=bad.status, headers=headers)


def create_app(
    session: Session,
    stream_hz: float = 25.0,
    manage_session: bool = True,
    token: str | None = None,
    loopback_only: bool = True,
    send_queue: int = SEND_QUEUE,
    throttle: Throttle | None = None,
):
    """The ASGI app around a :class:`Session` (started and stopped with the app when ``manage_session``).

    ``token`` is the session token every API request and WebSocket must present (a new random one
    when None: ``app.state.token``); ``loopback_only`` refuses ``Host`` headers that are not loopback;
    ``throttle`` limits failed token checks per peer (default :class:`Throttle`: 20 a minute).
    Refused requests are counted in ``session.access`` (summary events), not logged one by one.
    """

    @contextlib.asynccontextmanager
    async def lifespan(app):
        if manage_session:
            session.start()
        try:
            yield
        finally:
            if manage_session:
                await asyncio.to_thread(session.stop)

    app = FastAPI(title="oceangnc operator console", lifespan=lifespan, docs_url=None, redoc_url=None, openapi_url=None)
    app.mount("/static", StaticFiles(directory=STATIC), name="static")
    app.state.session = session
    app.state.token = token or new_token()
    guard = Guard(app.state.token, loopback_only, throttle)
    app.state.guard = guard

    @app.middleware("http")
    async def security(request: Request, call_next):
        path = request.url.path
        changes = request.method not in ("GET", "HEAD", "OPTIONS")
        # the page and its static files are public; the API and anything that changes state are not
        need_token = path.startswith("/api") or changes
        bad = guard.check(request, need_token=need_token)
        if bad is not None:
            session.access.refused(bad.kind, f"{request.method} {path[:80]}: {bad.reason}")
            return _refusal(bad)
        resp = await call_next(request)
        resp.headers.setdefault("X-Frame-Options", "DENY")
        resp.headers.setdefault("X-Content-Type-Options", "nosniff")
        resp.headers.setdefault("Referrer-Policy", "no-referrer")
        return resp

    @app.get("/")
    def index():
        return FileResponse(STATIC / "index.html", headers={"Cache-Control": "no-store"})

    @app.get("/vendor/{name}")
    def vendor(name: str):  # the 3D panel's modules (three.js, scene3d.js): oceangnc.view.replay.vendor_file
        from ..view.replay import vendor_file

        f = vendor_file(name)
        if f is None:
            return PlainTextResponse("not found", status_code=404)
        return FileResponse(f, media_type="text/javascript")

    @app.get("/api/state")
    def api_state():
        return JSONResponse(session.state())

    @app.get("/api/scenarios")
    def api_scenarios():
        return {"current": session.scenario.name, "live": session.live_scenarios()}

    @app.get("/api/log.parquet")
    def api_log():
        data, name = session.log_bytes()
        return Response(
            data,
            media_type="application/vnd.apache.parquet",
            headers={"Content-Disposition": f'attachment; filename="{name}"'},
        )

    @app.websocket("/ws")
    async def ws_endpoint(ws: WebSocket):
        bad = guard.check(ws)
        if bad is not None:
            session.access.refused(bad.kind, f"WebSocket: {bad.reason}")
            try:
                await ws.send_denial_response(_refusal(bad))
            except RuntimeError:  # server without the denial-response extension
                await ws.close(code=1008, reason=bad.reason[:120])
            return
        await ws.accept()
        want = ws.query_params.get("role", "operator") != "viewer"
        cid, _ = session.attach(want)
        queue: asyncio.Queue = asyncio.Queue(maxsize=send_queue)
        dropped = asyncio.Event()
        limiter = RateLimiter()

        def send(obj) -> None:
            """Queue a message; a full queue means the client stopped reading: drop it."""
            if dropped.is_set():
                return
            text = obj if isinstance(obj, str) else json.dumps(obj, separators=(",", ":"))
            try:
                queue.put_nowait(text)
            except asyncio.QueueFull:
                dropped.set()
                session.event(
                    "warning",
                    f"client #{cid} dropped: it stopped reading ({send_queue} messages "
                    f"queued); the others are not slowed",
                )

        async def sender():
            while True:
                text = await queue.get()
                await ws.send_text(text)

        def role_msg():
            return {"type": "role", "client": cid, "role": session.role(cid), "operator": session.operator}

        async def streamer():
            run = -1
            last_event = 0
            shown_role = None
            period = 1.0 / stream_hz
            loop = asyncio.get_running_loop()
            nxt = loop.time()
            while not dropped.is_set():
                r = (session.role(cid), session.operator)
                if r != shown_role:
                    shown_role = r
                    send(role_msg())
                if session.run_id != run:
                    hello = session.hello_message()
                    run = hello["run"]
                    send(hello)
                st = session.snapshot_json
                evs = session.events_since(last_event)
                if evs:
                    last_event = evs[-1]["id"]
                    st = st[:-1] + ',"events":' + json.dumps(evs, separators=(",", ":")) + "}"
                send(st)
                nxt += period
                delay = nxt - loop.time()
                if delay < -1.0:  # fell far behind (loaded machine): do not burst to catch up
                    nxt = loop.time()
                await asyncio.sleep(max(0.0, delay))

        async def receiver():
            last_reject_note = 0.0
            while True:
                m = await ws.receive()
                if m["type"] == "websocket.disconnect":
                    return
                raw = m.get("text") if m.get("text") is not None else m.get("bytes")
                if raw is None:
                    continue
                try:
                    if not limiter.allow():
                        now = asyncio.get_running_loop().time()
                        if now - last_reject_note < 1.0:
                            continue  # do not answer a flood message by message
                        last_reject_note = now
                        raise Rejected(
                            f"rate limit: more than {limiter.rate:g} messages/s "
                            f"(burst {limiter.burst:g}); message dropped"
                        )
                    msg = parse_message(raw)
                    if msg.type == "ping":
                        send({"type": "pong", "id": msg.id})
                        continue
                    if msg.type == "control":
                        if msg.take:
                            session.take_control(cid, force=msg.force)
                        else:
                            session.release_control(cid)
                        continue
                    if session.role(cid) != "operator":
                        raise Rejected(
                            f"{msg.type}: client #{cid} is a viewer; only the operator can send "
                            f"commands (take control first)"
                        )
                    session.submit(msg)
                except Rejected as e:
                    session.event("warning", f"rejected message from #{cid}: {e}")
                    send({"type": "rejected", "reason": str(e)})

        tasks = [asyncio.create_task(sender()), asyncio.create_task(streamer()), asyncio.create_task(receiver())]
        drop_wait = asyncio.create_task(dropped.wait())
        try:
            await asyncio.wait([tasks[0], tasks[2], drop_wait], return_when=asyncio.FIRST_COMPLETED)
        finally:
            for tk in (*tasks, drop_wait):
                tk.cancel()
            for tk in (*tasks, drop_wait):
                with contextlib.suppress(asyncio.CancelledError, WebSocketDisconnect, Exception):
                    await tk
            if dropped.is_set():
                with contextlib.suppress(Exception):
                    await asyncio.wait_for(ws.close(code=1013, reason="not reading: dropped"), 1.0)
            session.detach(cid)

    return app


def serve(
    session: Session,
    host: str = "127.0.0.1",
    port: int = 8050,
    stream_hz: float = 25.0,
    log_level: str = "warning",
    ready=None,
    token: str | None = None,
    ssl_certfile: str | None = None,
    ssl_keyfile: str | None = None,
):
    """Run the console on uvicorn until interrupted (blocking). ``ready`` is called once listening.

    ``ssl_certfile`` / ``ssl_keyfile`` (PEM) serve HTTPS and WSS through uvicorn's TLS options."""
    import uvicorn

    app = create_app(session, stream_hz=stream_hz, token=token, loopback_only=is_loopback(host))
    config = uvicorn.Config(
        app,
        host=host,
        port=port,
        log_level=log_level,
        ws_max_size=1 << 20,
        lifespan="on",
        access_log=False,
        ssl_certfile=ssl_certfile,
        ssl_keyfile=ssl_keyfile,
    )
    server = uvicorn.Server(config)
    sock = listen_socket(host, port)
    if ready is not None:
        orig = server.startup

        async def startup(sockets=None):
            await orig(sockets=sockets)
            ready(server, app)

        server.startup = startup
    server.run(sockets=[sock])
    return server


#: kernel send buffer of each connection (inherited from the listening socket): small enough that a
#: client that stops reading fills its send queue within seconds (and is dropped), far above the
#: 25 Hz stream's need (~50 kB/s)
SNDBUF = 128 * 1024


def listen_socket(host: str, port: int):
    """The listening socket, with a bounded per-connection send buffer (:data:`SNDBUF`)."""
    import socket

    fam = socket.AF_INET6 if ":" in host else socket.AF_INET
    sock = socket.socket(fam, socket.SOCK_STREAM)
    sock.setsockopt(socket.SOL_SOCKET, socket.SO_REUSEADDR, 1)
    sock.setsockopt(socket.SOL_SOCKET, socket.SO_SNDBUF, SNDBUF)
    sock.bind((host, port))
    sock.listen(128)
    sock.set_inheritable(True)
    return sock


def console_url(host: str, port: int, token: str, tls: bool = False) -> str:
    """The URL to open: on the address bound (``127.0.0.2`` stays ``127.0.0.2``), a loopback one for a
    wildcard binding (``0.0.0.0`` -> ``127.0.0.1``, ``::`` -> ``[::1]``; never a wildcard address)."""
    if host in ("0.0.0.0", "localhost"):
        shown = "127.0.0.1"
    elif host == "::":
        shown = "[::1]"
    elif ":" in host:
        shown = f"[{host}]"
    else:
        shown = host
    return f"{'https' if tls else 'http'}://{shown}:{port}/?token={token}"


def main_banner(host: str, port: int, session: Session, token: str, tls: bool = False) -> None:
    url = console_url(host, port, token, tls)
    print(f"oceangnc console: scenario {session.scenario.name} at {session.speed:g}x real time; open {url}", flush=True)
    if host in ("0.0.0.0", "::"):
        loop = "127.0.0.1" if host == "0.0.0.0" else "[::1]"
        print(
            f"note: listening on every {'IPv4 ' if host == '0.0.0.0' else ''}interface ({host}); the URL above "
            f"is this machine's loopback, from another machine replace {loop} with this machine's address",
            file=sys.stderr,
            flush=True,
        )
    if not is_loopback(host):
        print(
            f"note: listening on {host}: anyone who can reach it and holds the token can watch; the first "
            f"to take control drives{'' if tls else ' (no TLS: the token crosses the network in clear)'}",
            file=sys.stderr,
            flush=True,
        )
