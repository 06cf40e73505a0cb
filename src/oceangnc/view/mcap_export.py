"""A run folder as an MCAP file for Foxglove, Lichtblick and the ROS 2 tools: :func:`export_mcap`.

Every message is JSON (``message_encoding = "json"``) with a JSON Schema (``jsonschema``) and has
``log_time = publish_time`` = the run's wall-clock start plus ``round(t * 1e9)`` ns, t the log's time
column (:func:`stamps_ns`: a run's or MAVLink session's start from summary.json, an imported log's own
clock from import.json; a folder that records none starts at the Unix epoch). One message per log row
on each channel:

=====================  =========================  ================================================
topic                  schema                     content
=====================  =========================  ================================================
``/<body>/pose``       foxglove.PoseInFrame       pose of each vehicle (``usv``, ``uuv``, ``ship``)
                                                  in frame ``world``
``/tf``                foxglove.FrameTransforms   ``world`` -> ``<body>`` for every vehicle
``/scene``             foxglove.SceneUpdate       hulls, torpedo, cable polyline coloured by
                                                  tension, route and waypoints, seabed, sea surface
``/<body>/gps``        foxglove.LocationFix       when the run has lat/lon columns or a geographic
                                                  origin (``mavlink.origin_lat_deg``, an import's
                                                  ``origin_deg``): the fix of each vehicle (from
                                                  ``x``/``y`` and the origin): Foxglove's Map panel
``/signals/<prefix>``  oceangnc.Signals.<prefix>  every numeric column ``<prefix>.<name>`` of the
                                                  log as field ``<name>`` (NaN written as null)
=====================  =========================  ================================================

Frames: ``world`` is ENU (x east, y north, z up, origin at the simulation's NED origin) and each
vehicle frame is FLU (x forward, y port, z up), REP 103 as Foxglove and rviz expect;
:mod:`oceangnc.view.frames`. Scalar series keep the log's own NED/FRD values and SI units.
Rows where a vehicle's pose is not finite are skipped on its pose, tf and GPS channels (an imported
log's gaps); the scene then leaves that vehicle out.
"""

from __future__ import annotations

import json
import math
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from .foxglove_schemas import schema_bytes, signals_schema
from .frames import enu_flu_quaternion, ned_to_enu, qmul
from .run_data import RunData, load_run

#: quaternion (w, x, y, z) turning a Foxglove cylinder's axis (z) onto the body's x axis (+90 deg about y)
_Q_CYL = np.array([math.sqrt(0.5), 0.0, math.sqrt(0.5), 0.0])

COLORS = {
    "usv": (0.85, 0.85, 0.9, 1.0),
    "ship": (0.7, 0.25, 0.2, 1.0),
    "uuv": (1.0, 0.75, 0.1, 1.0),
    "route": (0.2, 0.9, 0.4, 1.0),
    "waypoint": (0.2, 0.9, 0.4, 0.25),
    "seabed": (0.55, 0.45, 0.3, 0.9),
    "sea": (0.1, 0.4, 0.7, 0.25),
}


class MissingMcap(ImportError):
    """The optional package ``mcap`` is not installed."""


def require_mcap():
    """Import :mod:`mcap.writer`, or raise :class:`MissingMcap` with the one-line install hint."""
    try:
        from mcap import writer
    except ImportError:
        raise MissingMcap("MCAP export needs the optional package 'mcap': install oceangnc[view]") from None
    return writer


def _time(ns: int) -> dict:
    return {"sec": ns // 1_000_000_000, "nsec": ns % 1_000_000_000}


def _vec(x, y, z) -> dict:
    return {"x": x, "y": y, "z": z}


def _quat(q) -> dict:
    return {"x": q[1], "y": q[2], "z": q[3], "w": q[0]}


def _color(c) -> dict:
    return {"r": c[0], "g": c[1], "b": c[2], "a": c[3]}


def tension_color(frac: float) -> tuple[float, float, float, float]:
    """Colour of a tension as a fraction of the run's largest: blue (0) - green - yellow - red (1)."""
    f = min(max(frac, 0.0), 1.0)
    stops = ((0.0, (0.15, 0.35, 1.0)), (0.35, (0.1, 0.85, 0.55)), (0.7, (1.0, 0.85, 0.1)), (1.0, (1.0, 0.15, 0.1)))
    for (f0, c0), (f1, c1) in zip(stops, stops[1:]):
        if f <= f1:
            a = (f - f0) / (f1 - f0)
            return (c0[0] + a * (c1[0] - c0[0]), c0[1] + a * (c1[1] - c0[1]), c0[2] + a * (c1[2] - c0[2]), 1.0)
    return (*stops[-1][1], 1.0)


def node_tensions(rd: RunData) -> np.ndarray | None:
    """Tension at every cable node (rows x nodes, N): the logged per-node tensions, or the end
    tensions interpolated linearly along the nodes (an approximation: the weight and drag of the
    cable make the true profile differ), or None without tension columns."""
    if not rd.cable_tension:
        return None
    cols = [rd.col(c, np.nan) for c in rd.cable_tension]
    if len(cols) == rd.cable_nodes:
        return np.stack(cols, axis=1)
    top, bottom = cols[0], cols[-1]
    s = np.linspace(0.0, 1.0, rd.cable_nodes)
    return top[:, None] * (1 - s) + bottom[:, None] * s


def _plane(corners_enu, color) -> dict:
    pts = [_vec(*p) for p in corners_enu]
    return {
        "pose": {"position": _vec(0.0, 0.0, 0.0), "orientation": _quat((1.0, 0.0, 0.0, 0.0))},
        "points": [pts[0], pts[1], pts[2], pts[0], pts[2], pts[3]],
        "color": _color(color),
        "colors": [],
        "indices": [],
    }


def extent(rd: RunData, margin: float | None = None) -> tuple[float, float, float, float]:
    """(n_min, n_max, e_min, e_max) of the vehicles' tracks and the route, widened by ``margin`` m
    (default: 10 m or twice the longest vehicle)."""
    if margin is None:
        margin = max([10.0] + [2.0 * b.length for b in rd.bodies])
    ns, es = [], []
    for b in rd.bodies:
        ns.append(rd.col(b.columns["x"]))
        es.append(rd.col(b.columns["y"]))
    if rd.route:
        ns.append(np.array([p[0] for p in rd.route]))
        es.append(np.array([p[1] for p in rd.route]))
    n = np.concatenate(ns) if ns else np.zeros(1)
    e = np.concatenate(es) if es else np.zeros(1)
    n, e = n[np.isfinite(n)], e[np.isfinite(e)]
    if not len(n):
        n = e = np.zeros(1)
    return float(n.min() - margin), float(n.max() + margin), float(e.min() - margin), float(e.max() + margin)


def _static_entities(rd: RunData, ext: tuple[float, float, float, float] | None = None) -> list[dict]:
    """Route, waypoints, seabed and sea surface: the same in every scene message (``ext``: the extent
    of the whole run when ``rd`` is a part of it)."""
    out: list[dict] = []
    n0, n1, e0, e1 = extent(rd) if ext is None else ext
    sea = [(e0, n0, 0.0), (e1, n0, 0.0), (e1, n1, 0.0), (e0, n1, 0.0)]
    out.append({"id": "sea_surface", "triangles": [_plane(sea, COLORS["sea"])]})
    if rd.seabed:
        corners = [(n0, e0), (n0, e1), (n1, e1), (n1, e0)]
        bed = [(e, n, -float(rd.seabed_depth(n, e))) for n, e in corners]
        out.append({"id": "seabed", "triangles": [_plane(bed, COLORS["seabed"])]})
    if rd.route:
        ident = {"position": _vec(0.0, 0.0, 0.0), "orientation": _quat((1.0, 0.0, 0.0, 0.0))}
        line = {
            "type": 0,
            "pose": ident,
            "thickness": 2.0,
            "scale_invariant": True,
            "points": [_vec(e, n, 0.0) for n, e in rd.route],
            "color": _color(COLORS["route"]),
            "colors": [],
            "indices": [],
        }
        r = 2.0 * (rd.acceptance or 1.0)
        spheres = [
            {
                "pose": {"position": _vec(e, n, 0.0), "orientation": _quat((1.0, 0.0, 0.0, 0.0))},
                "size": _vec(r, r, 0.2),
                "color": _color(COLORS["waypoint"]),
            }
            for n, e in rd.route
        ]
        out.append({"id": "route", "lines": [line], "spheres": spheres})
    return out


def _body_arrays(rd: RunData, b) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """ENU positions (rows x 3), FLU orientations (rows x 4, w x y z) and a finite-row mask."""
    c = b.columns
    x, y, z = ned_to_enu(rd.col(c["x"]), rd.col(c["y"]), rd.col(c["z"]))
    pos = np.stack([x, y, z], axis=1)
    q = enu_flu_quaternion(rd.col(c["phi"]), rd.col(c["theta"]), rd.col(c["psi"]))
    ok = np.isfinite(pos).all(axis=1) & np.isfinite(q).all(axis=1)
    return pos, q, ok


def _body_entity(b, pos, q, rot) -> dict:
    """Scene entity of a vehicle at ENU position ``pos``, orientation ``q`` (matrix ``rot``)."""
    if b.kind == "torpedo":
        L, D = b.length, b.width
        qc = qmul(q, _Q_CYL).tolist()

        def at(dx):
            p = pos + rot[:, 0] * dx
            return _vec(float(p[0]), float(p[1]), float(p[2]))

        col = _color(COLORS.get(b.name, COLORS["uuv"]))
        return {
            "id": b.name,
            "cylinders": [
                {
                    "pose": {"position": at(-0.1 * L), "orientation": _quat(qc)},
                    "size": _vec(D, D, 0.8 * L),
                    "bottom_scale": 1.0,
                    "top_scale": 1.0,
                    "color": col,
                },
                {
                    "pose": {"position": at(0.4 * L), "orientation": _quat(qc)},
                    "size": _vec(D, D, 0.2 * L),
                    "bottom_scale": 1.0,
                    "top_scale": 0.0,
                    "color": col,
                },
            ],
        }
    h = 0.35 * b.width
    p = pos + rot[:, 2] * (0.5 * h - 0.1 * h)  # mostly above the water line
    return {
        "id": b.name,
        "cubes": [
            {
                "pose": {"position": _vec(*(float(v) for v in p)), "orientation": _quat(q.tolist())},
                "size": _vec(b.length, b.width, h),
                "color": _color(COLORS.get(b.name, COLORS["usv"])),
            }
        ],
    }


def _signal_groups(rd: RunData) -> dict[str, list[tuple[str, str]]]:
    """prefix -> [(field, column)] of every numeric column but ``t`` (a column without a prefix goes
    to the group ``run``)."""
    groups: dict[str, list[tuple[str, str]]] = {}
    for c in rd.columns:
        if c == "t":
            continue
        prefix, _, name = c.partition(".") if "." in c else ("run", "", c)
        groups.setdefault(prefix, []).append((name, c))
    return groups


def _json(obj) -> bytes:
    return json.dumps(obj, separators=(",", ":"), allow_nan=False).encode()


@dataclass
class Channel:
    """One topic of the export: its schema and one JSON payload per log row (None: no message)."""

    topic: str
    schema_name: str
    schema: bytes  # JSON Schema document
    payloads: list[bytes | None]


@dataclass
class Whole:
    """What the messages of one part of a run take from the whole run: the extent of the tracks (the
    sea and seabed planes), the largest cable tension (its colour scale) and the time shift (ns)."""

    extent: tuple[float, float, float, float]
    tmax: float
    shift: int

    @classmethod
    def of(cls, parts) -> Whole | None:
        """Reduced over the :class:`RunData` parts of a run (None when there is none)."""
        w = None
        for rd in parts:
            ten = node_tensions(rd)
            tmax = float(np.nanmax(ten)) if ten is not None and np.isfinite(ten).any() else 0.0
            ns = _row_ns(rd)
            shift = int(ns.min()) if len(ns) and ns.min() < 0 else 0
            e = extent(rd) if rd.rows else None
            if w is None:
                w = cls(e or (0.0, 0.0, 0.0, 0.0), tmax, shift)
                w._empty = e is None
                continue
            if e is not None:
                a = w.extent
                w.extent = e if w._empty else (min(a[0], e[0]), max(a[1], e[1]), min(a[2], e[2]), max(a[3], e[3]))
                w._empty = False
            w.tmax, w.shift = max(w.tmax, tmax), min(w.shift, shift)
        return w

    _empty = False


def _row_ns(rd: RunData) -> np.ndarray:
    """The run's wall-clock start (:attr:`RunData.start_unix_s`: a run's or MAVLink session's start, an
    imported log's own clock; the UNIX epoch when none is recorded) plus round(t 1e9), ns."""
    start = 0 if rd.start_unix_s is None else round(rd.start_unix_s * 1e9)
    return np.round(rd.t * 1e9).astype(np.int64) + np.int64(start)


def stamps_ns(rd: RunData, shift: int | None = None) -> np.ndarray:
    """Message times (ns) of the log rows (:func:`_row_ns`), shifted to start at 0 if negative (MCAP times
    are unsigned); ``shift``: the whole run's (:class:`Whole`) when ``rd`` is a part of it."""
    ns = _row_ns(rd)
    if shift is not None:
        return ns - shift
    return ns - ns.min() if np.any(ns < 0) else ns


def build_channels(rd: RunData, whole: Whole | None = None) -> list[Channel]:
    """Every channel of the export (module docstring) with its messages, for MCAP or a live stream;
    ``whole``: what a part of a run takes from the whole run (the export streams a log in parts)."""
    stamps = [_time(int(v)) for v in stamps_ns(rd, whole.shift if whole else None)]
    out: list[Channel] = []

    def channel(topic: str, schema: str, payloads: list[bytes | None]) -> None:
        out.append(Channel(topic, schema, schema_bytes(schema), payloads))

    # poses, transforms, GPS
    body_data = {b.name: _body_arrays(rd, b) for b in rd.bodies}
    rots = {name: _rotations(q) for name, (_, q, _) in body_data.items()}
    tf_rows: list[list[dict]] = [[] for _ in range(rd.rows)]
    for b in rd.bodies:
        pos, q, ok = body_data[b.name]
        pl, ql = pos.tolist(), q.tolist()
        payloads: list[bytes | None] = []
        for i in range(rd.rows):
            if not ok[i]:
                payloads.append(None)
                continue
            pose = {"position": _vec(*pl[i]), "orientation": _quat(ql[i])}
            payloads.append(_json({"timestamp": stamps[i], "frame_id": "world", "pose": pose}))
            tf_rows[i].append(
                {
                    "timestamp": stamps[i],
                    "parent_frame_id": "world",
                    "child_frame_id": b.name,
                    "translation": pose["position"],
                    "rotation": pose["orientation"],
                }
            )
        channel(f"/{b.name}/pose", "foxglove.PoseInFrame", payloads)
    if rd.bodies:
        channel("/tf", "foxglove.FrameTransforms", [_json({"transforms": tr}) if tr else None for tr in tf_rows])
    for topic, payloads in _gps_messages(rd, stamps):
        channel(topic, "foxglove.LocationFix", payloads)

    # the 3D scene
    static = _static_entities(rd, whole.extent if whole else None)
    tension = node_tensions(rd)
    tmax = float(np.nanmax(tension)) if tension is not None and np.isfinite(tension).any() else 0.0
    if whole is not None:
        tmax = whole.tmax
    if rd.cable_nodes:
        cx, cy, cz = (np.stack([rd.col(c, np.nan) for c in rd.node_columns(a)], axis=1) for a in "xyz")
        ce, cn, cu = ned_to_enu(cx, cy, cz)
    scene: list[bytes | None] = []
    for i in range(rd.rows):
        ents = []
        for b in rd.bodies:
            pos, q, ok = body_data[b.name]
            if ok[i]:
                ents.append(_body_entity(b, pos[i], q[i], rots[b.name][i]))
        if rd.cable_nodes:
            pts, cols = [], []
            for k in range(rd.cable_nodes):
                p = (float(ce[i, k]), float(cn[i, k]), float(cu[i, k]))
                if not all(math.isfinite(v) for v in p):
                    continue  # a node not in use (winch)
                pts.append(_vec(*p))
                tk = tension[i, k] if tension is not None else math.nan
                if tension is not None and tmax > 0 and math.isfinite(tk):
                    cols.append(_color(tension_color(tk / tmax)))
                else:
                    cols.append(_color(tension_color(k / max(rd.cable_nodes - 1, 1))))
            ident = {"position": _vec(0.0, 0.0, 0.0), "orientation": _quat((1.0, 0.0, 0.0, 0.0))}
            line = {
                "type": 0,
                "pose": ident,
                "thickness": 0.05,
                "scale_invariant": False,
                "points": pts,
                "color": _color((1.0, 1.0, 1.0, 1.0)),
                "colors": cols,
                "indices": [],
            }
            ents.append({"id": "cable", "lines": [line]})
        ents += static
        full = [_entity(stamps[i], e) for e in ents]
        scene.append(_json({"deletions": [], "entities": full}))
    channel("/scene", "foxglove.SceneUpdate", scene)

    # every numeric signal, one channel per prefix
    for prefix, fields in _signal_groups(rd).items():
        names = [f for f, _ in fields]
        sch = signals_schema(prefix, names)
        rows = np.stack([rd.columns[c] for _, c in fields], axis=1).tolist()
        payloads = []
        for i, row in enumerate(rows):
            d = {"timestamp": stamps[i]}
            d.update(zip(names, (v if math.isfinite(v) else None for v in row)))
            payloads.append(_json(d))
        out.append(Channel(f"/signals/{prefix}", sch["title"], _json(sch), payloads))
    return out


BATCH_ROWS = 2_000  #: log rows per part of a streamed export (bounds its memory: about 13 kB of messages a row)


def export_mcap(run: str | Path | RunData, out: str | Path | None = None, batch_rows: int = BATCH_ROWS) -> Path:
    """Write the run folder ``run`` as MCAP to ``out`` (default ``RUN/run.mcap``); the path written.

    A run folder is streamed: its log is read twice, Parquet row group by row group in parts of at
    most ``batch_rows`` rows (:func:`~oceangnc.view.run_data.iter_run`), first for what every message
    takes from the whole run (:class:`Whole`), then to write the messages part by part; memory is
    bounded by a part, not the log (a 5-million-row log failed past 8 GB before). The messages are
    the same as from the whole log at once. Raises :class:`MissingMcap` without the ``mcap`` package,
    InputError for a folder without a log or an ``out`` it must not replace.
    """
    from ..core.files import check_output, write_output
    from .run_data import iter_run

    writer_mod = require_mcap()
    if isinstance(run, RunData):
        path, parts = run.path, (lambda: iter([run]))
    else:
        first = next(iter_run(run, 1), None)  # checks the folder and its log before anything is written
        path = first.path if first is not None else load_run(run).path
        parts = (lambda: iter_run(run, batch_rows)) if first is not None else (lambda: iter([load_run(run)]))
    out = check_output(out if out is not None else path / "run.mcap", "MCAP file", is_mcap)
    whole = Whole.of(parts())
    write_output(out, lambda f: _write(writer_mod, parts(), whole, f))  # an exclusive temporary file, renamed
    return out


MCAP_MAGIC = b"\x89MCAP0\r\n"


def is_mcap(head: bytes) -> bool:
    """True when ``head`` (a file's first bytes) starts an MCAP file (``--out`` may replace only one)."""
    return head.startswith(MCAP_MAGIC)


def _write(writer_mod, parts, whole: Whole | None, f) -> None:
    """Write the messages of every part, in time order (one row of every channel after the other:
    what MCAP readers stream best); the writer's chunks go to the file as they fill."""
    w = writer_mod.Writer(f)
    w.start(profile="", library="oceangnc")
    ids: dict[str, int] = {}
    sids: dict[str, int] = {}
    seq: dict[str, int] = {}
    rd = None
    for rd in parts:
        channels = build_channels(rd, whole)
        ns = stamps_ns(rd, whole.shift if whole else None).tolist()
        for c in channels:
            if c.topic not in ids:
                if c.schema_name not in sids:
                    sids[c.schema_name] = w.register_schema(name=c.schema_name, encoding="jsonschema", data=c.schema)
                ids[c.topic] = w.register_channel(topic=c.topic, message_encoding="json", schema_id=sids[c.schema_name])
                seq[c.topic] = 0
        for i in range(rd.rows):
            for c in channels:
                data = c.payloads[i]
                if data is None:
                    continue
                w.add_message(ids[c.topic], log_time=ns[i], publish_time=ns[i], data=data, sequence=seq[c.topic])
                seq[c.topic] += 1
    if rd is not None:
        meta = {
            "run": str(rd.path.name),
            "scenario": str(rd.summary.get("scenario", rd.config.get("scenario", ""))),
            "frames": "world: ENU (x east, y north, z up) at the NED origin; vehicles: FLU (REP 103)",
            "time": "log_time = wall-clock start of the run (else the Unix epoch) + simulated time t, ns",
            "summary": json.dumps(rd.summary, default=str),
        }
        w.add_metadata("oceangnc", meta)
    w.finish()


def _entity(stamp: dict, e: dict) -> dict:
    base = {
        "timestamp": stamp,
        "frame_id": "world",
        "id": e["id"],
        "lifetime": {"sec": 0, "nsec": 0},
        "frame_locked": False,
        "metadata": [],
        "arrows": [],
        "cubes": [],
        "spheres": [],
        "cylinders": [],
        "lines": [],
        "triangles": [],
        "texts": [],
        "models": [],
    }
    base.update({k: v for k, v in e.items() if k != "id"})
    return base


def _rotations(q: np.ndarray) -> np.ndarray:
    from .frames import quat_matrix

    return quat_matrix(np.nan_to_num(q))


def _gps_messages(rd: RunData, stamps) -> list[tuple[str, list[bytes | None]]]:
    """LocationFix channel(s): logged lat/lon columns, else each vehicle's x/y about the origin."""
    out = []
    cov = [0.0] * 9

    def fix(i, lat, lon, alt):
        if not (math.isfinite(lat) and math.isfinite(lon)):
            return None
        return _json(
            {
                "timestamp": stamps[i],
                "frame_id": "world",
                "latitude": lat,
                "longitude": lon,
                "altitude": alt if math.isfinite(alt) else 0.0,
                "position_covariance": cov,
                "position_covariance_type": 0,
                "metadata": [],  # required by Foxglove's schema since foxglove-sdk's LocationFix.json of 2025
            }
        )

    if rd.latlon:
        lat, lon = (rd.columns[c].tolist() for c in rd.latlon)
        body = rd.latlon[0].rpartition(".")[0] or "gps"
        out.append((f"/{body}/gps", [fix(i, lat[i], lon[i], 0.0) for i in range(rd.rows)]))
    elif rd.origin:
        from ..io.geo import ned_to_latlon

        for b in rd.bodies:
            n, e, d = (rd.col(b.columns[k]).tolist() for k in ("x", "y", "z"))
            payloads = []
            for i in range(rd.rows):
                if math.isfinite(n[i]) and math.isfinite(e[i]):
                    la, lo = ned_to_latlon(n[i], e[i], *rd.origin)
                    payloads.append(fix(i, la, lo, -d[i]))
                else:
                    payloads.append(None)
            out.append((f"/{b.name}/gps", payloads))
    return out
