"""Seeing a run (issue 31): the MCAP export read back with the mcap library, the frame conversions,
and the 3D replay page in headless Chromium (docs/view.md).

One short flagship run (``oceangnc run combined-survey --duration 20 --no-plots --mcap``) is shared by
the module; a synthetic run folder (no simulation) covers a geographic origin, a seabed and NaN rows.
"""

from __future__ import annotations

import json
import math
import subprocess
import sys
import tomllib
from pathlib import Path

import numpy as np
import pandas as pd
import pytest

from oceangnc.cli import main
from oceangnc.view import frames
from view_helpers import first_line

mcap_reader = pytest.importorskip("mcap.reader", reason="mcap is not installed (pip install 'oceangnc[view]')")

FOXGLOVE = {"foxglove.PoseInFrame", "foxglove.FrameTransforms", "foxglove.SceneUpdate", "foxglove.LocationFix"}


@pytest.fixture(scope="module")
def flagship(tmp_path_factory) -> Path:
    out = tmp_path_factory.mktemp("view") / "run"
    cmd = [sys.executable, "-m", "oceangnc", "run", "combined-survey", "--duration", "20", "--no-plots", "--quiet"]
    subprocess.run([*cmd, "--out", str(out), "--mcap"], check=True, timeout=600)
    return out


def read_mcap(path: Path) -> tuple[dict, dict[str, list]]:
    """({topic: schema name}, {topic: [(log_time, publish_time, decoded JSON)]})."""
    schemas: dict[str, str] = {}
    msgs: dict[str, list] = {}
    with open(path, "rb") as f:
        for schema, channel, message in mcap_reader.make_reader(f).iter_messages(log_time_order=False):
            schemas[channel.topic] = schema.name
            assert schema.encoding == "jsonschema" and channel.message_encoding == "json"
            row = (message.log_time, message.publish_time, json.loads(message.data))
            msgs.setdefault(channel.topic, []).append(row)
    return schemas, msgs


def _same(a: float, b) -> bool:
    """Equal as JSON round-trips floats (repr), NaN written as null."""
    return (b is None and not math.isfinite(a)) or (b is not None and float(b) == a)


def test_mcap_of_flagship_round_trips(flagship):
    df = pd.read_parquet(flagship / "log.parquet")
    schemas, msgs = read_mcap(flagship / "run.mcap")
    start = json.loads((flagship / "summary.json").read_text())["wall_time_start_unix_s"]  # the run's wall clock
    ns = np.round(df["t"].to_numpy() * 1e9).astype(np.int64) + np.int64(round(start * 1e9))
    # every channel: a Foxglove well-known schema, or the scalar series of one prefix
    for topic, name in schemas.items():
        if topic.startswith("/signals/"):
            assert name == "oceangnc.Signals." + topic.removeprefix("/signals/")
        else:
            assert name in FOXGLOVE, (topic, name)
    assert {"/usv/pose", "/uuv/pose", "/tf", "/scene"} <= set(schemas)
    assert schemas["/usv/pose"] == schemas["/uuv/pose"] == "foxglove.PoseInFrame"
    assert schemas["/scene"] == "foxglove.SceneUpdate"
    for topic, rows in msgs.items():  # one message per log row, stamped with the row's time
        assert [r[0] for r in rows] == ns.tolist(), topic
        assert [r[1] for r in rows] == ns.tolist(), topic
    # every logged signal is in its prefix's channel, values exactly as logged
    seen = set()
    for col in df.columns:
        if col == "t":
            continue
        prefix, name = col.split(".", 1)
        got = [m[2][name] for m in msgs[f"/signals/{prefix}"]]
        assert all(_same(a, b) for a, b in zip(df[col].to_numpy(), got)), col
        seen.add(col)
    assert len(seen) == len(df.columns) - 1
    for m in msgs["/signals/uuv"]:  # stamps in the messages too
        assert m[2]["timestamp"]["sec"] * 10**9 + m[2]["timestamp"]["nsec"] == m[0]

    # poses in ENU: (x, y, z) = (east, north, up)
    k = len(df) // 2
    p = msgs["/uuv/pose"][k][2]
    assert p["frame_id"] == "world"
    pos = p["pose"]["position"]
    assert (pos["x"], pos["y"], pos["z"]) == (df["uuv.y"][k], df["uuv.x"][k], -df["uuv.z"][k])
    q = p["pose"]["orientation"]
    want = frames.enu_flu_quaternion(df["uuv.phi"][k], df["uuv.theta"][k], df["uuv.psi"][k])
    assert np.allclose([q["w"], q["x"], q["y"], q["z"]], want, atol=1e-12)
    # the scene: both vehicles and the cable polyline through every node, last node at the UUV's tow point
    scene = msgs["/scene"][k][2]
    ents = {e["id"]: e for e in scene["entities"]}
    assert {"usv", "uuv", "cable", "route", "sea_surface"} <= set(ents)
    pts = ents["cable"]["lines"][0]["points"]
    assert len(pts) == 21 and len(ents["cable"]["lines"][0]["colors"]) == 21
    assert (pts[-1]["x"], pts[-1]["y"], pts[-1]["z"]) == (df["cable.y20"][k], df["cable.x20"][k], -df["cable.z20"][k])
    tf = msgs["/tf"][k][2]["transforms"]
    assert [t["child_frame_id"] for t in tf] == ["usv", "uuv"]


def test_export_command_and_layout(flagship, tmp_path, capsys):
    out = tmp_path / "x.mcap"
    assert main(["export", str(flagship), "--mcap", "--out", str(out)]) == 0
    assert f"wrote {out}" in capsys.readouterr().out
    assert out.read_bytes()[:8] == (flagship / "run.mcap").read_bytes()[:8] == b"\x89MCAP0\r\n"
    layout = json.loads((Path(frames.__file__).parent / "static" / "foxglove-layout.json").read_text())
    topics = {"/scene", "/usv/pose", "/uuv/pose"}
    assert topics <= set(layout["configById"]["3D!oceangnc"]["topics"])
    schemas, _ = read_mcap(out)
    assert topics <= set(schemas)
    for cfg in layout["configById"].values():  # every plotted path is a signal the export writes
        for p in cfg.get("paths", []):
            topic, _, field = p["value"].rpartition(".")
            topic = topic.split(".")[0]
            assert topic in schemas, p["value"]


def test_export_without_mcap_is_one_line(flagship, tmp_path, capsys, monkeypatch):
    for m in ("mcap", "mcap.writer"):
        monkeypatch.setitem(sys.modules, m, None)
    assert main(["export", str(flagship), "--mcap", "--out", str(tmp_path / "y.mcap")]) == 2
    err = capsys.readouterr().err.strip()
    assert "\n" not in err and "install oceangnc[view]" in err
    assert not (tmp_path / "y.mcap").exists()


def _synthetic_run(path: Path) -> pd.DataFrame:
    """A run folder without a simulation: a USV and a UUV on a circle, a 3-node cable, a NaN gap."""
    from oceangnc.io.logs import LogWriter

    path.mkdir(parents=True)
    t = np.arange(0.0, 5.0, 0.5)
    n = len(t)
    cols = {
        "usv.x": 10 * np.cos(t / 5),
        "usv.y": 10 * np.sin(t / 5),
        "usv.psi": t / 5 + np.pi / 2,
        "uuv.x": 10 * np.cos(t / 5) - 1,
        "uuv.y": 10 * np.sin(t / 5),
        "uuv.z": np.full(n, 4.0),
        "uuv.phi": np.full(n, 0.1),
        "uuv.theta": np.full(n, -0.2),
        "uuv.psi": t / 5 + np.pi / 2,
        "cable.top_tension": 100 + t,
        "cable.bottom_tension": 80 + t,
        "noprefix": t * 2,
    }
    for k in range(3):
        cols[f"cable.x{k}"] = cols["usv.x"] - k * 0.5
        cols[f"cable.y{k}"] = cols["usv.y"]
        cols[f"cable.z{k}"] = np.full(n, 2.0 * k)
    cols["uuv.theta"][3] = np.nan  # a gap in the UUV's attitude
    cols["usv.x"][4] = np.nan
    w = LogWriter(path / "log.parquet")
    for i in range(n):
        w.append(float(t[i]), {k: float(v[i]) for k, v in cols.items()})
    w.close()
    (path / "config.toml").write_text(
        'scenario = "synthetic"\n[mavlink]\norigin_lat_deg = 59.9\norigin_lon_deg = 10.7\n'
        "[environment.seabed]\ndepth = 20.0\nslope_deg = 3.0\n"
        "[guidance]\nwaypoints = [[0.0, 0.0], [10.0, 10.0]]\nacceptance = 2.0\n"
    )
    return pd.read_parquet(path / "log.parquet")


def test_mcap_gps_gaps_and_seabed(tmp_path):
    from oceangnc.io.geo import ned_to_latlon
    from oceangnc.view.mcap_export import export_mcap

    df = _synthetic_run(tmp_path / "syn")
    out = export_mcap(tmp_path / "syn")
    assert out == tmp_path / "syn" / "run.mcap"
    schemas, msgs = read_mcap(out)
    assert schemas["/usv/gps"] == schemas["/uuv/gps"] == "foxglove.LocationFix"
    assert len(msgs["/usv/pose"]) == len(df) - 1  # the row whose x is NaN is skipped...
    assert len(msgs["/uuv/pose"]) == len(df) - 1
    assert len(msgs["/signals/usv"]) == len(df)  # ...but every row's signals are written
    assert msgs["/signals/usv"][4][2]["x"] is None and msgs["/signals/uuv"][3][2]["theta"] is None
    assert [m[2]["noprefix"] for m in msgs["/signals/run"]] == df["noprefix"].tolist()
    fix = msgs["/uuv/gps"][2][2]
    lat, lon = ned_to_latlon(df["uuv.x"][2], df["uuv.y"][2], 59.9, 10.7)
    assert (fix["latitude"], fix["longitude"], fix["altitude"]) == (lat, lon, -4.0)
    ents = {e["id"]: e for e in msgs["/scene"][0][2]["entities"]}
    assert "seabed" in ents and len(ents["cable"]["lines"][0]["points"]) == 3
    bed_z = [p["z"] for p in ents["seabed"]["triangles"][0]["points"]]
    assert max(bed_z) < -15  # 20 m down, 3 deg slope over a few tens of metres
    assert len(ents["route"]["spheres"]) == 2


@pytest.mark.parametrize(
    "phi,theta,psi,fwd,left",
    [
        (0.0, 0.0, 0.0, (0, 1, 0), (-1, 0, 0)),  # heading north: forward = ENU y, port = west
        (0.0, 0.0, np.pi / 2, (1, 0, 0), (0, 1, 0)),  # heading east: port = north
        (0.0, 0.3, 0.0, (0, np.cos(0.3), np.sin(0.3)), (-1, 0, 0)),  # nose up (theta > 0)
        (0.3, 0.0, 0.0, (0, 1, 0), (-np.cos(0.3), 0, np.sin(0.3))),  # starboard down: port goes up
    ],
)
def test_enu_flu_orientation(phi, theta, psi, fwd, left):
    r = frames.quat_matrix(frames.enu_flu_quaternion([phi], [theta], [psi]))[0]
    assert np.allclose(r[:, 0], fwd, atol=1e-12) and np.allclose(r[:, 1], left, atol=1e-12)
    assert np.isclose(np.linalg.det(r), 1.0)


def test_config_of_flagship_has_route(flagship):
    from oceangnc.view.run_data import load_run

    rd = load_run(flagship)
    cfg = tomllib.loads((flagship / "config.toml").read_text())
    assert rd.route == [tuple(w) for w in cfg["guidance"]["waypoints"]]
    assert [b.name for b in rd.bodies] == ["usv", "uuv"] and rd.cable_nodes == 21
    assert rd.cable_tension == ["cable.top_tension", "cable.bottom_tension"]


# ---- the replay page in headless Chromium -----------------------------------------------------------


def _chromium() -> str | None:
    import os
    import shutil

    for cand in (os.environ.get("CHROMIUM_PATH"), shutil.which("chromium"), "/usr/lib/chromium/chromium"):
        if cand and Path(cand).exists():
            return cand
    return None


@pytest.fixture(scope="module")
def browser():
    chromium = _chromium()
    if chromium is None:
        pytest.skip("no Chromium binary (install Debian's 'chromium' or set CHROMIUM_PATH)")
    sync_api = pytest.importorskip("playwright.sync_api", reason="playwright is not installed")
    with sync_api.sync_playwright() as p:
        b = p.chromium.launch(executable_path=chromium, headless=True)
        yield b
        b.close()


@pytest.fixture
def page(browser):
    ctx = browser.new_context(viewport={"width": 1280, "height": 720}, device_scale_factor=1)
    pg = ctx.new_page()
    pg.set_default_timeout(60_000)
    errors: list[str] = []
    pg.on("pageerror", lambda e: errors.append(str(e)))
    yield pg
    ctx.close()
    assert not errors, errors


def _open(page, url: str) -> None:
    page.goto(url)
    page.wait_for_function("window.replay && window.replay.ready === true", timeout=60_000)
    page.evaluate("replay.pause()")


def _project(m: dict, world) -> tuple[float, float]:
    """CSS pixel (from the canvas's corner) of a three.js world point through the page's camera
    matrices (column-major, as three.js stores them), computed here rather than by the page."""
    proj = np.array(m["projection"]).reshape(4, 4).T
    view = np.array(m["view"]).reshape(4, 4).T
    clip = proj @ view @ np.array([*world, 1.0])
    ndc = clip[:3] / clip[3]
    return (ndc[0] + 1) / 2 * m["width"], (1 - ndc[1]) / 2 * m["height"]


T_SEEK = 12.0  # s, a logged row of the 10 Hz log
PX_TOL = 1.5  # px: the drawn mesh/vertex against the logged position through the same camera


@pytest.mark.browser
def test_replay_draws_uuv_and_cable_end_at_logged_positions(flagship, page, tmp_path):
    from PIL import Image

    assert main(["view", str(flagship)]) == 0
    html = flagship / "replay.html"
    text = html.read_text()
    assert "three.module" not in text.split('<script type="importmap">')[1][:60]  # inlined, not a file URL
    assert "http://" not in text.split('<script type="module">')[1]  # nothing fetched
    _open(page, html.as_uri())
    df = pd.read_parquet(flagship / "log.parquet")
    row = df.index[np.isclose(df["t"], T_SEEK)][0]
    assert page.evaluate(f"replay.seek({T_SEEK})") == T_SEEK
    st = page.evaluate("({uuv: replay.uuv, end: replay.cableEnd, layers: replay.layers, t: replay.t})")
    assert st["t"] == T_SEEK
    assert {"usv", "uuv", "cable", "usv_trail", "uuv_trail", "route", "sea"} <= set(st["layers"])
    uuv_ned = df.loc[row, ["uuv.x", "uuv.y", "uuv.z"]].to_numpy(float)
    end_ned = df.loc[row, ["cable.x20", "cable.y20", "cable.z20"]].to_numpy(float)
    # the page's state: the logged positions (Float32 in the page), in three.js as ned_to_three maps them
    assert np.allclose(st["uuv"]["ned"], uuv_ned, rtol=0, atol=1e-5)
    assert np.allclose(st["end"]["ned"], end_ned, rtol=0, atol=1e-5)
    assert np.allclose(st["uuv"]["world"], frames.ned_to_three(*uuv_ned), atol=1e-5)
    assert np.allclose(st["end"]["world"], frames.ned_to_three(*end_ned), atol=1e-5)
    # on screen: the drawn UUV mesh and last cable vertex where the logged positions project
    m = page.evaluate("replay.cameraMatrices()")
    drawn_uuv = page.evaluate("replay.projectObject('uuv')")
    drawn_end = page.evaluate("replay.projectObject('cableEnd')")
    want_uuv = _project(m, frames.ned_to_three(*uuv_ned))
    want_end = _project(m, frames.ned_to_three(*end_ned))
    assert np.hypot(drawn_uuv[0] - want_uuv[0], drawn_uuv[1] - want_uuv[1]) < PX_TOL, (drawn_uuv, want_uuv)
    assert np.hypot(drawn_end[0] - want_end[0], drawn_end[1] - want_end[1]) < PX_TOL, (drawn_end, want_end)
    assert 0 < want_uuv[0] < m["width"] and 0 < want_uuv[1] < m["height"]  # in view (the camera follows)
    # a screenshot: the pixel where the UUV projects is not the background, and it changes with the UUV hidden
    clip = {"x": m["left"], "y": m["top"], "width": m["width"], "height": m["height"]}
    page.screenshot(path=str(tmp_path / "with.png"), clip=clip)
    page.evaluate("replay.setVisible('uuv', false)")
    page.screenshot(path=str(tmp_path / "without.png"), clip=clip)
    page.evaluate("replay.setVisible('uuv', true)")
    px = (int(want_uuv[0]), int(want_uuv[1]))
    with_uuv = Image.open(tmp_path / "with.png").convert("RGB").getpixel(px)
    without = Image.open(tmp_path / "without.png").convert("RGB").getpixel(px)
    bg = tuple(int(page.evaluate("replay.background")[i : i + 2], 16) for i in (1, 3, 5))
    assert with_uuv != bg and with_uuv != without, (with_uuv, without, bg)
    # between two rows the page interpolates linearly
    t_mid = T_SEEK + 0.05
    page.evaluate(f"replay.seek({t_mid})")
    mid = np.array(page.evaluate("replay.uuv.ned"))
    nxt = df.loc[row + 1, ["uuv.x", "uuv.y", "uuv.z"]].to_numpy(float)
    a = (t_mid - T_SEEK) / (df["t"][row + 1] - T_SEEK)
    assert np.allclose(mid, uuv_ned + a * (nxt - uuv_ned), atol=1e-4)


@pytest.mark.browser
def test_replay_plays_and_scrubs(flagship, page):
    from oceangnc.view.replay import write_replay

    html = write_replay(flagship, flagship / "replay-play.html")
    _open(page, html.as_uri() + "?paused")
    assert page.evaluate("replay.playing") is False and page.evaluate("replay.t") == 0.0
    page.evaluate("replay.setSpeed(10); replay.play()")
    page.wait_for_function("replay.t > 2", timeout=60_000)
    page.evaluate("replay.pause()")
    t = page.evaluate("replay.t")
    page.wait_for_timeout(300)
    assert page.evaluate("replay.t") == t  # paused stays
    page.fill("#scrub", "500")  # the slider: half way
    page.dispatch_event("#scrub", "input")
    assert abs(page.evaluate("replay.t") - 10.0) < 1e-9
    assert page.inner_text("#time").startswith("t = 10.00")
    assert page.locator("#panels canvas").count() == 3  # depth, distance, tension
    box = page.locator("#panels canvas").first.bounding_box()
    page.mouse.click(box["x"] + 40 + (box["width"] - 48) * 0.25, box["y"] + box["height"] / 2)  # click a panel
    assert abs(page.evaluate("replay.t") - 5.0) < 0.2


@pytest.mark.browser
def test_view_serve_on_loopback(flagship, page):
    import os

    proc = subprocess.Popen(
        [sys.executable, "-m", "oceangnc", "view", str(flagship), "--serve", "--port", "0"],
        stdout=subprocess.PIPE,
        text=True,
        env=dict(os.environ, PYTHONUNBUFFERED="1"),
    )
    try:
        line = first_line(proc, 120)
        assert " at http://127.0.0.1:" in line, line
        url = line.split(" at ", 1)[1].split()[0]
        _open(page, url)
        assert page.evaluate("replay.rows") == len(pd.read_parquet(flagship / "log.parquet"))
        assert page.evaluate("document.querySelector('script[type=importmap]').textContent").count("/vendor/") == 2
        assert page.request.get(url + "nothing").status == 404
    finally:
        proc.terminate()
        proc.wait(timeout=30)


def _usv_only_run(path: Path) -> None:
    """A surface vessel alone (no UUV, no cable, no config): as 'oceangnc import' writes."""
    from oceangnc.io.logs import LogWriter

    path.mkdir(parents=True)
    w = LogWriter(path / "log.parquet")
    for t in np.arange(0.0, 3.0, 0.1):
        w.append(float(t), {"usv.x": 0.5 * t, "usv.y": 0.1 * t, "usv.psi": 0.2, "usv.speed": 0.5})
    w.close()


def test_mcap_of_a_run_without_cable(tmp_path):
    from oceangnc.view.mcap_export import export_mcap

    _usv_only_run(tmp_path / "usv")
    schemas, msgs = read_mcap(export_mcap(tmp_path / "usv"))
    assert set(schemas) == {"/usv/pose", "/tf", "/scene", "/signals/usv"}
    assert {e["id"] for e in msgs["/scene"][0][2]["entities"]} == {"usv", "sea_surface"}
    assert len(msgs["/scene"]) == 30
    assert not list((tmp_path / "usv").glob("*.part"))


@pytest.mark.browser
def test_replay_of_other_runs(tmp_path, page):
    """A synthetic tow (3 nodes, seabed, route, a NaN row) and a lone USV open without page errors."""
    _synthetic_run(tmp_path / "syn")
    _usv_only_run(tmp_path / "usv")
    assert main(["view", str(tmp_path / "syn"), "--out", str(tmp_path / "syn.html")]) == 0
    assert main(["view", str(tmp_path / "usv")]) == 0
    _open(page, (tmp_path / "syn.html").as_uri())
    page.evaluate("replay.seek(2.5)")
    assert {"seabed", "route", "cable", "usv", "uuv"} <= set(page.evaluate("replay.layers"))
    page.evaluate("replay.seek(2.0)")  # the row whose usv.x is NaN: the USV is hidden
    assert "usv" not in page.evaluate("replay.layers")
    assert page.locator("#panels canvas").count() == 3  # depth, horizontal distance (no lf.range), tension
    page.evaluate("replay.seek(1.5)")  # the row whose UUV pitch is NaN: the UUV is hidden, no error
    assert "uuv" not in page.evaluate("replay.layers")
    _open(page, (tmp_path / "usv" / "replay.html").as_uri())
    page.evaluate("replay.seek(1.0)")
    assert page.evaluate("replay.uuv") is None and page.evaluate("replay.cableEnd") is None
    assert np.allclose(page.evaluate("replay.bodies.usv.ned"), [0.5, 0.1, 0.0], atol=1e-6)
    assert page.locator("#panels canvas").count() == 1  # the USV's speed


# ---- waves on the sea surface --------------------------------------------------------------------


@pytest.fixture(scope="module")
def sea(tmp_path_factory) -> Path:
    """A short irregular-sea tow: JONSWAP Hs 1 m, Tp 6 s, 128 components (the scenario's defaults), the
    USV's own wave motions off (issue 29 part A: the tow point heaves with the surface, z0 = z_top - eta)."""
    out = tmp_path_factory.mktemp("view") / "sea"
    cmd = [sys.executable, "-m", "oceangnc", "run", "tow-sea-state", "--duration", "10", "--no-plots", "--quiet"]
    cmd += ["--set", "environment.usv_motions.enabled=false"]
    subprocess.run([*cmd, "--out", str(out)], check=True, timeout=600)
    return out


@pytest.mark.browser
def test_replay_sea_surface_is_the_runs_wave_field(sea, page):
    """The page's sea surface is a second implementation of the Airy elevation sum of
    oceangnc/environment/waves.py (docs/view.md, "Waves"). Two checks:

    * round trip / same law: the page's elevation (double precision, ``replay.seaElevation``) at points
      and times, and the drawn patch's heights (its angle-addition form, the mesh's single precision),
      equal ``WaveField.kinematics`` of the run's field (drawn again here from config.toml and sim.seed)
      within 1e-6 Hs;
    * against the simulation itself: with the USV's wave motions off, the cable's top point heaves with the
      wave elevation at the USV (``tow_point_heave = "surface"``: z0 = z_top - eta, models/_combined_sea.py),
      so the logged ``cable.z0`` plus the page's elevation at the logged (``cable.x0``, ``cable.y0``) is
      constant (z_top) within 1 mm (the plant's second-order expansion of eta, its docstring: <= 1e-2
      of the smallest components; 3e-5 m here) - a wrong seed or phase would leave the sea's own 0.23 m (Hs / 4) spread.
    """
    from oceangnc.environment import SeaEnvironmentConfig

    cfg = tomllib.loads((sea / "config.toml").read_text())
    field = SeaEnvironmentConfig.model_validate(cfg["environment"]).plant_kwargs(cfg["sim"]["seed"])["waves"]
    hs = cfg["environment"]["waves"]["hs"]
    assert main(["view", str(sea)]) == 0
    _open(page, (sea / "replay.html").as_uri())
    info = page.evaluate("replay.waves")
    assert info["count"] == field.a.size == 128 and info["hs"] == hs
    assert "sea" in page.evaluate("replay.layers")
    pts = [(0.0, 0.0, 0.0), (13.7, -4.2, 5.5), (-250.3, 80.1, 9.95), (40.0, 1000.0, 123.4)]
    for n, e, t in pts:
        got = page.evaluate(f"replay.seaElevation({n}, {e}, {t})")
        want = field.kinematics(t, [[n, e, 0.0]])[0][0]
        assert abs(got - want) <= 1e-6 * hs, (n, e, t, got, want)
    for t in (2.0, 7.35):
        page.evaluate(f"replay.seek({t})")
        patch = page.evaluate("replay.seaPatch()")
        assert patch["t"] == t
        g1 = patch["cells"] + 1
        i, j = np.meshgrid(np.arange(g1), np.arange(g1), indexing="ij")
        n = patch["n0"] + i.ravel() * patch["step"]
        e = patch["e0"] + j.ravel() * patch["step"]
        want = field.kinematics(t, np.c_[n, e, np.zeros_like(n)])[0]
        assert np.ptp(want) > 0.5 * hs  # a sea, not a flat plane
        assert np.abs(np.array(patch["eta"]) - want).max() <= 1e-6 * hs
        assert np.abs(np.array(patch["drawn"]) - want).max() <= 1e-6 * hs
        # the patch is centred on the vehicles the camera follows (within a grid step)
        mid = np.mean([b["ned"][:2] for b in page.evaluate("replay.bodies").values()], axis=0)
        centre = (patch["n0"] + patch["step"] * patch["cells"] / 2, patch["e0"] + patch["step"] * patch["cells"] / 2)
        assert np.hypot(centre[0] - mid[0], centre[1] - mid[1]) <= patch["step"]
    df = pd.read_parquet(sea / "log.parquet")
    rows = df[df["t"] > 0].iloc[::5]  # (the row at t = 0 is the initial state, before the first sea update)
    js = "replay.seaElevation({0}, {1}, {2})"
    eta = np.array([page.evaluate(js.format(r["cable.x0"], r["cable.y0"], r["t"])) for _, r in rows.iterrows()])
    z_top = rows["cable.z0"].to_numpy() + eta
    assert np.std(rows["cable.z0"]) > 0.1 * hs  # the top point heaves
    assert np.ptp(z_top) < 1e-3 * hs, np.ptp(z_top)


@pytest.mark.browser
def test_still_of_a_run(sea, tmp_path, capsys):
    """`python -m oceangnc.view.still RUN OUT.png`: the replay drawn by headless Chromium at a set time and
    camera (how the gallery's stills are made); the PNG has the page's size and shows the sea, not the
    background alone; the 3D view alone is smaller; bad options are one line and exit 2."""
    from PIL import Image

    from oceangnc.view import still

    if still.chromium_path() is None:
        pytest.skip("no Chromium binary")
    out = tmp_path / "s.png"
    # in a process of its own (this module's browser fixture keeps Playwright's event loop in this thread)
    cmd = [sys.executable, "-m", "oceangnc.view.still", str(sea)]
    subprocess.run([*cmd, str(out), "--t", "6", "--elevation", "20", "--distance", "40"], check=True, timeout=300)
    img = Image.open(out).convert("RGB")
    assert img.size == (1280, 720)
    colours = img.resize((64, 36)).getcolors(64 * 36)
    assert colours is not None and len(colours) > 50  # a drawn scene, not a blank page
    subprocess.run([*cmd, str(tmp_path / "v.png"), "--view-only", "--size", "800x600"], check=True, timeout=300)
    w, h = Image.open(tmp_path / "v.png").size
    assert w < 800 and h < 600  # the 3D view without the panels and the bar
    capsys.readouterr()
    assert still.main([str(sea), str(out), "--size", "10x10"]) == 2
    assert still.main([str(sea), str(out), "--elevation", "95"]) == 2
    assert still.main([str(tmp_path / "nothing"), str(out)]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 3 and all(e.startswith("error: ") for e in err), err


# ---- the Foxglove WebSocket stream ------------------------------------------------------------------


def test_foxglove_websocket_stream(flagship):
    """`oceangnc view RUN --foxglove` on 127.0.0.1 (10x, looping): a client subscribes over foxglove.websocket.v1 and
    receives the poses and signals of the logged rows, stamped with their times, values as logged."""
    import os
    import struct

    ws_client = pytest.importorskip("websockets.sync.client", reason="websockets is not installed")
    df = pd.read_parquet(flagship / "log.parquet")
    start = json.loads((flagship / "summary.json").read_text())["wall_time_start_unix_s"]  # the run's wall clock
    ns = (np.round(df["t"].to_numpy() * 1e9).astype(np.int64) + np.int64(round(start * 1e9))).tolist()
    cmd = [sys.executable, "-m", "oceangnc", "view", str(flagship), "--foxglove", "--port", "0"]
    proc = subprocess.Popen(
        [*cmd, "--speed", "10"], stdout=subprocess.PIPE, text=True, env=dict(os.environ, PYTHONUNBUFFERED="1")
    )
    try:
        line = first_line(proc, 120)
        assert "at ws://127.0.0.1:" in line, line
        url = line.split(" at ", 1)[1].split()[0]
        # the synchronous client (this module's browser fixture keeps an event loop in this thread)
        with ws_client.connect(url, subprotocols=["foxglove.websocket.v1"], open_timeout=30) as ws:
            assert ws.subprotocol == "foxglove.websocket.v1"
            info = json.loads(ws.recv(timeout=30))
            adv = json.loads(ws.recv(timeout=30))
            chans = {c["topic"]: c for c in adv["channels"]}
            subs = {"/uuv/pose": 7, "/signals/uuv": 8}
            sub = [{"id": s, "channelId": chans[t]["id"]} for t, s in subs.items()]
            ws.send(json.dumps({"op": "subscribe", "subscriptions": sub}))
            got: dict[int, list] = {7: [], 8: []}
            times = []
            while len(got[8]) < 40:  # bounded: 40 rows of the 201
                frame = ws.recv(timeout=30)
                assert isinstance(frame, bytes)
                if frame[0] == 0x02:
                    times.append(struct.unpack("<Q", frame[1:9])[0])
                    continue
                assert frame[0] == 0x01
                sid, ts = struct.unpack("<IQ", frame[1:13])
                got[sid].append((ts, json.loads(frame[13:])))
    finally:
        proc.terminate()
        proc.wait(timeout=30)
    assert info["op"] == "serverInfo" and "time" in info["capabilities"]
    schemas, _ = read_mcap(flagship / "run.mcap")  # the same channels and schemas as the MCAP export
    assert {t: c["schemaName"] for t, c in chans.items()} == schemas
    assert all(c["encoding"] == "json" and c["schemaEncoding"] == "jsonschema" for c in chans.values())
    assert json.loads(chans["/scene"]["schema"])["title"] == "foxglove.SceneUpdate"
    # from the first row after subscribing, every row in order (the stream starts again after the last)
    n = len(ns)
    k0 = ns.index(got[8][0][0])
    assert [ts for ts, _ in got[8]] == [ns[(k0 + j) % n] for j in range(len(got[8]))]
    assert [ts for ts, _ in got[7]][: len(got[8]) - 1] == [ns[(k0 + j) % n] for j in range(len(got[8]) - 1)]
    for ts, m in got[8]:
        row = ns.index(ts)
        assert m["z"] == df["uuv.z"][row] and m["psi"] == df["uuv.psi"][row]
    ts, pose = got[7][-1]
    row = ns.index(ts)
    p = pose["pose"]["position"]
    assert (p["x"], p["y"], p["z"]) == (df["uuv.y"][row], df["uuv.x"][row], -df["uuv.z"][row])
    assert {ns[(k0 + j) % n] for j in range(30)} <= set(times)


def test_foxglove_origin_rules():
    from oceangnc.view.foxglove_ws import origin_allowed

    assert origin_allowed(None) and origin_allowed("https://app.foxglove.dev")
    assert origin_allowed("http://127.0.0.1:3000") and origin_allowed("http://localhost:8080")
    assert not origin_allowed("https://evil.example") and not origin_allowed("null")
    assert origin_allowed("https://lichtblick.example", ("https://lichtblick.example",))
