"""The throttle of failed session tokens never locks the operator out (issue 41).

Every local user shares 127.0.0.1, so the throttle's peer is everybody on the machine. Before the fix
a local process sending 5 wrong tokens a second emptied that peer's bucket, and an empty bucket refused
the right token too: the operator reconnected 0 times in 30 tries. Now the right token always gets
through and only the failures are slowed (HTTP 429), on the console and on the MAVLink vehicle's live
Foxglove stream alike. The clock is a fake one: 30 s of guessing run in milliseconds.
"""

from __future__ import annotations

from types import SimpleNamespace

import pytest
from fastapi.testclient import TestClient

from oceangnc.console.access import Throttle
from oceangnc.console.server import create_app
from oceangnc.console.session import Session

TOKEN = "sec-token-42xyz"


class FakeClock:
    def __init__(self):
        self.t = 1000.0

    def __call__(self):
        return self.t


def _guess_and_reconnect(clk, guess, reconnect) -> tuple[list[int], int]:
    """30 s of a guesser at 5 wrong tokens a second, the operator reconnecting once a second with the right
    token: (the guesser's statuses, how many of the operator's 30 tries got through)."""
    statuses, through = [], 0
    for _second in range(30):
        for _ in range(5):
            statuses.append(guess())
            clk.t += 0.2
        through += reconnect()
    return statuses, through


def test_a_local_guesser_does_not_lock_the_console_operator_out(tmp_path):
    clk = FakeClock()
    s = Session("usv-remote", out_root=tmp_path, write_log=False)
    s.access.clock = clk
    with TestClient(
        create_app(s, token=TOKEN, throttle=Throttle(20, 60.0, clock=clk)), base_url="http://127.0.0.1"
    ) as c:

        def reconnect() -> int:
            with c.websocket_connect(f"ws://127.0.0.1/ws?token={TOKEN}") as ws:
                return int(ws.receive_json()["type"] == "role")

        statuses, through = _guess_and_reconnect(
            clk, lambda: c.get("/api/state?token=wrong-guess").status_code, reconnect
        )
        assert through == 30  # was 0 of 30
        assert c.get(f"/api/state?token={TOKEN}").status_code == 200
    # the failures are still slowed: 20 at once, then one back every 3 s (30 s: 10 more), the rest 429
    assert statuses[:20] == [401] * 20
    assert set(statuses) == {401, 429}
    assert 29 <= statuses.count(401) <= 31
    assert s.access.by_kind["throttled"] == statuses.count(429)


class _Conn:
    remote_address = ("127.0.0.1", 50000)

    @staticmethod
    def respond(status: int, text: str):
        return SimpleNamespace(status_code=status, body=text, headers={})


def test_a_local_guesser_does_not_lock_the_foxglove_stream_out():
    """The live stream of ``oceangnc mavlink --foxglove`` checks the token at the WebSocket handshake
    (:meth:`~oceangnc.view.foxglove_ws.FoxgloveRunServer.process_request`): the same rule."""
    pytest.importorskip("websockets", reason="websockets is not installed")
    from oceangnc.view.foxglove_ws import FoxgloveLiveServer

    clk = FakeClock()
    srv = FoxgloveLiveServer([], token=TOKEN)
    srv._throttle = Throttle(20, 60.0, clock=clk)

    def handshake(path: str, headers: dict | None = None):
        return srv.process_request(_Conn(), SimpleNamespace(path=path, headers=headers or {}))

    def guess() -> int:
        return handshake("/?token=wrong-guess").status_code

    def reconnect() -> int:
        return int(handshake(f"/?token={TOKEN}") is None)

    statuses, through = _guess_and_reconnect(clk, guess, reconnect)
    assert through == 30  # was 0 of 30
    assert handshake("/", {"Authorization": f"Bearer {TOKEN}"}) is None
    assert statuses[:20] == [401] * 20 and set(statuses) == {401, 429}
    assert 29 <= statuses.count(401) <= 31
    refused = [handshake("/?token=x") for _ in range(2)][-1]  # (the last second may have given a try back)
    assert refused.status_code == 429 and int(refused.headers["Retry-After"]) >= 1
