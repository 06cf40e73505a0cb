"""The HTTP server of ``oceangnc view --serve``: the replay page on 127.0.0.1, as careful as the console.

Before issue 41 it answered any ``Host`` header, so a web page could read a run's whole data by DNS
rebinding (a name of the attacker's that resolves to 127.0.0.1 after the page loaded), and it started
a thread per connection with no time limit: 400 slow clients held 400 threads. Now (docs/view.md,
docs/reliability.md):

* **Host.** A request whose ``Host`` is not a loopback name (``127.0.0.0/8``, ``[::1]``, ``localhost``)
  is refused with HTTP 403, which defeats DNS rebinding (the console's rule,
  :class:`oceangnc.console.server.Guard`).
* **Origin.** A request that carries an ``Origin`` header must come from the page's own origin
  (``http://`` + its ``Host``), else HTTP 403.
* **Threads.** At most ``max_clients`` connections are served at once (default 16); a connection
  beyond them is answered HTTP 503 and closed at once, in the accepting thread, without a thread.
* **Idle time.** A connection that sends nothing for ``idle_s`` seconds (default 10) is closed.

Only three paths answer: ``/`` (also ``/index.html``, ``/replay.html``) and the two vendor files.
"""

from __future__ import annotations

import ipaddress
import threading
from http.server import BaseHTTPRequestHandler, ThreadingHTTPServer
from urllib.parse import urlparse

MAX_CLIENTS = 16  #: connections served at once
IDLE_S = 10.0  #: seconds a connection may stay silent


def loopback_host(host: str) -> bool:
    """True when the ``Host`` header ``host`` (with or without a port) names the loopback interface."""
    name = urlparse("//" + host).hostname or ""
    if name == "localhost":
        return True
    try:
        return ipaddress.ip_address(name).is_loopback
    except ValueError:
        return False


def refusal(headers) -> str | None:
    """The reason a request with ``headers`` is refused (module docstring), or None."""
    host = headers.get("Host", "")
    if not loopback_host(host):
        return f"host {host!r} not allowed (the replay server listens on loopback only)"
    origin = headers.get("Origin")
    if origin is not None and (origin == "null" or urlparse(origin).netloc != host or not origin.startswith("http:")):
        return f"origin {origin!r} not allowed (only the replay page itself)"
    return None


class _Server(ThreadingHTTPServer):
    daemon_threads = True
    request_queue_size = 128  # the listen backlog: a burst is answered (503 past the bound), not left to retry SYNs

    def __init__(self, addr, handler, max_clients: int):
        super().__init__(addr, handler)
        self.slots = threading.BoundedSemaphore(max_clients)

    def process_request(self, request, client_address):
        if not self.slots.acquire(blocking=False):  # full: answer and close here, no thread
            try:
                request.sendall(b"HTTP/1.0 503 Service Unavailable\r\nContent-Length: 0\r\nRetry-After: 1\r\n\r\n")
            except OSError:
                pass
            self.shutdown_request(request)
            return
        super().process_request(request, client_address)

    def process_request_thread(self, request, client_address):
        try:
            super().process_request_thread(request, client_address)
        finally:
            self.slots.release()


def make_server(files, port: int, max_clients: int = MAX_CLIENTS, idle_s: float = IDLE_S) -> ThreadingHTTPServer:
    """The server on 127.0.0.1:``port`` (0: any free port). ``files(path)`` gives ``(body, content type)``
    for a request path (without its query), or None for 404."""

    class Handler(BaseHTTPRequestHandler):
        timeout = idle_s  # the socket's timeout: a silent client is dropped

        def do_GET(self):  # noqa: N802 (http.server's name)
            why = refusal(self.headers)
            if why is not None:
                self.send_error(403, why)
                return
            found = files(self.path.split("?", 1)[0])
            if found is None:
                self.send_error(404)
                return
            body, ctype = found
            self.send_response(200)
            self.send_header("Content-Type", ctype)
            self.send_header("Content-Length", str(len(body)))
            self.send_header("Cache-Control", "no-store")
            self.send_header("X-Content-Type-Options", "nosniff")
            self.end_headers()
            self.wfile.write(body)

        def log_message(self, fmt, *args):
            pass

    return _Server(("127.0.0.1", port), Handler, max_clients)
