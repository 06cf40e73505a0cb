"""The console's 3D panel (issue 31, docs/view.md) in headless Chromium: a real ``oceangnc console
combined-survey`` on 127.0.0.1, its page opened with the token; the panel draws every new state, and
the UUV and the last cable node are drawn where the state it drew puts them (page state, projection
through its camera computed here, and a screenshot once the operator has paused the run)."""

from __future__ import annotations

import os
import shutil
import subprocess
import sys
from pathlib import Path

import httpx
import numpy as np
import pytest
from console_server import console_server
from view_helpers import first_line

from oceangnc.view import frames

pytestmark = pytest.mark.browser
TOKEN = "view3d-test-token-1"
PX_TOL = 1.5


def _chromium() -> str | None:
    for cand in (os.environ.get("CHROMIUM_PATH"), shutil.which("chromium"), "/usr/lib/chromium/chromium"):
        if cand and Path(cand).exists():
            return cand
    return None


@pytest.fixture(scope="module")
def console(tmp_path_factory):
    pytest.importorskip("fastapi", reason="the console needs oceangnc[console]")
    out = tmp_path_factory.mktemp("console3d")
    with console_server(out, TOKEN, 180, scenario="combined-survey") as (port, _):
        yield f"http://127.0.0.1:{port}"


def _project(m: dict, world) -> tuple[float, float]:
    proj = np.array(m["projection"]).reshape(4, 4).T
    view = np.array(m["view"]).reshape(4, 4).T
    clip = proj @ view @ np.array([*world, 1.0])
    ndc = clip[:3] / clip[3]
    return (ndc[0] + 1) / 2 * m["width"], (1 - ndc[1]) / 2 * m["height"]


def test_console_3d_panel_draws_the_live_state(console, tmp_path):
    chromium = _chromium()
    if chromium is None:
        pytest.skip("no Chromium binary (install Debian's 'chromium' or set CHROMIUM_PATH)")
    sync_api = pytest.importorskip("playwright.sync_api", reason="playwright is not installed")
    from PIL import Image

    # the vendor route serves the two modules and nothing else
    assert httpx.get(console + "/vendor/three.module.min.js", timeout=10).status_code == 200
    assert httpx.get(console + "/vendor/scene3d.js", timeout=10).status_code == 200
    assert httpx.get(console + "/vendor/replay.py", timeout=10).status_code == 404
    with sync_api.sync_playwright() as p:
        b = p.chromium.launch(executable_path=chromium, headless=True)
        try:
            page = b.new_page(viewport={"width": 1400, "height": 900})
            errors: list[str] = []
            page.on("pageerror", lambda e: errors.append(str(e)))
            page.goto(f"{console}/?token={TOKEN}")
            page.wait_for_function("window.view3d && window.view3d.updates > 10 && window.view3d.uuv", timeout=90_000)
            u0 = page.evaluate("view3d.updates")
            page.wait_for_function(f"view3d.updates > {u0 + 5}", timeout=60_000)  # it keeps drawing new states
            # the operator pauses the run: the last state stays on screen
            page.click("#pause")
            page.wait_for_function("window.__console.state && window.__console.state.paused === true", timeout=30_000)
            # the panel catches up with the last state (it draws at most 20 times a second; a busy machine is slower)
            page.wait_for_function("window.__console.state.t === view3d.state.t", timeout=30_000)
            st = page.evaluate(
                """(() => { const s = view3d.state.signals; return {
                    t: view3d.t, uuv: view3d.uuv, end: view3d.cableEnd, m: view3d.cameraMatrices(),
                    drawnUuv: view3d.projectObject('uuv'), drawnEnd: view3d.projectObject('cableEnd'),
                    sig: [s['uuv.x'], s['uuv.y'], s['uuv.z']], last: view3d.state.signals['cable.x20'] !== undefined
                      ? [s['cable.x20'], s['cable.y20'], s['cable.z20']] : null,
                    paused: window.__console.state.paused, same: window.__console.state.t === view3d.state.t }; })()"""
            )
            assert st["paused"] and st["same"], "the panel drew the latest state"
            assert st["t"] > 0
            uuv_ned = np.array(st["sig"], float)
            assert np.allclose(st["uuv"]["ned"], uuv_ned, atol=1e-9)
            assert np.allclose(st["uuv"]["world"], frames.ned_to_three(*uuv_ned), atol=1e-9)
            want = _project(st["m"], frames.ned_to_three(*uuv_ned))
            assert np.hypot(st["drawnUuv"][0] - want[0], st["drawnUuv"][1] - want[1]) < PX_TOL
            assert 0 < want[0] < st["m"]["width"] and 0 < want[1] < st["m"]["height"]
            assert st["last"] is not None
            end_ned = np.array(st["last"], float)
            assert np.allclose(st["end"]["ned"], end_ned, atol=1e-9)
            want_end = _project(st["m"], frames.ned_to_three(*end_ned))
            assert np.hypot(st["drawnEnd"][0] - want_end[0], st["drawnEnd"][1] - want_end[1]) < PX_TOL
            # a screenshot of the panel: the UUV's pixel is not the background
            m = st["m"]
            page.screenshot(
                path=str(tmp_path / "panel.png"),
                clip={"x": m["left"], "y": m["top"], "width": m["width"], "height": m["height"]},
            )
            px = Image.open(tmp_path / "panel.png").convert("RGB").getpixel((int(want[0]), int(want[1])))
            assert px != (0x0B, 0x17, 0x24), px
            assert not errors, errors
        finally:
            b.close()


def test_foxglove_stream_of_the_live_console(console):
    """`oceangnc view --console URL --foxglove`: the running session read as a viewer with its token,
    republished on the Foxglove WebSocket protocol; a client receives poses and signals of the live
    states, in time order, the pose the ENU image of the same state's NED signals."""
    import json
    import threading

    ws_client = pytest.importorskip("websockets.sync.client", reason="websockets is not installed")
    cmd = [
        sys.executable,
        "-m",
        "oceangnc",
        "view",
        "--console",
        f"{console}/?token={TOKEN}",
        "--foxglove",
        "--port",
        "0",
    ]
    # an operator (a script with the token) takes control and runs the session: live states with new times
    with ws_client.connect(f"{console.replace('http', 'ws')}/ws?token={TOKEN}&role=operator", open_timeout=30) as op:
        op.send(json.dumps({"type": "control", "take": True, "force": True}))
        op.send(json.dumps({"type": "pause", "paused": False}))
        done = threading.Event()

        def drain():  # read the operator's own stream, so that the console never drops it as too slow
            while not done.is_set():
                try:
                    op.recv(timeout=0.5)
                except TimeoutError:
                    pass
                except Exception:
                    return

        reader = threading.Thread(target=drain, daemon=True)
        reader.start()
        try:
            order, got = _live_stream(cmd, ws_client)
        finally:
            done.set()
            reader.join(timeout=5)
    assert order == sorted(order) and len(set(order)) == len(order)
    both = [ts for ts in order if ts in got[1]]
    assert len(both) >= 5
    for ts in both:
        sig, pose = got[2][ts], got[1][ts]["pose"]["position"]
        assert (pose["x"], pose["y"], pose["z"]) == (sig["y"], sig["x"], -sig["z"])


def _live_stream(cmd, ws_client):
    """Start the bridge ``cmd``, subscribe to /uuv/pose (1) and /signals/uuv (2), read 10 states."""
    import json
    import struct

    proc = subprocess.Popen(cmd, stdout=subprocess.PIPE, text=True, env=dict(os.environ, PYTHONUNBUFFERED="1"))
    try:
        line = first_line(proc, 120)
        assert "at ws://127.0.0.1:" in line, line
        url = line.split(" at ", 1)[1].split()[0]
        with ws_client.connect(url, subprotocols=["foxglove.websocket.v1"], open_timeout=30) as ws:
            info = json.loads(ws.recv(timeout=30))
            chans = {c["topic"]: c for c in json.loads(ws.recv(timeout=30))["channels"]}
            assert info["op"] == "serverInfo"
            assert {"/usv/pose", "/uuv/pose", "/scene", "/signals/uuv", "/signals/cable"} <= set(chans)
            assert chans["/scene"]["schemaName"] == "foxglove.SceneUpdate"
            sub = [
                {"id": 1, "channelId": chans["/uuv/pose"]["id"]},
                {"id": 2, "channelId": chans["/signals/uuv"]["id"]},
            ]
            ws.send(json.dumps({"op": "subscribe", "subscriptions": sub}))
            got: dict[int, dict] = {1: {}, 2: {}}
            order = []
            while len(got[2]) < 10:  # bounded: 10 live states
                frame = ws.recv(timeout=30)
                if frame[0] != 0x01:
                    continue
                sid, ts = struct.unpack("<IQ", frame[1:13])
                got[sid][ts] = json.loads(frame[13:])
                if sid == 2:
                    order.append(ts)
    finally:
        proc.terminate()
        proc.wait(timeout=30)
    return order, got


def test_console_3d_panel_draws_the_waves_of_a_sea_state(tmp_path):
    """`oceangnc console tow-sea-state`: the hello's view carries the scenario's wave components and the
    3D panel draws the sea surface from them (scene3d.WavePatch, as the replay page): its heights at the
    time of the state it drew equal oceangnc.environment.waves (WaveField.kinematics of the field the
    plant is built with) within 1e-6 Hs at every vertex (round trip of the same law, two codes)."""
    chromium = _chromium()
    if chromium is None:
        pytest.skip("no Chromium binary (install Debian's 'chromium' or set CHROMIUM_PATH)")
    sync_api = pytest.importorskip("playwright.sync_api", reason="playwright is not installed")
    pytest.importorskip("fastapi", reason="the console needs oceangnc[console]")
    from oceangnc.api import resolve_config

    _, cfg = resolve_config("tow-sea-state")
    field = cfg.environment.plant_kwargs(cfg.sim.seed)["waves"]
    hs = cfg.environment.waves.hs
    with console_server(tmp_path, TOKEN, 180, scenario="tow-sea-state") as (port, _):
        url = f"http://127.0.0.1:{port}"
        with sync_api.sync_playwright() as p:
            b = p.chromium.launch(executable_path=chromium, headless=True)
            try:
                page = b.new_page(viewport={"width": 1400, "height": 900})
                errors: list[str] = []
                page.on("pageerror", lambda e: errors.append(str(e)))
                page.goto(f"{url}/?token={TOKEN}")
                page.wait_for_function("window.view3d && view3d.updates > 5 && view3d.t > 0", timeout=90_000)
                patches = [page.evaluate("view3d.seaPatch()")]
                u0 = page.evaluate("view3d.updates")
                page.wait_for_function(f"view3d.updates > {u0 + 5} && view3d.seaPatch().t !== {patches[0]['t']}")
                patches.append(page.evaluate("view3d.seaPatch()"))
                assert not errors, errors
            finally:
                b.close()
    for patch in patches:
        g1 = patch["cells"] + 1
        i, j = np.meshgrid(np.arange(g1), np.arange(g1), indexing="ij")
        n = patch["n0"] + i.ravel() * patch["step"]
        e = patch["e0"] + j.ravel() * patch["step"]
        want = field.kinematics(patch["t"], np.c_[n, e, np.zeros_like(n)])[0]
        assert np.ptp(want) > 0.5 * hs  # a sea, not a flat plane
        assert np.abs(np.array(patch["eta"]) - want).max() <= 1e-6 * hs
    assert patches[1]["t"] > patches[0]["t"]  # the surface moves with the live time
