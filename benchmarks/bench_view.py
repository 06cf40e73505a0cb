"""3D replay benchmark (issue 31): page load time and frames per second of the replay of a 10-minute
flagship run with 20 cable segments, in headless Chromium; and the MCAP export time of that run.

    python benchmarks/bench_view.py [--duration 600] [--seconds 10] [--repeat 3] [--run DIR]

1. The run: ``oceangnc run combined-survey --duration 600 --set cable.segments=20 --set
   guidance.waypoints=ROUTE --no-plots``, ROUTE a 420 m lawnmower (the flagship's own 3 waypoints
   are done in 40 s, where the run ends); made once into ``--run`` (default a folder under the
   system's temp dir) and reused after.
2. ``oceangnc view`` writes its self-contained ``replay.html``; the page size is recorded.
3. Load: a new browser page opens the file and waits for ``window.replay.ready``; the figure is the
   page's own ``replay.loadMs`` (``performance.now()`` at the first frame drawn: from the start of
   the navigation, parsing the data and building the scene included), best and median of
   ``--repeat`` loads. The issue's target: under 3 s.
4. Frames per second: the replay plays at 1x, then at 10x, for ``--seconds`` wall seconds each;
   frames drawn (``replay.frames``) over the page's own elapsed time. Headless Chromium renders WebGL in software
   (SwiftShader) here and its animation frames are capped at the display rate (60 Hz). Target >= 30.
   With ``--waves`` the run is ``tow-sea-state`` (JONSWAP Hs 1 m, Tp 6 s, 128 components) with 20
   cable segments instead: the page draws the sea surface from the wave components every frame
   (``WavePatch``, 49 x 49 vertices); the frame rate is measured with the waves and, in the same
   browser, with ``?waves=0`` (the calm plane), and the mean time of one wave update (``replay.waveMs``).
5. The console's 3D panel (``--console-viewers N``, default 20; 0 skips it): ``oceangnc console
   combined-survey`` on 127.0.0.1, N - 1 WebSocket viewers reading the state stream (role viewer)
   and one console page in headless Chromium (the operator); the figure is the panel's updates per
   second (``view3d.updates``: new states drawn) over ``--seconds``. The console streams 25 states
   a second by default (``--stream-hz``), the ceiling. Target >= 20 Hz with 20 viewers.
"""

from __future__ import annotations

import argparse
import os
import shutil
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

from record import record

ROUTE = "[[0, 0], [120, 0], [120, 30], [0, 30], [0, 60], [120, 60]]"  # 420 m: 700 s at 0.6 m/s


def make_run(path: Path, duration: float, waves: bool = False) -> Path:
    if (path / "log.parquet").exists() and (path / "summary.json").exists():
        return path
    scenario = "tow-sea-state" if waves else "combined-survey"
    cmd = [sys.executable, "-m", "oceangnc", "run", scenario, "--duration", str(duration), "--set", "cable.segments=20"]
    if not waves:
        cmd += ["--set", f"guidance.waypoints={ROUTE}"]
    cmd += ["--no-plots", "--quiet", "--out", str(path), "--overwrite"]
    print("making the run:", " ".join(cmd[2:]), flush=True)
    subprocess.run(cmd, check=True)
    return path


def chromium() -> str:
    for cand in (os.environ.get("CHROMIUM_PATH"), shutil.which("chromium"), "/usr/lib/chromium/chromium"):
        if cand and Path(cand).exists():
            return cand
    raise SystemExit("no Chromium binary (install Debian's 'chromium' or set CHROMIUM_PATH)")


def main() -> None:
    ap = argparse.ArgumentParser()
    ap.add_argument("--duration", type=float, default=600.0, help="simulated seconds of the run (default 600)")
    ap.add_argument("--seconds", type=float, default=10.0, help="wall seconds of playing for the frame rate")
    ap.add_argument("--repeat", type=int, default=3, help="page loads")
    ap.add_argument("--run", help="run folder (made when missing)")
    ap.add_argument("--console-viewers", type=int, default=20, help="viewers of the console benchmark (0: skip)")
    ap.add_argument("--waves", action="store_true", help="a tow-sea-state run (waves drawn) instead of combined-survey")
    args = ap.parse_args()
    from playwright.sync_api import sync_playwright

    from oceangnc.view.mcap_export import export_mcap
    from oceangnc.view.replay import write_replay
    from oceangnc.view.run_data import load_run

    tag = "-waves" if args.waves else ""
    run = Path(args.run or Path(tempfile.gettempdir()) / f"oceangnc-bench-view{tag}-{int(args.duration)}s")
    make_run(run, args.duration, args.waves)
    rd = load_run(run)
    if rd.t[-1] < 0.95 * args.duration:
        print(f"warning: the run ended at {rd.t[-1]:.0f} s, before --duration {args.duration:.0f} s", flush=True)
    scen = "tow-sea-state, waves drawn" if args.waves else "combined-survey"
    case = f"{scen} {rd.t[-1]:.0f} s, {rd.cable_nodes - 1} cable segments, {rd.rows} rows"
    t0 = time.perf_counter()
    html = write_replay(rd)
    t_write = time.perf_counter() - t0
    size_mb = html.stat().st_size / 1e6
    t0 = time.perf_counter()
    mcap = export_mcap(rd)
    t_mcap = time.perf_counter() - t0
    print(f"{case}: replay.html {size_mb:.2f} MB written in {t_write:.2f} s; run.mcap "
          f"{mcap.stat().st_size / 1e6:.2f} MB in {t_mcap:.2f} s", flush=True)  # fmt: skip

    loads, fps = [], []
    with sync_playwright() as p:
        b = p.chromium.launch(executable_path=chromium(), headless=True)
        for i in range(args.repeat):
            ctx = b.new_context(viewport={"width": 1280, "height": 720})
            page = ctx.new_page()
            page.goto(html.resolve().as_uri() + "?paused")
            page.wait_for_function("window.replay && window.replay.ready === true", timeout=120_000)
            loads.append(page.evaluate("replay.loadMs") / 1000)
            if i == 0:
                f0, w0 = page.evaluate("[replay.frames, performance.now()]")
                page.evaluate("replay.setSpeed(1); replay.play()")
                page.wait_for_timeout(args.seconds * 1000)
                f1, w1 = page.evaluate("[replay.frames, performance.now()]")
                page.evaluate("replay.pause()")
                fps.append((f1 - f0) / ((w1 - w0) / 1000))
                page.evaluate("replay.seek(replay.t0); replay.setSpeed(10); replay.play()")  # a second figure
                f0, w0 = page.evaluate("[replay.frames, performance.now()]")
                page.wait_for_timeout(args.seconds * 1000)
                f1, w1 = page.evaluate("[replay.frames, performance.now()]")
                fps.append((f1 - f0) / ((w1 - w0) / 1000))
                wave_ms = page.evaluate("replay.waveMs")
            ctx.close()
        calm_fps = None
        if args.waves:  # the same page without the wave surface, for the ratio
            ctx = b.new_context(viewport={"width": 1280, "height": 720})
            page = ctx.new_page()
            page.goto(html.resolve().as_uri() + "?paused&waves=0")
            page.wait_for_function("window.replay && window.replay.ready === true", timeout=120_000)
            f0, w0 = page.evaluate("[replay.frames, performance.now()]")
            page.evaluate("replay.setSpeed(1); replay.play()")
            page.wait_for_timeout(args.seconds * 1000)
            f1, w1 = page.evaluate("[replay.frames, performance.now()]")
            calm_fps = (f1 - f0) / ((w1 - w0) / 1000)
            ctx.close()
        b.close()
    print(f"loads (s): {', '.join(f'{v:.2f}' for v in loads)}; fps 1x {fps[0]:.1f}, 10x {fps[1]:.1f}")
    if calm_fps is not None:
        print(f"waves: {wave_ms:.2f} ms per update of the sea surface; fps 1x without them (?waves=0) {calm_fps:.1f}")
    note = f"headless Chromium (software WebGL), 1280x720, page {size_mb:.1f} MB"
    record("3D replay", f"page load, best of {args.repeat} ({case})", min(loads), "s", "< 3 s", note)
    record("3D replay", f"page load, median of {args.repeat} ({case})", statistics.median(loads), "s", "< 3 s", note)
    record("3D replay", f"frames per second playing at 1x ({case})", fps[0], "fps", ">= 30", note)
    record("3D replay", f"frames per second playing at 10x ({case})", fps[1], "fps", ">= 30", note)
    if calm_fps is not None:
        record("3D replay", f"one update of the wave surface, 49 x 49 vertices x 128 components ({case})", wave_ms, "ms", "", note)
        record("3D replay", f"frames per second at 1x, waves / calm plane ({case})", fps[0] / calm_fps, "x", "", note)
    record("3D replay", f"write replay.html ({case})", t_write, "s", "", "oceangnc.view.replay.write_replay")
    record("3D replay", f"MCAP export ({case})", t_mcap, "s", "", "oceangnc.view.mcap_export.export_mcap")

    if args.console_viewers > 0:
        console_panel(args.console_viewers, args.seconds)


def console_panel(viewers: int, seconds: float) -> None:
    import socket
    import threading

    import httpx
    from playwright.sync_api import sync_playwright
    from websockets.sync.client import connect

    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        port = s.getsockname()[1]
    token = "bench-view-console-token"
    out = Path(tempfile.mkdtemp(prefix="oceangnc-bench-console-"))
    cmd = [sys.executable, "-m", "oceangnc", "console", "combined-survey", "--port", str(port), "--out", str(out)]
    proc = subprocess.Popen([*cmd, "--token", token], stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
    url = f"http://127.0.0.1:{port}"
    stop = threading.Event()
    received = [0] * (viewers - 1)

    def viewer(i: int) -> None:
        with connect(f"ws://127.0.0.1:{port}/ws?token={token}&role=viewer", open_timeout=30) as ws:
            while not stop.is_set():
                try:
                    ws.recv(timeout=1)
                    received[i] += 1
                except TimeoutError:
                    pass

    try:
        deadline = time.monotonic() + 180
        while time.monotonic() < deadline:
            try:
                if httpx.get(url + "/api/state", params={"token": token}, timeout=2).status_code == 200:
                    break
            except httpx.HTTPError:
                time.sleep(0.5)
        threads = [threading.Thread(target=viewer, args=(i,), daemon=True) for i in range(viewers - 1)]
        for t in threads:
            t.start()
        with sync_playwright() as p:
            b = p.chromium.launch(executable_path=chromium(), headless=True)
            page = b.new_page(viewport={"width": 1400, "height": 900})
            page.goto(f"{url}/?token={token}")
            page.wait_for_function("window.view3d && view3d.updates > 10", timeout=120_000)
            u0, f0, w0 = page.evaluate("[view3d.updates, view3d.frames, performance.now()]")
            page.wait_for_timeout(seconds * 1000)
            u1, f1, w1 = page.evaluate("[view3d.updates, view3d.frames, performance.now()]")
            clients = page.evaluate("window.__console.state.clients")
            b.close()
        stop.set()
        for t in threads:
            t.join(timeout=5)
    finally:
        stop.set()
        proc.terminate()
        proc.wait(timeout=30)
        shutil.rmtree(out, ignore_errors=True)
    hz = (u1 - u0) / ((w1 - w0) / 1000)
    print(f"console 3D panel: {hz:.1f} updates/s, {(f1 - f0) / ((w1 - w0) / 1000):.1f} frames/s, "
          f"{clients} clients connected; viewers got {min(received)}-{max(received)} messages")  # fmt: skip
    case = f"console 3D panel updates per second, combined-survey, {clients} clients"
    case += f" ({viewers - 1} WebSocket viewers + the page)"
    record("3D replay", case, hz, "Hz", ">= 20", "headless Chromium, software WebGL; the console streams 25 states/s")


if __name__ == "__main__":
    main()
