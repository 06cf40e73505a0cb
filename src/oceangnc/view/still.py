"""A still of the 3D replay of a run folder, drawn by headless Chromium: ``python -m oceangnc.view.still RUN
OUT.png [--t T] [--size 1280x720] [--follow tow|usv|uuv] [--azimuth DEG] [--elevation DEG] [--distance M]
[--view-only]``.

The replay page (:func:`oceangnc.view.replay.build_html`, written to a temporary file) is opened in
Chromium through Playwright, paused, moved to time ``T`` (default: the middle of the run) and the
camera set; the PNG is the whole page (3D view, panels, controls) or, with ``--view-only``, the 3D
view alone. This is how the gallery's stills are made (``docs/img/replay_*.png``; docs/view.md).

Needs Playwright (``pip install playwright``; its own browser download is not used) and a Chromium
binary: ``$CHROMIUM_PATH``, else ``chromium`` on the PATH, else ``/usr/lib/chromium/chromium``.
"""

from __future__ import annotations

import argparse
import math
import os
import shutil
import sys
import tempfile
from pathlib import Path


def chromium_path() -> str | None:
    """The Chromium binary to drive: ``$CHROMIUM_PATH``, ``chromium`` on the PATH, or Debian's."""
    for cand in (os.environ.get("CHROMIUM_PATH"), shutil.which("chromium"), "/usr/lib/chromium/chromium"):
        if cand and Path(cand).exists():
            return cand
    return None


def still(
    run,
    out,
    t: float | None = None,
    size: tuple[int, int] = (1280, 720),
    follow: str = "tow",
    azimuth_deg: float | None = None,
    elevation_deg: float | None = None,
    distance: float | None = None,
    view_only: bool = False,
) -> Path:
    """Write the PNG ``out`` of the replay of ``run`` at time ``t`` (s; None: mid-run) and return its path.
    Raises InputError for a run folder without a log, RuntimeError without Playwright or Chromium."""
    from .replay import write_replay
    from .run_data import load_run

    rd = load_run(run)
    exe = chromium_path()
    if exe is None:
        raise RuntimeError("no Chromium binary (install Debian's 'chromium' or set CHROMIUM_PATH)")
    try:
        from playwright.sync_api import sync_playwright
    except ImportError:
        raise RuntimeError("stills need the package 'playwright' (pip install playwright)") from None
    out = Path(out)
    out.parent.mkdir(parents=True, exist_ok=True)
    with tempfile.TemporaryDirectory(prefix="oceangnc-still-") as tmp:
        html = write_replay(rd, Path(tmp) / "replay.html")
        with sync_playwright() as p:
            browser = p.chromium.launch(executable_path=exe, headless=True)
            try:
                page = browser.new_page(viewport={"width": size[0], "height": size[1]}, device_scale_factor=1)
                errors: list[str] = []
                page.on("pageerror", lambda e: errors.append(str(e)))
                page.goto(html.resolve().as_uri() + "?paused&aa=1")
                page.wait_for_function("window.replay && window.replay.ready === true", timeout=120_000)
                if errors:
                    raise RuntimeError(f"the replay page failed: {errors[0]}")
                page.evaluate("replay.pause()")
                page.evaluate(f"replay.setFollow({follow!r})")
                t_at = float(rd.t[0] + rd.t[-1]) / 2 if t is None else float(t)
                page.evaluate(f"replay.seek({t_at!r})")
                cam = {}
                if azimuth_deg is not None:
                    cam["az"] = math.radians(azimuth_deg)
                if elevation_deg is not None:
                    cam["el"] = math.radians(elevation_deg)
                if distance is not None:
                    cam["dist"] = float(distance)
                if cam:
                    page.evaluate(f"replay.setOrbit({cam!r})".replace("'", '"'))
                page.wait_for_timeout(200)  # the panels' canvases
                target = page.locator("#view") if view_only else page
                target.screenshot(path=str(out))
            finally:
                browser.close()
    return out


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(prog="python -m oceangnc.view.still", description=__doc__.split("\n\n")[0])
    ap.add_argument("run", help="run folder (holding log.parquet)")
    ap.add_argument("out", help="PNG file to write")
    ap.add_argument("--t", type=float, help="replay time, s (default: the middle of the run)")
    ap.add_argument("--size", default="1280x720", help="page size in CSS pixels, WxH (default 1280x720)")
    ap.add_argument("--follow", default="tow", choices=("tow", "usv", "uuv", "free"), help="camera target")
    ap.add_argument("--azimuth", type=float, help="camera azimuth about the target, deg")
    ap.add_argument("--elevation", type=float, help="camera elevation, deg (-85 to 85)")
    ap.add_argument("--distance", type=float, help="camera distance from the target, m")
    ap.add_argument("--view-only", action="store_true", help="the 3D view alone, without panels and controls")
    a = ap.parse_args(argv)
    from ..errors import InputError

    try:
        w, h = (int(v) for v in a.size.lower().split("x"))
        if not (200 <= w <= 4096 and 200 <= h <= 4096):
            raise ValueError
    except ValueError:
        print(f"error: --size {a.size}: WxH with 200 <= W, H <= 4096", file=sys.stderr)
        return 2
    if a.elevation is not None and not -85 <= a.elevation <= 85:
        print(f"error: --elevation {a.elevation}: allowed range -85 to 85 deg", file=sys.stderr)
        return 2
    if a.distance is not None and not 0.5 <= a.distance <= 1e4:
        print(f"error: --distance {a.distance}: allowed range 0.5 to 10000 m", file=sys.stderr)
        return 2
    try:
        path = still(a.run, a.out, a.t, (w, h), a.follow, a.azimuth, a.elevation, a.distance, a.view_only)
    except (InputError, RuntimeError) as e:
        print(f"error: {e}", file=sys.stderr)
        return 2
    print(f"wrote {path}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
