"""The console's web server: FastAPI on uvicorn, one WebSocket per page, static files, log download.

Routes
------
``GET /``                 the console page (``static/index.html``)
``GET /static/...``       its script and style sheet
``GET /api/state``        the latest state message (JSON), for scripts and health checks
``GET /api/scenarios``    the scenarios that run live
``GET /api/log.parquet``  the current run's log, same Parquet format as ``oceangnc run``
``WS  /ws``               state stream (``hello`` on connect and on every new run, then ``state``
                          messages at ``stream_hz``, with new events attached) and commands back
                          (:mod:`oceangnc.console.messages`); a rejected command gets
                          ``{"type": "rejected", "reason": ...}``.

Safety: the server binds to 127.0.0.1 unless told otherwise; a WebSocket whose ``Origin`` header
names another host than the page's is refused (another web site open in the same browser cannot
drive the vehicle); every message is validated for type, range and rate before it reaches the
simulation.
"""

from __future__ import annotations

import asyncio
import contextlib
import json
import sys
from pathlib import Path
from urllib.parse import urlparse

from fastapi import FastAPI, WebSocket, WebSocketDisconnect
from fastapi.responses import FileResponse, JSONResponse, Response
from fastapi.staticfiles import StaticFiles

from .messages import RateLimiter, Rejected, parse_message
from .session import Session

STATIC = Path(__file__).parent / "static"


def create_app(session: Session, stream_hz: float = 25.0, manage_session: bool = True):
    """The ASGI app around a :class:`Session` (started and stopped with the app when ``manage_session``)."""
    @contextlib.asynccontextmanager
    async def lifespan(app):
        if manage_session:
            session.start()
        try:
            yield
        finally:
            if manage_session:
                await asyncio.to_thread(session.stop)

    app = FastAPI(title="oceangnc operator console", lifespan=lifespan, docs_url=None, redoc_url=None)
    app.mount("/static", StaticFiles(directory=STATIC), name="static")
    app.state.session = session

    @app.get("/")
    def index():
        return FileResponse(STATIC / "index.html", headers={"Cache-Control": "no-store"})

    @app.get("/api/state")
    def api_state():
        return JSONResponse(session.state())

    @app.get("/api/scenarios")
    def api_scenarios():
        return {"current": session.scenario.name, "live": session.live_scenarios()}

    @app.get("/api/log.parquet")
    def api_log():
        data, name = session.log_bytes()
        return Response(data, media_type="application/vnd.apache.parquet",
                        headers={"Content-Disposition": f'attachment; filename="{name}"'})

    @app.websocket("/ws")
    async def ws_endpoint(ws: WebSocket):
        origin = ws.headers.get("origin")
        host = ws.headers.get("host", "")
        if origin and urlparse(origin).netloc != host:
            await ws.close(code=1008, reason="origin not allowed")
            return
        await ws.accept()
        send_lock = asyncio.Lock()
        limiter = RateLimiter()
        session.client_connected()

        async def send(obj):
            text = obj if isinstance(obj, str) else json.dumps(obj, separators=(",", ":"))
            async with send_lock:
                await ws.send_text(text)

        async def streamer():
            run = -1
            last_event = 0
            period = 1.0 / stream_hz
            loop = asyncio.get_running_loop()
            nxt = loop.time()
            while True:
                if session.run_id != run:
                    hello = session.hello_message()
                    run = hello["run"]
                    await send(hello)
                st = session.snapshot_json
                evs = session.events_since(last_event)
                if evs:
                    last_event = evs[-1]["id"]
                    st = st[:-1] + ',"events":' + json.dumps(evs, separators=(",", ":")) + "}"
                await send(st)
                nxt += period
                delay = nxt - loop.time()
                if delay < -1.0:  # fell far behind (loaded machine): do not burst to catch up
                    nxt = loop.time()
                await asyncio.sleep(max(0.0, delay))

        task = asyncio.create_task(streamer())
        last_reject_note = 0.0
        try:
            while True:
                m = await ws.receive()
                if m["type"] == "websocket.disconnect":
                    break
                raw = m.get("text") if m.get("text") is not None else m.get("bytes")
                if raw is None:
                    continue
                try:
                    if not limiter.allow():
                        now = asyncio.get_running_loop().time()
                        if now - last_reject_note < 1.0:
                            continue  # do not answer a flood message by message
                        last_reject_note = now
                        raise Rejected(f"rate limit: more than {limiter.rate:g} messages/s "
                                       f"(burst {limiter.burst:g}); message dropped")
                    msg = parse_message(raw)
                    if msg.type == "ping":
                        await send({"type": "pong", "id": msg.id})
                        continue
                    session.submit(msg)
                except Rejected as e:
                    session.event("warning", f"rejected message: {e}")
                    await send({"type": "rejected", "reason": str(e)})
        except WebSocketDisconnect:
            pass
        finally:
            task.cancel()
            with contextlib.suppress(asyncio.CancelledError, Exception):
                await task
            session.client_disconnected()

    return app


def serve(session: Session, host: str = "127.0.0.1", port: int = 8050, stream_hz: float = 25.0,
          log_level: str = "warning", ready=None):
    """Run the console on uvicorn until interrupted (blocking). ``ready`` is called once listening."""
    import uvicorn

    app = create_app(session, stream_hz=stream_hz)
    config = uvicorn.Config(app, host=host, port=port, log_level=log_level, ws_max_size=1 << 20,
                            lifespan="on", access_log=False)
    server = uvicorn.Server(config)
    if ready is not None:
        orig = server.startup

        async def startup(sockets=None):
            await orig(sockets=sockets)
            ready(server)

        server.startup = startup
    server.run()
    return server


def main_banner(host: str, port: int, session: Session) -> None:
    url = f"http://{host}:{port}/"
    print(f"oceangnc console: scenario {session.scenario.name} at {session.speed:g}x real time; open {url}",
          flush=True)
    if host not in ("127.0.0.1", "localhost", "::1"):
        print(f"warning: listening on {host}: the console has no authentication, anyone who can reach "
              f"this address can drive the vehicle", file=sys.stderr, flush=True)
