"""``oceangnc view --serve`` is as careful as the console (issue 41).

Before: any ``Host`` header was answered (a web page could read a run's data by DNS rebinding), any
``Origin`` too, and each connection got a thread with no time limit (400 slow clients, 400 threads).
The server of :mod:`oceangnc.view.replay_server` is run here on a page of its own (no run folder needed):
foreign Host and Origin get 403, connections beyond the bound get 503 without a thread, and a silent
client is dropped after the idle time, after which the page is served again.
"""

from __future__ import annotations

import http.client
import socket
import threading

import pytest

from oceangnc.view.replay_server import make_server, refusal

PAGE = b"<html>replay</html>"


@pytest.fixture
def server():
    httpd = make_server(lambda p: (PAGE, "text/html") if p == "/" else None, 0, max_clients=4, idle_s=3.0)
    t = threading.Thread(target=httpd.serve_forever, daemon=True)
    t.start()
    yield httpd
    httpd.shutdown()
    httpd.server_close()


def get(port: int, headers: dict | None = None, path: str = "/") -> tuple[int, bytes]:
    c = http.client.HTTPConnection("127.0.0.1", port, timeout=30)
    c.putrequest("GET", path, skip_host=True)
    for k, v in (headers if headers is not None else {"Host": f"127.0.0.1:{port}"}).items():
        c.putheader(k, v)
    c.endheaders()
    r = c.getresponse()
    body = r.read()
    c.close()
    return r.status, body


def test_foreign_host_and_origin_are_refused(server):
    port = server.server_address[1]
    assert get(port) == (200, PAGE)
    assert get(port, {"Host": f"localhost:{port}"}) == (200, PAGE)
    assert get(port, {"Host": f"[::1]:{port}"})[0] == 200
    assert get(port, {"Host": f"rebind.attacker.example:{port}"})[0] == 403  # DNS rebinding (was 200)
    assert get(port, {"Host": "10.0.0.5"})[0] == 403
    assert get(port, {})[0] == 403  # no Host at all
    ok = f"http://127.0.0.1:{port}"
    assert get(port, {"Host": f"127.0.0.1:{port}", "Origin": ok})[0] == 200
    for origin in ("http://attacker.example", "null", f"https://127.0.0.1:{port}", "http://127.0.0.1:1"):
        assert get(port, {"Host": f"127.0.0.1:{port}", "Origin": origin})[0] == 403, origin
    assert get(port, path="/log.parquet")[0] == 404


def test_refusal_names_the_host():
    assert "rebind.example" in refusal({"Host": "rebind.example:8060"})
    assert refusal({"Host": "127.0.0.1:8060"}) is None


def test_slow_clients_are_bounded_and_dropped_when_idle(server):
    port = server.server_address[1]
    before = threading.active_count()
    slow = [socket.create_connection(("127.0.0.1", port), timeout=30) for _ in range(40)]
    try:
        # the 5th to 40th connections are answered 503 and closed at once, in the accepting thread
        assert all(s.recv(200).startswith(b"HTTP/1.0 503") for s in slow[4:])
        assert threading.active_count() - before <= 4  # was one thread per slow client (40)
        # the 4 served ones said nothing: dropped after the idle time (3 s here), without an answer
        for s in slow[:4]:
            assert s.recv(200) == b""
    finally:
        for s in slow:
            s.close()
    assert get(port) == (200, PAGE)  # the page is served again
