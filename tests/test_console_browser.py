"""Operator console end to end in headless Chromium (Playwright driving Debian's ``chromium``).

The server is the real ``oceangnc console`` command in a subprocess on a free 127.0.0.1 port. Every
test starts a new run (fresh simulation) from its page, so the tests do not depend on each other.
The gamepad is simulated by an init script replacing ``navigator.getGamepads`` (headless Chromium
never connects a pad, and neither Playwright nor the DevTools protocol can emulate one).
Waits are explicit conditions with generous timeouts, for a loaded 2-core machine.
"""

from __future__ import annotations

import json
import os
import shutil
import time
from pathlib import Path

import httpx
import pytest
from console_server import console_server

pytestmark = pytest.mark.browser

T_WAIT = 30_000  # ms, for conditions on the streamed state
TOKEN = "browser-test-token-1"


def _chromium() -> str | None:
    for cand in (
        os.environ.get("CHROMIUM_PATH"),
        shutil.which("chromium"),
        "/usr/lib/chromium/chromium",
        shutil.which("chromium-browser"),
    ):
        if cand and Path(cand).exists():
            return cand
    return None


CHROMIUM = _chromium()
if CHROMIUM is None:
    pytest.skip("no Chromium binary (install Debian's 'chromium' or set CHROMIUM_PATH)", allow_module_level=True)
sync_api = pytest.importorskip("playwright.sync_api", reason="playwright is not installed")

FAKE_GAMEPAD = """
(() => {
  const pad = {id: 'oceangnc test pad (standard)', index: 0, connected: true, mapping: 'standard',
               timestamp: 0, axes: [0, 0, 0, 0],
               buttons: Array.from({length: 17}, () => ({pressed: false, touched: false, value: 0}))};
  window.__pad = pad;
  window.__setPad = (axes, buttons) => {
    if (axes) pad.axes = axes.slice();
    if (buttons) for (const [i, v] of Object.entries(buttons)) pad.buttons[i] = {pressed: !!v, touched: !!v, value: v ? 1 : 0};
    pad.timestamp = performance.now();
  };
  navigator.getGamepads = () => [pad, null, null, null];
  window.addEventListener('load', () => {
    const ev = new Event('gamepadconnected'); ev.gamepad = pad; window.dispatchEvent(ev);
  });
})();
"""


@pytest.fixture(scope="module")
def server(tmp_path_factory):
    out = tmp_path_factory.mktemp("console_runs")
    with console_server(out, TOKEN, start_timeout_s=90) as (port, proc):
        url = f"http://127.0.0.1:{port}"
        yield {"url": url, "out": out, "proc": proc, "page": f"{url}/?token={TOKEN}"}


@pytest.fixture(scope="module")
def chromium_browser():
    with sync_api.sync_playwright() as p:
        b = p.chromium.launch(executable_path=CHROMIUM, headless=True)
        yield b
        b.close()


@pytest.fixture
def console_page(chromium_browser, server):
    """A console page with the fake gamepad, on a fresh run (new simulation, t = 0, autonomous mode)."""
    ctx = chromium_browser.new_context(viewport={"width": 1280, "height": 800})
    ctx.add_init_script(FAKE_GAMEPAD)
    pg = ctx.new_page()
    errors: list[str] = []
    pg.on("pageerror", lambda e: errors.append(str(e)))
    pg.goto(server["page"])
    pg.wait_for_function(
        "window.__console.hello && window.__console.state && window.__console.role === 'operator'", timeout=T_WAIT
    )
    run0 = pg.evaluate("window.__console.hello.run")
    pg.select_option("#scenario-select", "usv-remote")
    pg.click("#newrun")
    pg.wait_for_function(f"window.__console.hello.run > {run0} && window.__console.state.run > {run0}", timeout=T_WAIT)
    pg.errors = errors
    yield pg
    ctx.close()
    assert not errors, f"JavaScript errors on the page: {errors}"


def state(pg, expr: str):
    return pg.evaluate(f"(() => {{ const st = window.__console.state; const sig = st.signals; return {expr}; }})()")


def wait_state(pg, cond: str, timeout: int = T_WAIT):
    """Wait until ``cond`` (JS, with ``st`` the latest state and ``sig`` its signals) holds."""
    pg.wait_for_function(
        f"(() => {{ const st = window.__console.state; if (!st) return false; "
        f"const sig = st.signals; return {cond}; }})()",
        timeout=timeout,
    )


def test_page_loads_and_shows_the_vehicle(console_page):
    page = console_page
    wait_state(page, "st.t > 1.0 && sig['usv.u'] > 0.3")  # autonomous by default: under way
    assert page.locator("#link").get_attribute("data-up") == "1"
    assert page.locator(".ro[data-key='usv.speed'] .val").inner_text() not in ("", "—")
    assert page.locator(".gauge[data-key='usv.thrust_port']").count() == 1
    assert "GPS OK" in page.locator("#sensors").inner_text()
    # the hull is drawn where the streamed state says the USV is: sample the canvas there
    page.wait_for_timeout(300)  # let a few animation frames draw
    color = page.evaluate("""(() => {
        const S = window.__console, sig = S.state.signals, cv = document.getElementById('map');
        const [x, y] = S.toScreen(sig['usv.x'], sig['usv.y']);
        const d = cv.getContext('2d').getImageData(Math.round(x) - 4, Math.round(y) - 4, 9, 9).data;
        let best = 0;
        for (let i = 0; i < d.length; i += 4) best = Math.max(best, d[i + 2] - d[i]);  // blue over red
        return best; })()""")
    assert color > 100  # the USV's light-blue hull (#4fc3f7), not the dark sea (#0b2538: 45)


def test_simulated_gamepad_drives_the_vehicle(console_page):
    page = console_page
    page.click("#mode-remote")
    wait_state(page, "st.mode === 'remote' && st.stick.source === 'gamepad' && Math.abs(sig['usv.u']) < 0.1")
    page.evaluate("window.__setPad([0, -1, 0, 0])")  # left stick fully forward (up is negative)
    wait_state(page, "sig['usv.u'] > 0.6 && st.stick.surge > 0.99")
    page.evaluate("window.__setPad([0.6, -1, 0, 0])")  # and to the right: yaw to starboard
    wait_state(page, "sig['usv.r'] > 0.1 && sig['usv.thrust_port'] > sig['usv.thrust_stbd']")
    x0 = state(page, "[sig['usv.x'], sig['usv.y']]")
    wait_state(page, f"Math.hypot(sig['usv.x'] - {x0[0]}, sig['usv.y'] - {x0[1]}) > 2")
    assert state(page, "st.failsafe") is False


def test_keyboard_fallback_drives_the_vehicle(console_page):
    page = console_page
    page.click("#mode-remote")
    wait_state(page, "st.mode === 'remote' && Math.abs(sig['usv.u']) < 0.1")
    page.locator("#map").focus()
    page.keyboard.down("KeyW")
    try:
        wait_state(page, "st.stick.source === 'keyboard' && sig['usv.u'] > 0.5")
    finally:
        page.keyboard.up("KeyW")
    page.keyboard.down("KeyA")  # yaw to port
    try:
        wait_state(page, "sig['usv.r'] < -0.1")
    finally:
        page.keyboard.up("KeyA")


def test_emergency_stop_zeroes_thrust_within_one_update(console_page):
    page = console_page
    wait_state(page, "sig['usv.thrust_port'] > 50 && sig['usv.thrust_stbd'] > 50")  # cruising
    n0 = page.evaluate("window.__console.recent.length")
    page.evaluate("window.__console.recent = []")
    page.click("#estop")
    wait_state(page, "st.estop === true")
    seq = page.evaluate(
        "window.__console.recent.map(s => [s.estop, s.signals['usv.thrust_port'], s.signals['usv.thrust_stbd'], s.t])"
    )
    first = next(i for i, s in enumerate(seq) if s[0])
    assert seq[first][1] == 0.0 and seq[first][2] == 0.0, seq  # the first update that reports it
    assert n0 > 0
    assert page.locator("#banner").get_attribute("data-state") == "estop"
    # latched: still zero later, and the gauges show it
    wait_state(page, f"st.t > {seq[first][3] + 1.0}")
    assert state(page, "[st.estop, sig['usv.thrust_port'], sig['usv.thrust_stbd']]") == [True, 0.0, 0.0]
    assert page.locator(".gauge[data-key='usv.thrust_port'] .gv").inner_text().startswith("0.0")
    page.click("#estop-reset")
    wait_state(page, "st.estop === false && sig['usv.thrust_port'] > 50")


def test_closing_the_page_triggers_the_failsafe(console_page, chromium_browser, server):
    page = console_page
    page.click("#mode-remote")
    page.evaluate("window.__setPad([0, -1, 0, 0])")
    wait_state(page, "sig['usv.u'] > 0.5")
    page.context.close()  # the operator's browser goes away
    deadline = time.monotonic() + 30
    while True:
        st = httpx.get(server["url"] + "/api/state", params={"token": TOKEN}, timeout=5).json()
        if st["failsafe"] and st["signals"]["usv.thrust_port"] == 0.0 and st["signals"]["usv.thrust_stbd"] == 0.0:
            break
        assert time.monotonic() < deadline, f"no failsafe after closing the page: {json.dumps(st)[:400]}"
        time.sleep(0.1)
    assert st["failsafe_reason"] == "operator link lost" and st["clients"] == 0 and st["operator"] is None
    # a new page finds the failsafe in its event log; it reconnects with the stick centred, which
    # clears the failsafe (a stick held over would keep it)
    ctx = chromium_browser.new_context()
    pg = ctx.new_page()
    pg.goto(server["page"])
    pg.wait_for_function(
        "window.__console.events.some(e => e.text.startsWith('FAILSAFE (operator link lost)'))", timeout=T_WAIT
    )
    pg.wait_for_function("window.__console.state && !window.__console.state.failsafe", timeout=T_WAIT)
    assert "failsafe cleared: link restored and stick centred" in pg.locator("#events").inner_text()
    ctx.close()


def test_silent_stick_triggers_the_failsafe_and_page_shows_it(console_page):
    page = console_page
    page.click("#mode-remote")
    page.evaluate("window.__setPad([0, -1, 0, 0])")
    wait_state(page, "sig['usv.u'] > 0.5")
    page.evaluate("window.__console.ws.send = () => {}")  # the page stays connected but stops sending
    wait_state(page, "st.failsafe && sig['usv.thrust_port'] === 0 && sig['usv.thrust_stbd'] === 0")
    assert "no stick input" in page.locator("#banner").inner_text()


def test_malformed_messages_are_rejected_and_the_run_continues(console_page):
    page = console_page
    wait_state(page, "st.t > 0.5")
    t0 = state(page, "st.t")
    page.evaluate("window.__console.sendRaw('{this is not json')")
    page.evaluate("window.__console.sendRaw(JSON.stringify({type: 'stick', surge: 7, yaw: 0}))")
    page.evaluate("window.__console.sendRaw(JSON.stringify({type: 'gains', gains: {'usv_pilot.speed_kp': -5}}))")
    page.wait_for_function("window.__console.rejected.length >= 3", timeout=T_WAIT)
    reasons = page.evaluate("window.__console.rejected")
    assert "malformed JSON" in reasons[0]
    assert "surge = 7" in reasons[1]
    assert "usv_pilot.speed_kp = -5: allowed range" in reasons[2]
    wait_state(page, f"st.t > {t0 + 2.0} && !st.ended && sig['usv.u'] > 0.3")
    assert "rejected" in page.locator("#events").inner_text()


def test_download_gives_the_parquet_log(console_page):
    page = console_page
    wait_state(page, "st.t > 2.0")
    with page.expect_download() as info:
        page.click("#download")
    path = info.value.path()
    import pyarrow.parquet as pq

    tab = pq.read_table(path)
    assert tab.column_names[0] == "t" and "usv.x" in tab.column_names
    assert tab.num_rows >= 2.0 * 20 - 1  # 20 Hz log over >= 2 s


# -- issue 20: who can drive, layout, strip charts ------------------------------------------------------------

EVIL_PAGE = """<!doctype html><html><body><script>
window.result = {opened: false, closed: null, error: false};
const ws = new WebSocket("ws://127.0.0.1:%(port)d/ws?token=%(token)s");
ws.onopen = () => { window.result.opened = true;
  ws.send(JSON.stringify({type: "estop", engaged: true}));
  ws.send(JSON.stringify({type: "mode", mode: "remote"})); };
ws.onerror = () => { window.result.error = true; };
ws.onclose = (e) => { window.result.closed = e.code; };
fetch("http://127.0.0.1:%(port)d/api/state?token=%(token)s", {method: "POST", mode: "no-cors"}).catch(() => {});
</script></body></html>"""


@pytest.fixture
def evil_site(server):
    """Another origin on 127.0.0.1 (another port) serving a page that tries to drive the console.
    It even knows the token: the Origin check alone must stop it."""
    import http.server
    import threading

    port = int(server["url"].rsplit(":", 1)[1])
    body = (EVIL_PAGE % {"port": port, "token": TOKEN}).encode()

    class H(http.server.BaseHTTPRequestHandler):
        def do_GET(self):
            self.send_response(200)
            self.send_header("Content-Type", "text/html")
            self.send_header("Content-Length", str(len(body)))
            self.end_headers()
            self.wfile.write(body)

        def log_message(self, *a):
            pass

    srv = http.server.ThreadingHTTPServer(("127.0.0.1", 0), H)
    th = threading.Thread(target=srv.serve_forever, daemon=True)
    th.start()
    yield f"http://127.0.0.1:{srv.server_address[1]}/"
    srv.shutdown()


def test_a_page_from_another_origin_cannot_send_a_command(console_page, chromium_browser, evil_site, server):
    page = console_page
    wait_state(page, "st.t > 0.5 && !st.estop && st.mode === 'auto'")
    ctx = chromium_browser.new_context()
    evil = ctx.new_page()
    evil.goto(evil_site)
    evil.wait_for_function("window.result.closed !== null", timeout=T_WAIT)
    res = evil.evaluate("window.result")
    ctx.close()
    assert res["opened"] is False and res["closed"] == 1006  # the handshake was refused (HTTP 403)
    page.wait_for_timeout(500)
    st = httpx.get(server["url"] + "/api/state", params={"token": TOKEN}, timeout=5).json()
    assert st["estop"] is False and st["mode"] == "auto"
    origin = evil_site.rstrip("/")
    page.wait_for_function(
        f"window.__console.events.some(e => e.text.includes(\"origin '{origin}' not allowed\"))", timeout=T_WAIT
    )


def test_a_viewer_cannot_send_a_command_and_take_over_is_explicit(console_page, chromium_browser, server):
    page = console_page
    wait_state(page, "st.t > 0.5 && !st.estop")
    ctx = chromium_browser.new_context()
    viewer = ctx.new_page()
    viewer.goto(server["page"] + "&role=viewer")
    viewer.wait_for_function("window.__console.role === 'viewer' && window.__console.state", timeout=T_WAIT)
    assert viewer.locator("#estop").is_disabled() and viewer.locator("#mode-remote").is_disabled()
    viewer.evaluate("window.__console.sendRaw(JSON.stringify({type: 'estop', engaged: true}))")
    viewer.wait_for_function("window.__console.rejected.length >= 1", timeout=T_WAIT)
    assert "is a viewer; only the operator can send commands" in viewer.evaluate("window.__console.rejected[0]")
    assert state(page, "st.estop") is False
    assert viewer.locator("#take").inner_text().startswith("Take over from #")
    viewer.click("#take")  # explicit take-over: the first page becomes a viewer, and the log says so
    viewer.wait_for_function("window.__console.role === 'operator'", timeout=T_WAIT)
    page.wait_for_function("window.__console.role === 'viewer'", timeout=T_WAIT)
    page.wait_for_function("window.__console.events.some(e => e.text.startsWith('TAKE-OVER'))", timeout=T_WAIT)
    viewer.click("#estop")
    wait_state(page, "st.estop === true")
    viewer.click("#take")  # release: the first page (opened to drive) takes control back
    page.wait_for_function("window.__console.role === 'operator'", timeout=T_WAIT)
    ctx.close()


def test_layout_keeps_the_vehicle_and_readouts_clear(console_page, tmp_path):
    page = console_page
    page.click("#estop")  # the banner shows
    wait_state(page, "st.estop === true")
    page.wait_for_timeout(400)
    boxes = page.evaluate("""(() => { const r = {};
        for (const id of ['map', 'banner', 'mapinfo', 'routebar']) { const b = document.getElementById(id).getBoundingClientRect();
          r[id] = [b.left, b.top, b.right, b.bottom]; }
        const S = window.__console, sig = S.state.signals, d = window.devicePixelRatio || 1;
        const [x, y] = S.toScreen(sig['usv.x'], sig['usv.y']); const m = r.map;
        r.usv = [m[0] + x / d, m[1] + y / d]; return r; })()""")
    page.screenshot(path=str(tmp_path / "layout.png"))

    def overlap(a, b):
        return a[0] < b[2] and b[0] < a[2] and a[1] < b[3] and b[1] < a[3]

    m = boxes["map"]
    for other in ("banner", "mapinfo", "routebar"):
        assert not overlap(m, boxes[other]), (other, boxes)
    assert not overlap(boxes["banner"], boxes["mapinfo"])
    x, y = boxes["usv"]
    assert m[0] + 20 < x < m[2] - 20 and m[1] + 20 < y < m[3] - 20, boxes  # the vehicle is well inside
    page.click("#estop-reset")


def test_a_rejected_gain_goes_back_in_its_box_and_is_logged_once(console_page):
    page = console_page
    box = page.locator("#gains input[data-name='usv_pilot.speed_kp']")
    orig = box.input_value()
    box.fill("1e9")
    page.click("#gains-apply")
    page.wait_for_function("window.__console.rejected.some(r => r.startsWith('gains:'))", timeout=T_WAIT)
    page.wait_for_timeout(600)
    assert box.input_value() == orig
    n = page.evaluate("window.__console.events.filter(e => e.text.includes('usv_pilot.speed_kp = 1e+09')).length")
    assert n == 1


def test_strip_charts_show_depth_distance_and_tension(console_page):
    page = console_page
    page.select_option("#scenario-select", "combined-survey")
    run0 = page.evaluate("window.__console.hello.run")
    page.click("#newrun")
    page.wait_for_function(
        f"window.__console.hello.run > {run0} && window.__console.state.run > {run0}", timeout=60_000
    )
    page.wait_for_function("window.__console.charts.every(c => c.t.length > 25)", timeout=60_000)
    charts = page.evaluate(
        "window.__console.charts.map(c => [c.spec.label, c.el.classList.contains('hidden'), "
        "c.v[c.v.length - 1], c.t[c.t.length - 1] - c.t[0]])"
    )
    assert [c[0] for c in charts] == ["UUV depth", "relative distance", "cable tension"]
    assert not any(c[1] for c in charts)
    sig = page.evaluate("window.__console.state.signals")
    assert charts[0][2] == pytest.approx(sig["uuv.z"], abs=0.5) and charts[2][2] > 0
    assert all(c[3] <= 60.0 for c in charts)
