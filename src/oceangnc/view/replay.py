"""The 3D replay page of a run folder: :func:`write_replay` (one self-contained HTML file, default
``RUN/replay.html``) and :func:`serve` (the same page on 127.0.0.1, three.js served from the
package's ``static/vendor`` folder).

The page is ``static/replay.html`` with three things put in: the run's data (:func:`replay_data`,
JSON whose series are base64 little-endian Float32 arrays, the time column Float64), the page's
code (``static/replay.js``, ``static/replay.css``) and its import map (:func:`import_map`): ``three``
(the vendored ``three.module.min.js``) and ``oceangnc/scene3d`` (``static/scene3d.js``, the frames
and meshes the console's 3D panel shares) as ``data:`` URLs in the written file (so it opens from
disk, offline), or under ``/vendor/`` when served. Nothing is fetched from the network.
"""

from __future__ import annotations

import base64
import json
import sys
from pathlib import Path

import numpy as np

from .mcap_export import extent
from .run_data import RunData, load_run

STATIC = Path(__file__).resolve().parent / "static"
THREE = STATIC / "vendor" / "three.module.min.js"
SCENE3D = STATIC / "scene3d.js"


def _f32(a) -> str:
    return base64.b64encode(np.asarray(a, dtype="<f4").tobytes()).decode("ascii")


def _f64(a) -> str:
    return base64.b64encode(np.asarray(a, dtype="<f8").tobytes()).decode("ascii")


def _panels(rd: RunData) -> list[dict]:
    """The linked time-series panels: UUV depth, USV-UUV distance, cable tension (when logged), else
    the speed of the first vehicle."""
    p = []
    if "uuv.z" in rd.columns:
        p.append({"title": "UUV depth", "unit": "m", "series": [["uuv.z", "depth"]], "invert": True})
    if "lf.range" in rd.columns:
        p.append({"title": "relative distance USV-UUV", "unit": "m", "series": [["lf.range", "range"]]})
    elif {"usv.x", "uuv.x"} <= set(rd.columns):
        p.append({"title": "relative distance USV-UUV", "unit": "m", "series": [["view.rel_distance", "horizontal"]]})
    if rd.cable_tension:
        if rd.cable_tension == ["cable.top_tension", "cable.bottom_tension"]:
            s = [["cable.top_tension", "top"], ["cable.bottom_tension", "bottom"]]
        else:
            s = [[rd.cable_tension[0], "top"], [rd.cable_tension[-1], "bottom"]]
        p.append({"title": "cable tension", "unit": "N", "series": s})
    if not p and rd.bodies:
        b = rd.bodies[0].name
        if f"{b}.speed" in rd.columns:
            p.append({"title": f"{b} speed", "unit": "m/s", "series": [[f"{b}.speed", "speed"]]})
    return p


def replay_data(rd: RunData) -> dict:
    """Everything the page draws, as a JSON-able dict (module docstring)."""
    series: dict[str, np.ndarray] = {}
    for b in rd.bodies:
        for c in b.columns.values():
            if c is not None:
                series[c] = rd.columns[c]
    for a in "xyz":
        for c in rd.node_columns(a):
            series[c] = rd.columns[c]
    for c in rd.cable_tension:
        series[c] = rd.columns[c]
    panels = _panels(rd)
    for p in panels:
        for c, _ in p["series"]:
            if c == "view.rel_distance":
                cs = rd.columns
                series[c] = np.hypot(cs["usv.x"] - cs["uuv.x"], cs["usv.y"] - cs["uuv.y"])
            else:
                series[c] = rd.columns[c]
    n0, n1, e0, e1 = extent(rd)
    return {
        "run": rd.path.name,
        "scenario": str(rd.summary.get("scenario", rd.config.get("scenario", ""))),
        "rows": rd.rows,
        "t": _f64(rd.t),
        "series": {k: _f32(v) for k, v in series.items()},
        "bodies": [
            {"name": b.name, "kind": b.kind, "length": b.length, "width": b.width, "columns": b.columns}
            for b in rd.bodies
        ],
        "cable": {
            "nodes": rd.cable_nodes,
            "tension": rd.cable_tension,
            "tensionMode": (
                "nodes" if len(rd.cable_tension) == rd.cable_nodes else ("ends" if rd.cable_tension else "none")
            ),
        },
        "route": [list(p) for p in rd.route],
        "acceptance": rd.acceptance,
        "seabed": rd.seabed,
        "extent": {"n0": n0, "n1": n1, "e0": e0, "e1": e1},
        "panels": panels,
        "waves": _waves(rd),
    }


def _waves(rd: RunData) -> dict | None:
    """The run's wave components for the page's sea surface (None in calm water): amplitude a (m),
    angular frequency omega (rad/s), wave number k (rad/m), travel direction theta (rad from north) and
    phase eps (rad) of each, as float64 (JSON numbers round-trip them exactly), with Hs, Tp and the
    mean direction of the config for the legend."""
    w = rd.waves
    if w is None:
        return None
    cfg = rd.config["environment"]["waves"]
    return {
        "a": w.a.tolist(),
        "omega": w.omega.tolist(),
        "k": w.k.tolist(),
        "theta": w.theta.tolist(),
        "eps": w.eps.tolist(),
        "kind": str(cfg.get("kind")),
        "hs": float(cfg.get("hs", w.hs())),
        "tp": float(cfg.get("tp", 0.0)),
        "direction_deg": float(cfg.get("direction_deg", 0.0)),
    }


def _json_script(obj) -> str:
    """JSON safe inside a <script> element ("</" and "<!--" cannot occur)."""
    return json.dumps(obj, separators=(",", ":"), allow_nan=False).replace("<", "\\u003c")


def _data_url(path: Path) -> str:
    return "data:text/javascript;base64," + base64.b64encode(path.read_bytes()).decode("ascii")


def import_map(base: str | None = None) -> dict:
    """The import map of the 3D pages: ``three`` and ``oceangnc/scene3d`` (the shared frames and
    meshes, ``static/scene3d.js``), as ``data:`` URLs (``base`` None) or under the URL ``base``."""
    if base is None:
        return {"imports": {"three": _data_url(THREE), "oceangnc/scene3d": _data_url(SCENE3D)}}
    return {"imports": {"three": f"{base}/three.module.min.js", "oceangnc/scene3d": f"{base}/scene3d.js"}}


def vendor_file(name: str) -> Path | None:
    """The path of a servable vendor file, or None (only the names of :data:`VENDOR_FILES`)."""
    return {"three.module.min.js": THREE, "scene3d.js": SCENE3D}.get(name)


def build_html(rd: RunData, base: str | None = None) -> str:
    """The page as a string; ``base`` None: three.js and scene3d.js inlined as data: URLs, else
    imported from ``base`` (the ``--serve`` server's ``/vendor``)."""
    html = (STATIC / "replay.html").read_text()
    title = f"{rd.path.name} - oceangnc replay"
    parts = {
        "@TITLE@": title.replace("&", "&amp;").replace("<", "&lt;"),
        "@CSS@": (STATIC / "replay.css").read_text(),
        "@IMPORTMAP@": _json_script(import_map(base)),
        "@DATA@": _json_script(replay_data(rd)),
        "@APP@": (STATIC / "replay.js").read_text(),
    }
    for k, v in parts.items():
        head, sep, tail = html.partition(k)
        if not sep:
            raise RuntimeError(f"replay.html has no {k}")
        html = head + v + tail
    return html


def write_replay(run: str | Path | RunData, out: str | Path | None = None) -> Path:
    """Write the self-contained replay page of run folder ``run`` (default ``RUN/replay.html``)."""
    from ..core.files import check_output, write_output

    rd = run if isinstance(run, RunData) else load_run(run)
    out = check_output(out if out is not None else rd.path / "replay.html", "replay page", is_replay_page)
    page = build_html(rd).encode("utf-8")
    write_output(out, lambda f: f.write(page))  # a temporary file created exclusively, then renamed
    return out


def is_replay_page(head: bytes) -> bool:
    """True when ``head`` (a file's first bytes) is a replay page this module wrote (``--out`` may
    replace only such a page)."""
    return head.lower().startswith(b"<!doctype html>") and b" - oceangnc replay</title>" in head


def serve(run, port: int = 8060, open_browser: bool = False, out=None, ready=None) -> int:
    """Serve the replay page of ``run`` on http://127.0.0.1:PORT/ until interrupted (0 on Ctrl-C).

    Only three paths answer: ``/`` (the page, importing ``/vendor/three.module.min.js`` and
    ``/vendor/scene3d.js``) and those two files; Host and Origin are checked and the connections bounded
    as :mod:`oceangnc.view.replay_server` says. ``out`` also writes the self-contained file;
    ``ready(port)`` is called once listening (tests)."""
    from .replay_server import make_server

    rd = load_run(run)
    if out is not None:
        write_replay(rd, out)
    page = build_html(rd, base="/vendor").encode()

    def files(path: str):
        if path in ("/", "/index.html", "/replay.html"):
            return page, "text/html; charset=utf-8"
        if path.startswith("/vendor/") and (f := vendor_file(path[len("/vendor/") :])) is not None:
            return f.read_bytes(), "text/javascript; charset=utf-8"
        return None

    # Host and Origin checked, connections and idle time bounded (oceangnc.view.replay_server)
    httpd = make_server(files, port)
    url = f"http://127.0.0.1:{httpd.server_address[1]}/"
    print(f"replay of {rd.path} at {url} (Ctrl-C to stop)", flush=True)
    if ready is not None:
        ready(httpd.server_address[1])
    if open_browser:
        import webbrowser

        webbrowser.open(url)
    try:
        httpd.serve_forever()
    except KeyboardInterrupt:
        print("stopped", file=sys.stderr)
    finally:
        httpd.server_close()
    return 0
