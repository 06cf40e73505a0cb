"""Screenshot of a running console in headless Chromium (how docs/img/console*.png were made).

    OCEANGNC_CONSOLE_TOKEN=my-secret-token oceangnc console combined-survey --speed 2 &
    python examples/console_screenshot.py --url 'http://127.0.0.1:8050/?token=my-secret-token' --wait 20 --out docs/img/console.png

Uses Playwright with Debian's Chromium (``CHROMIUM_PATH`` overrides the binary). ``--remote``
switches to remote mode and pushes a simulated gamepad (``navigator.getGamepads`` replaced, as in
the browser tests) with the given surge and yaw before waiting.
"""

from __future__ import annotations

import argparse
import os
import shutil

PAD = """
(() => { const pad = {id: 'scripted pad', index: 0, connected: true, mapping: 'standard', axes: [0, 0, 0, 0],
  buttons: Array.from({length: 17}, () => ({pressed: false, value: 0}))};
  window.__setPad = (axes) => { pad.axes = axes; };
  navigator.getGamepads = () => [pad]; })();
"""


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--url", default="http://127.0.0.1:8050/")
    ap.add_argument("--out", default="console.png")
    ap.add_argument("--wait", type=float, default=10.0, help="seconds to let the run go before the shot")
    ap.add_argument("--remote", nargs=2, type=float, metavar=("SURGE", "YAW"), help="drive with the stick")
    ap.add_argument("--new-run", action="store_true", help="start a new run first (t = 0)")
    ap.add_argument("--width", type=int, default=1400)
    ap.add_argument("--height", type=int, default=860)
    a = ap.parse_args()
    from playwright.sync_api import sync_playwright

    exe = os.environ.get("CHROMIUM_PATH") or shutil.which("chromium") or "/usr/lib/chromium/chromium"
    with sync_playwright() as p:
        b = p.chromium.launch(executable_path=exe, headless=True)
        ctx = b.new_context(viewport={"width": a.width, "height": a.height})
        ctx.add_init_script(PAD)
        pg = ctx.new_page()
        pg.goto(a.url)
        pg.wait_for_function("window.__console && window.__console.state", timeout=60_000)
        if a.new_run:
            run0 = pg.evaluate("window.__console.hello.run")
            pg.click("#newrun")
            pg.wait_for_function(f"window.__console.state.run > {run0}", timeout=60_000)
        if a.remote:
            pg.click("#mode-remote")
            pg.evaluate(f"window.__setPad([{a.remote[1]}, {-a.remote[0]}, 0, 0])")
        pg.wait_for_timeout(a.wait * 1000)
        pg.screenshot(path=a.out)
        print(f"wrote {a.out} at t = {pg.evaluate('window.__console.state.t'):.1f} s")
        b.close()


if __name__ == "__main__":
    main()
