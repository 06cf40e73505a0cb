"""Operator console, server side: message validation, rate limit, pacing, failsafe, e-stop, log.

Session tests drive :meth:`Session.step_once` with a fake wall clock, so they are deterministic;
the pacing test uses the real clock for 10 s (issue 9: simulated time tracks wall time within 5 %).
"""

from __future__ import annotations

import io
import json
import math
import time

import pyarrow.parquet as pq
import pytest

from oceangnc.console.messages import (
    BURST,
    RATE_PER_S,
    RateLimiter,
    Rejected,
    check_gains,
    parse_message,
)
from oceangnc.console.session import Session
from oceangnc.units import KGF

TOKEN = "test-token-0123"

# -- message validation --------------------------------------------------------------------------------


def test_valid_messages_parse():
    m = parse_message('{"type": "stick", "surge": 0.5, "yaw": -1, "source": "gamepad"}')
    assert (m.surge, m.yaw, m.source) == (0.5, -1.0, "gamepad")
    assert parse_message('{"type": "mode", "mode": "remote"}').mode == "remote"
    assert parse_message('{"type": "estop", "engaged": true}').engaged is True
    w = parse_message('{"type": "waypoints", "points": [[10, 0], [10, 10]]}')
    assert w.points == [(10.0, 0.0), (10.0, 10.0)]
    assert parse_message(b'{"type": "new_run"}').scenario is None


@pytest.mark.parametrize(
    "raw, fragment",
    [
        ("{not json", "malformed JSON"),
        ("[1, 2]", "must be a JSON object"),
        ('{"type": "launch_missiles"}', "unknown message type 'launch_missiles'"),
        ('{"surge": 0.1}', "unknown message type None"),
        ('{"type": "stick", "surge": 1.5, "yaw": 0}', "surge = 1.5"),
        ('{"type": "stick", "surge": NaN, "yaw": 0}', "surge"),
        ('{"type": "stick", "surge": Infinity, "yaw": 0}', "surge"),
        ('{"type": "stick", "surge": "fast", "yaw": 0}', "surge = 'fast'"),
        ('{"type": "stick", "surge": 0.1}', "yaw: Field required"),
        ('{"type": "stick", "surge": 0.1, "yaw": 0, "turbo": 1}', "turbo"),
        ('{"type": "mode", "mode": "manual"}', "mode = 'manual'"),
        ('{"type": "estop", "engaged": "maybe"}', "engaged"),
        ('{"type": "waypoints", "points": []}', "points"),
        ('{"type": "waypoints", "points": [[1e9, 0]]}', "farther than 100 km"),
        ('{"type": "new_run", "scenario": "../../etc/passwd"}', "scenario"),
        ('{"type": "gains", "gains": {}}', "gains"),
    ],
)
def test_bad_messages_are_rejected_with_a_reason(raw, fragment):
    with pytest.raises(Rejected) as exc:
        parse_message(raw)
    msg = str(exc.value)
    assert fragment in msg
    assert "\n" not in msg  # one line, for the page's event log


def test_oversized_message_rejected():
    raw = json.dumps({"type": "waypoints", "points": [[1.0, 2.0]] * 5000})
    with pytest.raises(Rejected, match="message too long"):
        parse_message(raw)


def test_gain_names_and_ranges_checked():
    specs = {"pilot.kp": {"min": 0.0, "max": 10.0, "unit": "N"}}
    check_gains({"pilot.kp": 3.0}, specs)
    with pytest.raises(Rejected, match="unknown gain 'pilot.kd'; adjustable gains: pilot.kp"):
        check_gains({"pilot.kd": 1.0}, specs)
    with pytest.raises(Rejected, match=r"pilot.kp = 11: allowed range 0 <= value <= 10"):
        check_gains({"pilot.kp": 11.0}, specs)


def test_rate_limiter_token_bucket():
    now = [0.0]
    lim = RateLimiter(clock=lambda: now[0])
    allowed = sum(lim.allow() for _ in range(500))
    assert allowed == int(BURST)  # a burst is capped ...
    now[0] += 1.0
    allowed = sum(lim.allow() for _ in range(500))
    assert allowed == int(RATE_PER_S)  # ... and the sustained rate is RATE_PER_S per second


# -- session (fake clock) --------------------------------------------------------------------------------


class FakeClock:
    def __init__(self):
        self.t = 1000.0

    def __call__(self):
        return self.t


@pytest.fixture
def session(tmp_path):
    clk = FakeClock()
    s = Session("usv-remote", out_root=tmp_path, clock=clk)
    s.client_connected()
    s.fake = clk
    yield s
    s.stop()


def advance(s, seconds, stick=None, period=0.05):
    """Advance the fake wall clock by ``seconds`` in steps, sending ``stick`` each step if given."""
    n = int(round(seconds / period))
    for _ in range(n):
        s.fake.t += period
        if stick is not None:
            s.submit(parse_message(json.dumps({"type": "stick", "surge": stick[0], "yaw": stick[1]})))
        s.step_once()


def send(s, **msg):
    s.submit(parse_message(json.dumps(msg)))


def thrust(s):
    b = s.sim.bus
    return b["usv.thrust_port"], b["usv.thrust_stbd"]


def test_fake_clock_pacing_follows_speed(tmp_path):
    clk = FakeClock()
    s = Session("usv-remote", out_root=tmp_path, clock=clk, speed=2.0, write_log=False)
    s.client_connected()
    s.fake = clk
    advance(s, 3.0)
    assert s.sim.t == pytest.approx(6.0, abs=s.tick_s + 1e-9)


def test_stick_drives_surge_speed_and_yaw_rate(session):
    s = session
    send(s, type="mode", mode="remote")
    advance(s, 15.0, stick=(0.0, 0.0))
    assert abs(s.sim.bus["usv.u"]) < 0.05  # stick centred: the boat stops
    advance(s, 20.0, stick=(1.0, 0.0))
    u_max = s.cfg.remote.max_speed
    assert s.sim.bus["usv.u"] == pytest.approx(u_max, rel=0.03)  # full stick ahead -> u_max
    advance(s, 15.0, stick=(1.0, 0.5))
    r_d = 0.5 * math.radians(s.cfg.remote.max_yaw_rate_degps)
    assert s.sim.bus["usv.r"] == pytest.approx(r_d, rel=0.05)  # yaw to starboard: r > 0
    assert s.sim.bus["usv.thrust_port"] > s.sim.bus["usv.thrust_stbd"]  # 003 eq. 3.11 mixing
    assert not s.failsafe


def test_open_loop_stick_maps_to_thrust(session):
    s = session
    send(s, type="mode", mode="remote")
    send(s, type="loop", loop="open")
    advance(s, 1.0, stick=(0.5, 0.2))
    tp, ts = thrust(s)
    rm = s.cfg.remote
    assert tp == pytest.approx((0.5 * rm.open_loop_thrust_kgf + 0.2 * rm.open_loop_diff_kgf) * KGF)
    assert ts == pytest.approx((0.5 * rm.open_loop_thrust_kgf - 0.2 * rm.open_loop_diff_kgf) * KGF)


def test_estop_zeroes_thrust_at_once_and_is_latched(session):
    s = session
    advance(s, 5.0)  # autonomous: cruising
    assert min(thrust(s)) > 10.0
    send(s, type="estop", engaged=True)
    t_sim = s.sim.t
    s.step_once()  # the next console pass, wall clock not advanced: no simulated time passes
    assert s.sim.t == t_sim
    assert thrust(s) == (0.0, 0.0)  # zero at once, not one actuator period later
    assert s.state()["estop"] is True and s.state()["signals"]["usv.thrust_port"] == 0.0
    send(s, type="mode", mode="remote")  # switching modes does not clear a latched stop
    advance(s, 5.0, stick=(1.0, 0.0))
    assert thrust(s) == (0.0, 0.0) and s.estop
    send(s, type="estop", engaged=False)
    advance(s, 2.0, stick=(1.0, 0.0))
    assert min(thrust(s)) > 10.0 and not s.estop


def test_stick_timeout_trips_failsafe_and_needs_neutral_stick_to_clear(session):
    s = session
    send(s, type="mode", mode="remote")
    advance(s, 5.0, stick=(1.0, 0.0))
    assert min(thrust(s)) > 0 and not s.failsafe
    advance(s, 0.9)  # stick silent for 0.9 s: still driving
    assert not s.failsafe
    advance(s, 0.2)  # > 1 s: failsafe, thrust zero
    assert s.failsafe and "no stick input" in s.failsafe_reason
    advance(s, 0.05)
    assert thrust(s) == (0.0, 0.0)
    assert s.sim.bus["console.failsafe"] == 1.0
    advance(s, 1.0, stick=(1.0, 0.0))  # link back but stick held over: stays in failsafe
    assert s.failsafe and thrust(s) == (0.0, 0.0)
    advance(s, 0.2, stick=(0.0, 0.0))  # centred: cleared
    assert not s.failsafe
    advance(s, 2.0, stick=(0.6, 0.0))
    assert min(thrust(s)) > 0


def test_disconnect_in_remote_mode_trips_failsafe(session):
    s = session
    send(s, type="mode", mode="remote")
    advance(s, 3.0, stick=(1.0, 0.0))
    s.client_disconnected()
    advance(s, 0.05)
    assert s.failsafe and s.failsafe_reason == "operator link lost"
    advance(s, 0.05)
    assert thrust(s) == (0.0, 0.0)
    assert any("FAILSAFE" in e["text"] for e in s.events)


def test_autonomous_mode_survives_disconnect(session):
    s = session
    s.client_disconnected()
    advance(s, 3.0)
    assert not s.failsafe and min(thrust(s)) > 10.0


def test_gain_change_reaches_the_running_controller(session):
    s = session
    pilot = next(b for b in s.sim.blocks if b.name == "usv_pilot")
    send(s, type="gains", gains={"usv_pilot.speed_kp": 800.0})
    advance(s, 0.05)
    assert pilot.speed_pid.kp == 800.0
    assert s.hello_message()["gains"]["usv_pilot.speed_kp"]["value"] == 800.0
    with pytest.raises(Rejected, match="allowed range"):
        send(s, type="gains", gains={"usv_pilot.speed_kp": 1e6})
    assert pilot.speed_pid.kp == 800.0


def test_clicked_waypoints_replace_the_route(session):
    s = session
    send(s, type="waypoints", points=[[0.0, -30.0]])  # due west
    advance(s, 30.0)
    b = s.sim.bus
    assert b["usv.y"] < -10.0 and abs(b["usv.x"]) < 5.0
    assert s.state()["waypoints"] == [[0.0, -30.0]]


def test_pause_freezes_time_and_new_run_restarts(session):
    s = session
    advance(s, 2.0)
    send(s, type="pause", paused=True)
    advance(s, 0.05)
    t_paused = s.sim.t
    advance(s, 2.0)
    assert s.sim.t == t_paused
    send(s, type="pause", paused=False)
    advance(s, 1.0)  # resumed at the first of these 20 updates: 0.95 s of running
    assert s.sim.t == pytest.approx(t_paused + 0.95, abs=2 * s.tick_s)
    run0 = s.run_id
    send(s, type="new_run")
    advance(s, 0.05)
    assert s.run_id == run0 + 1 and s.sim.t < 0.1
    with pytest.raises(Rejected, match="unknown or non-live scenario 'nope'"):
        send(s, type="new_run", scenario="nope")


def test_downloaded_log_matches_run_log_format(session, tmp_path):
    s = session
    advance(s, 3.0)
    data, name = s.log_bytes()
    tab = pq.read_table(io.BytesIO(data))
    assert name.startswith("usv-remote-run")
    cols = tab.column_names
    assert cols[0] == "t" and "usv.x" in cols and "usv.thrust_port" in cols and "console.estop" in cols
    t = tab.column("t").to_numpy()
    assert len(t) >= 55 and t[1] - t[0] == pytest.approx(1 / s.cfg.sim.log_rate)
    run_dir = s.run_dir
    s.stop()  # closes the on-disk log.parquet
    disk = pq.read_table(run_dir / "log.parquet")
    assert disk.column_names == cols
    assert disk.num_rows >= tab.num_rows
    assert json.loads((run_dir / "summary.json").read_text())["scenario"] == "usv-remote"


# -- real time -------------------------------------------------------------------------------------------


def test_pacing_tracks_wall_clock_within_5_percent_over_10_s(tmp_path):
    """Issue 9: simulated time tracks wall time within 5 % over 10 s (real clock, real thread)."""
    s = Session("usv-remote", out_root=tmp_path, write_log=False)
    s.start()
    try:
        t_sim0 = s.sim.t
        w0 = time.perf_counter()
        time.sleep(10.0)
        dt_sim = s.state()["t"] - t_sim0
        dt_wall = time.perf_counter() - w0
    finally:
        s.stop()
    assert abs(dt_sim - dt_wall) / dt_wall < 0.05, (dt_sim, dt_wall)


# -- the ASGI app (in-process) -------------------------------------------------------------------------


def test_websocket_streams_rejects_bad_messages_and_keeps_running(tmp_path):
    from fastapi.testclient import TestClient

    from oceangnc.console.server import create_app

    s = Session("usv-remote", out_root=tmp_path, write_log=False)
    with TestClient(create_app(s, token=TOKEN), base_url="http://127.0.0.1") as client:
        with client.websocket_connect(f"ws://127.0.0.1/ws?token={TOKEN}") as ws:
            role = ws.receive_json()
            assert role == {"type": "role", "client": 1, "role": "operator", "operator": 1}
            hello = ws.receive_json()
            assert hello["type"] == "hello" and hello["scenario"] == "usv-remote"
            assert [b["name"] for b in hello["view"]["bodies"]] == ["usv"]
            assert "usv_pilot.yaw_kp" in hello["gains"]
            first = ws.receive_json()
            assert first["type"] == "state"
            ws.send_text("{definitely not json")
            ws.send_text(json.dumps({"type": "stick", "surge": 3, "yaw": 0}))
            reasons, t_last = [], first["t"]
            deadline = time.monotonic() + 20
            while (len(reasons) < 2 or t_last < first["t"] + 1.0) and time.monotonic() < deadline:
                m = ws.receive_json()
                if m["type"] == "rejected":
                    reasons.append(m["reason"])
                elif m["type"] == "state":
                    t_last = m["t"]
                    assert not m["ended"]
            assert "malformed JSON" in reasons[0] and "surge = 3" in reasons[1]
            assert t_last >= first["t"] + 1.0  # the run went on
        r = client.get("/api/log.parquet", headers={"x-oceangnc-token": TOKEN})
        assert r.status_code == 200 and r.content[:4] == b"PAR1"
        assert client.get(f"/api/state?token={TOKEN}").json()["type"] == "state"
        assert client.get("/api/state").status_code == 401


def test_websocket_from_a_foreign_origin_is_refused(tmp_path):
    """Refused at the handshake with HTTP 403 (docs/console.md says so), even with the right token."""
    from fastapi.testclient import TestClient
    from starlette.testclient import WebSocketDenialResponse

    from oceangnc.console.server import create_app

    s = Session("usv-remote", out_root=tmp_path, write_log=False)
    with TestClient(create_app(s, token=TOKEN), base_url="http://127.0.0.1") as client:
        with pytest.raises(WebSocketDenialResponse) as exc:
            with client.websocket_connect(
                f"ws://127.0.0.1/ws?token={TOKEN}", headers={"origin": "http://evil.example"}
            ) as ws:
                ws.receive_json()
        assert exc.value.status_code == 403 and "origin 'http://evil.example' not allowed" in exc.value.text


def test_cli_rejects_bad_options(capsys):
    from oceangnc.cli import main

    assert main(["console", "--speed", "0"]) == 2
    assert "--speed 0" in capsys.readouterr().err
    assert main(["console", "--host", "not-an-ip"]) == 2
    assert "--host" in capsys.readouterr().err
    assert main(["console", "no-such-scenario"]) == 2
    assert "unknown scenario 'no-such-scenario'" in capsys.readouterr().err


# -- other scenarios through the shared bus protocol ------------------------------------------------------


def test_usv_remote_offline_autopilot_completes_the_route(tmp_path):
    """``oceangnc run usv-remote``: the pure-pursuit autopilot goes round the 50 m square."""
    from oceangnc.api import run

    res = run("usv-remote", duration=300.0, plots=False, out=tmp_path)
    assert res.summary["guidance.waypoints_reached"] == 4
    assert res.summary["guidance.cross_track_rms_m"] < 1.0
    df = res.df
    assert math.hypot(df["usv.x"].iloc[-1], df["usv.y"].iloc[-1]) < 4.0  # back at the start corner


def test_berthing_pilot_is_silenced_in_remote_mode(tmp_path):
    """berthing-dock: in auto the scripted pilot holds the stick; in remote the console's stick wins."""
    import oceangnc.scenarios.berthing  # noqa: F401 - the project's own module: an import error fails the test

    clk = FakeClock()
    s = Session("berthing-dock", out_root=tmp_path, clock=clk, write_log=False, speed=10.0)
    s.client_connected()
    s.fake = clk
    try:
        advance(s, 3.0)  # 30 s of ship time, scripted pilot
        assert s.sim.bus["joystick.surge"] > 0.1  # the pilot's cruise stick
        send(s, type="mode", mode="remote")
        advance(s, 3.0, stick=(-0.5, 0.25))
        assert s.sim.bus["joystick.surge"] == -0.5 and s.sim.bus["joystick.yaw"] == 0.25
        assert s.sim.bus["joystick.surge_f"] < 0  # the joystick filter (001 eq. 26) sees it
        polys = {p["name"] for p in s.view["polylines"]}
        assert {"quay", "berth"} <= polys and len(s.view["route"]) == 3
        assert s.view["bodies"][0]["length"] == s.cfg.ship.length
    finally:
        s.stop()


def test_fixed_route_scenarios_refuse_clicked_waypoints(tmp_path):
    """A scenario whose guidance does not read ``console.waypoints`` refuses a route, with a reason."""
    import oceangnc.scenarios.berthing  # noqa: F401 - the project's own module: an import error fails the test

    s = Session("berthing-channel", out_root=tmp_path, write_log=False)
    try:
        with pytest.raises(Rejected, match="flies a fixed route"):
            send(s, type="waypoints", points=[[10.0, 0.0]])
        assert s.hello["route_edit"] is False and s.hello["loop_switch"] is False
    finally:
        s.stop()


def test_gps_outage_shows_as_a_sensor_failure(tmp_path):
    """A configured GPS outage drops ``gps.valid`` to 0 in the streamed state (the page's FAIL lamp);
    the autopilot keeps going on the last fix and recovers when the fix returns."""
    clk = FakeClock()
    s = Session("usv-remote", overrides={"gps.outages": [[2.0, 4.0]]}, out_root=tmp_path, clock=clk, write_log=False)
    s.client_connected()
    s.fake = clk
    try:
        assert {"key": "gps.valid", "label": "GPS"} in s.hello["view"]["sensors"]
        advance(s, 1.5)
        assert s.state()["signals"]["gps.valid"] == 1.0
        advance(s, 1.5)  # t = 3 s: inside the outage
        st = s.state()["signals"]
        assert st["gps.valid"] == 0.0 and st["usv.u"] > 0.5
        held = (st["gps.x"], st["gps.y"])
        advance(s, 0.5)
        assert (s.state()["signals"]["gps.x"], s.state()["signals"]["gps.y"]) == held  # last fix held
        advance(s, 1.5)  # t = 5 s: back
        st = s.state()["signals"]
        assert st["gps.valid"] == 1.0 and abs(st["gps.x"] - st["usv.x"]) < 0.3
    finally:
        s.stop()


def test_combined_vehicle_follows_the_stick_and_tows_the_uuv(tmp_path):
    """combined-survey through the shared protocol: in remote mode the stick turns the USV to
    starboard and the UUV, on its 3 m cable, stays with it; the e-stop zeroes all five thrusters."""
    import oceangnc.scenarios.combined  # noqa: F401 - the project's own module: an import error fails the test

    clk = FakeClock()
    s = Session("combined-survey", out_root=tmp_path, clock=clk, write_log=False)
    s.client_connected()
    s.fake = clk
    try:
        send(s, type="mode", mode="remote")
        advance(s, 8.0, stick=(0.8, 0.6), period=0.1)
        b = s.sim.bus
        assert b["usv.r"] > 0.05 and b["usv.u"] > 0.2
        assert math.hypot(b["usv.x"] - b["uuv.x"], b["usv.y"] - b["uuv.y"]) < 3.5
        send(s, type="estop", engaged=True)
        s.step_once()
        assert all(
            b[f"{v}.thrust_{k}"] == 0.0
            for v, k in [("usv", "port"), ("usv", "stbd"), ("uuv", "port"), ("uuv", "stbd"), ("uuv", "bow")]
        )
    finally:
        s.stop()


def test_first_run_waits_for_the_first_operator(tmp_path):
    clk = FakeClock()
    s = Session("usv-remote", out_root=tmp_path, clock=clk, write_log=False, start_on_connect=True)
    s.fake = clk
    try:
        advance(s, 2.0)
        assert s.sim.t == 0.0 and s.state()["paused"] is True
        s.client_connected()
        advance(s, 1.0)
        assert s.sim.t == pytest.approx(0.95, abs=2 * s.tick_s) and not s.paused
    finally:
        s.stop()


def test_overrides_stay_with_their_scenario(tmp_path):
    """``--set`` keys of the starting scenario are not forced on another scenario's new run."""
    clk = FakeClock()
    s = Session("usv-remote", overrides={"gps.sigma": 0.0}, out_root=tmp_path, clock=clk, write_log=False)
    s.client_connected()
    s.fake = clk
    try:
        assert s.cfg.gps.sigma == 0.0
        send(s, type="new_run", scenario="usv-straight")  # has no gps section
        advance(s, 0.05)
        assert s.scenario.name == "usv-straight" and s.run_id == 2
        send(s, type="new_run", scenario="usv-remote")
        advance(s, 0.05)
        assert s.cfg.gps.sigma == 0.0
    finally:
        s.stop()
