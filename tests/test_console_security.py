"""Who can drive the console (issue 20): token, Origin and Host checks, operator and viewer roles,
strict message types, e-stop hold and bumpless resume, warm-up, CLI binding rules."""

from __future__ import annotations

import json
import time

import pytest
from fastapi.testclient import TestClient
from starlette.testclient import WebSocketDenialResponse

from oceangnc.console.messages import Rejected, parse_message
from oceangnc.console.access import AccessLog, Throttle
from oceangnc.console.server import console_url, create_app, main_banner
from oceangnc.core.files import read_json_lines
from oceangnc.console.session import Session
from oceangnc.units import KGF

TOKEN = "sec-token-42xyz"
WS = f"ws://127.0.0.1/ws?token={TOKEN}"


@pytest.fixture
def app_client(tmp_path):
    s = Session("usv-remote", out_root=tmp_path, write_log=False)
    with TestClient(create_app(s, token=TOKEN), base_url="http://127.0.0.1") as client:
        client.session = s
        yield client


def recv_until(ws, pred, limit=400):
    for _ in range(limit):
        m = ws.receive_json()
        if pred(m):
            return m
    raise AssertionError("message not received")


def test_every_api_request_and_websocket_needs_the_token(app_client):
    c = app_client
    assert c.get("/api/state").status_code == 401
    assert c.get("/api/state?token=wrong").status_code == 401
    assert c.get("/api/log.parquet").status_code == 401
    assert c.get(f"/api/state?token={TOKEN}").status_code == 200
    assert c.get("/api/state", headers={"authorization": f"Bearer {TOKEN}"}).status_code == 200
    assert c.get("/").status_code == 200  # the page itself is public; it carries no data
    for url in ("ws://127.0.0.1/ws", "ws://127.0.0.1/ws?token=nope"):
        with pytest.raises(WebSocketDenialResponse) as e, c.websocket_connect(url):
            pass
        assert e.value.status_code == 401 and "session token" in e.value.text


def test_foreign_origin_and_foreign_host_are_refused_with_403(app_client):
    c = app_client
    for origin in ("http://evil.example", "http://127.0.0.1:9999", "null", "https://127.0.0.1"):
        with pytest.raises(WebSocketDenialResponse) as e, c.websocket_connect(WS, headers={"origin": origin}):
            pass
        assert e.value.status_code == 403 and "not allowed" in e.value.text
        r = c.get(f"/api/state?token={TOKEN}", headers={"origin": origin})
        assert r.status_code == 403
    # a state-changing method from another origin, or without the token
    assert c.post(f"/api/state?token={TOKEN}", headers={"origin": "http://evil.example"}).status_code == 403
    assert c.post("/api/state").status_code == 401
    # DNS rebinding: a page of evil.example resolved to 127.0.0.1 sends Host: evil.example
    r = c.get(f"/api/state?token={TOKEN}", headers={"host": "evil.example:8050", "origin": "http://evil.example:8050"})
    assert r.status_code == 403 and "host" in r.text
    # the page's own origin, and scripts that send no Origin, are accepted (with the token)
    with c.websocket_connect(WS, headers={"origin": "http://127.0.0.1"}) as ws:
        assert ws.receive_json()["type"] == "role"
    with c.websocket_connect(WS) as ws:
        assert ws.receive_json()["type"] == "role"
    # counted, not logged one by one: one summary (the first refusal) in its own history, none in the
    # operators' one
    acc = c.session.access
    assert acc.by_kind["origin"] == 9 and acc.by_kind["host"] == 1 and acc.by_kind["token"] == 1
    assert not [e for e in c.session.events if e["text"].startswith("refused")]
    first = c.session.access_events[0]["text"]
    assert first.startswith("refused 1 request(s)") and "origin 'http://evil.example' not allowed" in first


def test_viewer_cannot_command_and_take_over_is_explicit_and_logged(app_client):
    c, s = app_client, app_client.session
    with c.websocket_connect(WS) as op, c.websocket_connect(WS + "&role=viewer") as viewer:
        r_op = op.receive_json()
        r_v = viewer.receive_json()
        assert r_op["role"] == "operator" and r_v["role"] == "viewer" and r_v["operator"] == r_op["client"]
        viewer.send_text(json.dumps({"type": "estop", "engaged": True}))
        rej = recv_until(viewer, lambda m: m["type"] == "rejected")
        assert "is a viewer; only the operator can send commands" in rej["reason"]
        viewer.send_text(json.dumps({"type": "control", "take": True}))  # without force: refused
        rej = recv_until(viewer, lambda m: m["type"] == "rejected")
        assert f"operator #{r_op['client']} holds control" in rej["reason"]
        viewer.send_text(json.dumps({"type": "ping", "id": 5}))  # viewers may ping
        assert recv_until(viewer, lambda m: m["type"] == "pong")["id"] == 5
        time.sleep(0.3)
        assert s.estop is False and s.operator == r_op["client"]
        viewer.send_text(json.dumps({"type": "control", "take": True, "force": True}))
        assert recv_until(viewer, lambda m: m["type"] == "role")["role"] == "operator"
        assert recv_until(op, lambda m: m["type"] == "role")["role"] == "viewer"
        assert any(
            e["level"] == "alarm"
            and f"TAKE-OVER: client #{r_v['client']} took control from operator #{r_op['client']}" in e["text"]
            for e in s.events
        )
        op.send_text(json.dumps({"type": "mode", "mode": "remote"}))
        assert "is a viewer" in recv_until(op, lambda m: m["type"] == "rejected")["reason"]
        viewer.send_text(json.dumps({"type": "estop", "engaged": True}))
        recv_until(viewer, lambda m: m["type"] == "state" and m["estop"])
    assert s.operator is None and s.clients == 0


def test_a_rejected_gain_is_logged_once(app_client):
    c, s = app_client, app_client.session
    with c.websocket_connect(WS) as ws:
        ws.send_text(json.dumps({"type": "gains", "gains": {"usv_pilot.speed_kp": 1e9}}))
        recv_until(ws, lambda m: m["type"] == "rejected")
        time.sleep(0.2)
    assert sum("usv_pilot.speed_kp" in e["text"] for e in s.events) == 1


@pytest.mark.parametrize(
    "raw",
    [
        '{"type": "stick", "surge": true, "yaw": 0}',
        '{"type": "stick", "surge": "0.5", "yaw": 0}',
        '{"type": "stick", "surge": 0.5, "yaw": "1"}',
        '{"type": "estop", "engaged": 1}',
        '{"type": "estop", "engaged": "true"}',
        '{"type": "pause", "paused": 0}',
        '{"type": "mode", "mode": 1}',
        '{"type": "waypoints", "points": [["1", 2]]}',
        '{"type": "waypoints", "points": [[1, 2, 3]]}',
        '{"type": "gains", "gains": {"usv_pilot.speed_kp": "800"}}',
        '{"type": "ping", "id": 1.5}',
        '{"type": "control", "take": 1}',
    ],
)
def test_message_fields_are_strictly_typed(raw):
    with pytest.raises(Rejected):
        parse_message(raw)


def test_integers_still_count_as_numbers():
    assert parse_message('{"type": "stick", "surge": 1, "yaw": 0}').surge == 1.0
    assert parse_message('{"type": "waypoints", "points": [[1, 2]]}').points == [(1.0, 2.0)]


class FakeClock:
    def __init__(self):
        self.t = 1000.0

    def __call__(self):
        return self.t


def test_estop_holds_integrators_and_reset_ramps_thrust_without_a_step(tmp_path):
    """003's combined vehicle cruising on autopilot: e-stop 10 s, reset. Before the fix the speed PID
    integrated the growing speed error while the thrusters were held at zero, so Reset gave full
    thrust at once (36.2 kgf) and a speed overshoot."""
    clk = FakeClock()
    s = Session("combined-survey", out_root=tmp_path, clock=clk, write_log=False)
    s.client_connected()

    def adv(sec, rec=None):
        for _ in range(round(sec / 0.05)):
            clk.t += 0.05
            s.step_once()
            if rec is not None:
                rec.append((s.sim.t, s.sim.bus["usv.thrust_port"], s.sim.bus["usv.u"]))

    try:
        adv(25.0)
        ctrl = next(b for b in s.sim.blocks if b.name == "usv_control")
        u_cruise = s.sim.bus["usv.u"]
        s.submit(parse_message('{"type": "estop", "engaged": true}'))
        adv(0.05)
        i_stop = ctrl.speed.integral
        adv(10.0)
        assert s.sim.bus["usv.thrust_port"] == 0.0
        assert ctrl.speed.integral == i_stop  # held, not wound up by the 10 s of speed error
        assert s.sim.bus["usv.u"] < 0.5 * u_cruise  # the boat did slow down
        s.submit(parse_message('{"type": "estop", "engaged": false}'))
        rec: list = []
        adv(30.0, rec)
    finally:
        s.stop()
    t_max = 36.2 * KGF
    thrust = [r[1] for r in rec]
    steps = [abs(b - a) for a, b in zip([0.0, *thrust[:-1]], thrust)]
    assert thrust[0] < 0.1 * t_max  # no step at Reset ...
    assert max(steps[:40]) < 0.1 * t_max  # ... and a ramp, not a jump, over the next 2 s
    assert max(thrust) > 0.5 * t_max  # the autopilot does drive again
    assert max(r[2] for r in rec) < 1.05 * u_cruise  # no speed overshoot above the cruise speed


def test_warmup_compiles_before_the_first_page(tmp_path):
    s = Session("usv-remote", out_root=tmp_path, write_log=False)
    took = s.warmup()
    assert took > 0 and s.sim.t == 0.0  # the live run itself has not moved
    s.mode = "remote"
    t0 = time.perf_counter()
    s.sim.run(1.0)
    assert time.perf_counter() - t0 < 1.0  # no compilation left on the first second of the live run


def test_console_url_is_the_bound_address_or_loopback_never_wildcard(capsys):
    assert console_url("0.0.0.0", 8050, "tok") == "http://127.0.0.1:8050/?token=tok"
    assert console_url("127.0.0.1", 8050, "tok", tls=True) == "https://127.0.0.1:8050/?token=tok"
    assert console_url("::", 8050, "t") == "http://[::1]:8050/?token=t"
    assert console_url("192.168.1.5", 9000, "t") == "http://192.168.1.5:9000/?token=t"
    # another loopback address: the URL names it (127.0.0.1 has nothing listening; issue 26)
    assert console_url("127.0.0.2", 8050, "t") == "http://127.0.0.2:8050/?token=t"
    assert console_url("::1", 8050, "t") == "http://[::1]:8050/?token=t"
    assert console_url("localhost", 8050, "t") == "http://127.0.0.1:8050/?token=t"

    class _S:
        scenario = type("Sc", (), {"name": "usv-remote"})
        speed = 1.0

    main_banner("0.0.0.0", 8050, _S(), "t")
    out = capsys.readouterr()
    assert "open http://127.0.0.1:8050/?token=t" in out.out
    assert "every IPv4 interface (0.0.0.0)" in out.err and "replace 127.0.0.1 with this machine's address" in out.err
    main_banner("127.0.0.2", 8050, _S(), "t")
    out = capsys.readouterr()
    assert "open http://127.0.0.2:8050/?token=t" in out.out and out.err == ""


def test_cli_refuses_a_network_binding_without_token_or_allow_remote(capsys):
    from oceangnc.cli import main

    assert main(["console", "--host", "0.0.0.0"]) == 2
    err = capsys.readouterr().err
    assert "--host 0.0.0.0" in err and "--token" in err and "--allow-remote" in err and "\n" not in err.strip()
    assert main(["console", "--token", "short"]) == 2
    assert "at least 8" in capsys.readouterr().err
    assert main(["console", "--ssl-certfile", "/nonexistent.pem"]) == 2
    assert "go together" in capsys.readouterr().err


def test_tls_serves_https_with_the_token_url(tmp_path):
    """``--ssl-certfile/--ssl-keyfile``: uvicorn's TLS; the printed URL is https on loopback."""
    import os
    import shutil
    import socket
    import subprocess
    import sys

    import httpx

    if shutil.which("openssl") is None:
        pytest.skip("no openssl binary to make a test certificate")
    key, cert = tmp_path / "key.pem", tmp_path / "cert.pem"
    subprocess.run(
        [
            "openssl",
            "req",
            "-x509",
            "-newkey",
            "rsa:2048",
            "-nodes",
            "-keyout",
            str(key),
            "-out",
            str(cert),
            "-days",
            "2",
            "-subj",
            "/CN=127.0.0.1",
            "-addext",
            "subjectAltName=IP:127.0.0.1",
        ],
        check=True,
        capture_output=True,
        timeout=60,
    )
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        port = s.getsockname()[1]
    proc = subprocess.Popen(
        [
            sys.executable,
            "-m",
            "oceangnc.cli",
            "console",
            "usv-remote",
            "--port",
            str(port),
            "--out",
            str(tmp_path / "runs"),
            "--token",
            TOKEN,
            "--ssl-certfile",
            str(cert),
            "--ssl-keyfile",
            str(key),
            "--no-warmup",
        ],
        stdout=subprocess.PIPE,
        stderr=subprocess.STDOUT,
        text=True,
        env=dict(os.environ, PYTHONUNBUFFERED="1"),
    )
    try:
        line = ""
        deadline = time.monotonic() + 90
        while "open " not in line and time.monotonic() < deadline:
            line = proc.stdout.readline()
            assert line or proc.poll() is None, "console exited"
        assert f"open https://127.0.0.1:{port}/?token={TOKEN}" in line
        r = httpx.get(f"https://127.0.0.1:{port}/api/state", params={"token": TOKEN}, verify=str(cert), timeout=10)
        assert r.status_code == 200 and r.json()["type"] == "state"
        with pytest.raises(httpx.HTTPError):
            httpx.get(f"http://127.0.0.1:{port}/api/state", params={"token": TOKEN}, timeout=5)
    finally:
        proc.terminate()
        proc.wait(timeout=20)


# -- refused requests counted, not stored; failed tokens throttled (issue 26) ---------------------------------


def test_a_tokenless_flood_cannot_push_the_take_over_alarm_out(tmp_path):
    """Before: each refused request was an event in the 1,000-entry history, and 1,100 tokenless
    requests pushed a take-over alarm out of it (it was saved nowhere else)."""
    clk = FakeClock()
    s = Session("usv-remote", out_root=tmp_path)
    s.access.clock = clk  # the summary interval and the throttle's window do not pass during the flood
    with TestClient(
        create_app(s, token=TOKEN, throttle=Throttle(20, 60.0, clock=clk)), base_url="http://127.0.0.1"
    ) as c:
        with c.websocket_connect(WS) as op, c.websocket_connect(WS + "&role=viewer") as viewer:
            op.receive_json()
            viewer.receive_json()
            viewer.send_text(json.dumps({"type": "control", "take": True, "force": True}))
            assert recv_until(viewer, lambda m: m["type"] == "role")["role"] == "operator"
        assert any(e["text"].startswith("TAKE-OVER") for e in s.events)
        codes = [c.get("/api/state").status_code for _ in range(1100)]
        codes += [c.get("/api/state?token=wrong-guess").status_code for _ in range(20)]
        # throttled: 20 failed tokens from this peer, then 429 for every request needing the token ...
        assert codes[:20] == [401] * 20 and set(codes[20:]) == {429}
        r = c.get("/api/state?token=another-guess")
        assert r.status_code == 429 and r.headers["retry-after"] == "3"
        # ... but the right token always gets through (issue 41: the throttle slows the failures only)
        assert c.get(f"/api/state?token={TOKEN}").status_code == 200
        assert c.get("/").status_code == 200  # the public page is not throttled
        clk.t += 60.0  # the window has passed: the right token works, a wrong one is refused again
        s.access.flush()  # (the session's loop does this too) the interval is over: one summary
        r = c.get(f"/api/state?token={TOKEN}")
        assert r.status_code == 200
        assert c.get("/api/state?token=nope").status_code == 401
        # the operators' history still holds the alarm, and a page connecting now is shown it
        assert any(e["text"].startswith("TAKE-OVER") for e in s.events)
        assert not any(e["text"].startswith("refused") for e in s.events)
        assert s.access.total == 1122 and s.access.by_kind == {"token": 21, "throttled": 1101}
        with c.websocket_connect(WS) as ws:
            st = recv_until(ws, lambda m: m["type"] == "state" and "events" in m)
            texts = [e["text"] for e in st["events"]]
            assert any(t.startswith("TAKE-OVER") for t in texts)
            assert sum(t.startswith("refused") for t in texts) == 2  # the first refusal, then one per interval
    # the run folder: the alarm and the refusal summaries in events.jsonl (the last one at shut-down)
    (run,) = tmp_path.iterdir()
    lines = read_json_lines(run / "events.jsonl")
    assert any(e["level"] == "alarm" and e["text"].startswith("TAKE-OVER") for e in lines)
    acc = [e for e in lines if e.get("kind") == "access"]
    assert len(acc) == 3, [e["text"] for e in acc]  # at most one per interval, the rest at shut-down
    assert acc[0]["text"].startswith("refused 1 request(s) just now: 1 x token (GET /api/state: missing")
    assert acc[1]["text"].startswith("refused 1120 request(s) in 60.0 s: 1101 x throttled")
    assert "; 19 x token" in acc[1]["text"] and acc[1]["text"].endswith("[1121 refused since start]")
    assert acc[2]["text"].startswith("refused 1 request(s) just now: 1 x token (GET /api/state: missing")
    assert acc[2]["text"].endswith("[1122 refused since start]")
    assert [e["id"] for e in lines] == sorted(e["id"] for e in lines)


def test_access_log_sends_at_most_one_summary_per_interval():
    clk = FakeClock()
    out: list[str] = []
    log = AccessLog(out.append, interval_s=10.0, clock=clk)
    log.refused("token", "GET /api/state: missing token")
    assert len(out) == 1 and out[0].startswith("refused 1 request(s) just now: 1 x token")
    for i in range(500):
        clk.t += 0.01
        log.refused("origin" if i % 2 else "token", f"WebSocket: origin {i % 5}")
        log.flush()
    assert len(out) == 1  # 5 s of refusals: counted, not sent
    clk.t += 5.001
    log.flush()
    assert len(out) == 2 and out[1].startswith("refused 500 request(s) in 10.0 s: 250 x origin")
    assert "WebSocket: origin 1; WebSocket: origin 3" in out[1]  # a few distinct examples, not all 500
    log.flush(force=True)
    assert len(out) == 2  # nothing pending, nothing sent
    assert log.total == 501 and log.by_kind == {"token": 251, "origin": 250}


def test_throttle_counts_failures_per_peer_and_refills():
    clk = FakeClock()
    th = Throttle(limit=3, window_s=30.0, clock=clk, max_peers=4)
    for _ in range(3):
        assert th.wait_s("10.0.0.1") == 0.0
        th.failed("10.0.0.1")
    assert th.wait_s("10.0.0.1") == pytest.approx(10.0)  # one try back every 10 s
    assert th.wait_s("10.0.0.2") == 0.0  # another peer is not affected
    clk.t += 10.0
    assert th.wait_s("10.0.0.1") == 0.0
    th.failed("10.0.0.1")
    assert th.wait_s("10.0.0.1") > 0.0
    for i in range(10):  # many peers: the memory stays bounded, the oldest are forgotten
        th.failed(f"10.0.1.{i}")
    assert len(th._peers) <= 4


def test_refused_websocket_handshakes_are_throttled_too(tmp_path):
    clk = FakeClock()
    s = Session("usv-remote", out_root=tmp_path, write_log=False)
    with TestClient(
        create_app(s, token=TOKEN, throttle=Throttle(2, 60.0, clock=clk)), base_url="http://127.0.0.1"
    ) as c:
        statuses = []
        for _ in range(4):
            with pytest.raises(WebSocketDenialResponse) as e, c.websocket_connect("ws://127.0.0.1/ws?token=x"):
                pass
            statuses.append(e.value.status_code)
        assert statuses == [401, 401, 429, 429]
        clk.t += 30.0
        with c.websocket_connect(WS) as ws:
            assert ws.receive_json()["type"] == "role"


# -- the token outside the command line; strong tokens on the network (issue 26) -------------------------------


@pytest.mark.parametrize(
    ("token", "why"),
    [
        ("short-token-1", "13 characters, fewer than 16"),
        ("aaaaaaaaaaaaaaaaaaaaaaaa", "only 1 different characters"),
        ("abababcdabababcdabab", "only 4 different characters"),
        ("abcdefghabcdefghabcdefgh", "the 8-character pattern 'abcdefgh' repeated"),
        ("0123456789abcdefghij", "a run of consecutive characters"),
        ("ponmlkjihgfedcba", "a run of consecutive characters"),
    ],
)
def test_weak_tokens_are_named(token, why):
    from oceangnc.console.cli import weak_token
    from oceangnc.console.server import new_token

    assert weak_token(token) == why
    assert all(weak_token(new_token()) == "" for _ in range(200))
    assert weak_token("x7Qp-2mZk_9RvT4a") == ""


def _cli(capsys, args, env=None, monkeypatch=None):
    from oceangnc.cli import main

    if monkeypatch is not None:
        monkeypatch.delenv("OCEANGNC_CONSOLE_TOKEN", raising=False)
        for k, v in (env or {}).items():
            monkeypatch.setenv(k, v)
    code = main(["console", *args])
    err = capsys.readouterr().err.strip()
    return code, err


def test_cli_token_from_a_file_or_the_environment_and_strong_on_the_network(capsys, monkeypatch, tmp_path):
    """``--token`` shows in ``ps``: the token may come from ``--token-file`` or OCEANGNC_CONSOLE_TOKEN;
    a token the network can try (non-loopback ``--host``) must be strong. Each refusal: one line, exit 2.
    (``--ssl-certfile`` alone fails after the token checks: it shows that a token was accepted.)"""
    weak, strong = tmp_path / "weak", tmp_path / "strong"
    weak.write_text("password12\n")
    strong.write_text("x7Qp-2mZk_9RvT4a\n")
    (tmp_path / "empty").write_text("\n")
    after = ["--ssl-certfile", "/nonexistent.pem"]
    cases = [
        # (args, environment, the one line expected)
        (["--host", "0.0.0.0", "--token", "short-token-1"], {}, "--token: too weak a token for --host 0.0.0.0"),
        (["--host", "0.0.0.0"], {"OCEANGNC_CONSOLE_TOKEN": "aaaaaaaaaaaaaaaaaaaa"}, "OCEANGNC_CONSOLE_TOKEN: too weak"),
        (["--host", "0.0.0.0", "--token-file", str(weak)], {}, f"--token-file {weak}: too weak a token"),
        (["--token-file", str(tmp_path / "none")], {}, f"--token-file {tmp_path / 'none'}: cannot read it"),
        (["--token-file", str(tmp_path)], {}, f"--token-file {tmp_path}: cannot read it"),
        (["--token-file", str(tmp_path / "empty")], {}, "the file is empty"),
        (["--token-file", str(strong), "--token", "abcdefgh12"], {}, "--token and --token-file: give one of them"),
        ([], {"OCEANGNC_CONSOLE_TOKEN": "short"}, "OCEANGNC_CONSOLE_TOKEN: the token needs at least 8"),
        (["--host", "0.0.0.0"], {}, "give a shared secret (--token-file PATH, OCEANGNC_CONSOLE_TOKEN, or --token"),
        # accepted tokens: the command goes on to the next check
        (["--host", "0.0.0.0", "--token-file", str(strong), *after], {}, "go together"),
        (["--host", "0.0.0.0", *after], {"OCEANGNC_CONSOLE_TOKEN": "x7Qp-2mZk_9RvT4a"}, "go together"),
        (["--token", "password12", *after], {}, "go together"),  # loopback: 8 characters suffice
    ]
    for args, env, expected in cases:
        code, err = _cli(capsys, args, env, monkeypatch)
        assert code == 2 and expected in err and "\n" not in err and "Traceback" not in err, (args, env, err)


def test_token_from_a_file_and_the_url_on_the_loopback_address_bound(tmp_path):
    """``--host 127.0.0.2`` printed a URL on 127.0.0.1, where nothing listens (issue 26); the token of
    ``--token-file`` is used (over OCEANGNC_CONSOLE_TOKEN) and is not on the command line."""
    import os
    import subprocess
    import sys

    import httpx
    from console_server import free_port

    port = free_port()
    tok = tmp_path / "token"
    tok.write_text(TOKEN + "\n")
    proc = subprocess.Popen(
        [sys.executable, "-m", "oceangnc.cli", "console", "usv-remote", "--host", "127.0.0.2", "--port", str(port)]
        + ["--out", str(tmp_path / "runs"), "--token-file", str(tok), "--no-warmup"],
        stdout=subprocess.PIPE,
        stderr=subprocess.STDOUT,
        text=True,
        env=dict(os.environ, PYTHONUNBUFFERED="1", OCEANGNC_CONSOLE_TOKEN="env-token-not-used-1"),
    )
    try:
        line = ""
        deadline = time.monotonic() + 90
        while "open " not in line and time.monotonic() < deadline:
            line = proc.stdout.readline()
            assert line or proc.poll() is None, "console exited"
        url = line.split("open ", 1)[1].strip()
        assert url == f"http://127.0.0.2:{port}/?token={TOKEN}"
        r = httpx.get(url.replace("/?", "/api/state?"), timeout=10)
        assert r.status_code == 200 and r.json()["type"] == "state"
        assert httpx.get(f"http://127.0.0.2:{port}/api/state?token=env-token-not-used-1", timeout=10).status_code == 401
        with pytest.raises(httpx.HTTPError):
            httpx.get(f"http://127.0.0.1:{port}/", timeout=5)  # nothing on 127.0.0.1
        cmdline = open(f"/proc/{proc.pid}/cmdline", "rb").read().decode() if sys.platform == "linux" else ""
        assert TOKEN not in cmdline
    finally:
        proc.terminate()
        proc.wait(timeout=20)


def test_events_file_appends_lines_and_a_cut_last_line_is_skipped(tmp_path):
    from oceangnc.core.files import LineAppender

    p = tmp_path / "events.jsonl"
    f = LineAppender(p)
    f.write('{"id": 1}')
    f.write('{"id": 2}', sync=True)
    f.close()
    f.write('{"id": 3}')  # closed: ignored
    g = LineAppender(p)  # a second run of the writer appends, never truncates
    g.write('{"id": 4}')
    g.close()
    with open(p, "a") as h:
        h.write('{"id": 5, "te')  # a write cut by a kill
    assert read_json_lines(p) == [{"id": 1}, {"id": 2}, {"id": 4}]
