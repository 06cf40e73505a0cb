"""What a run folder holds for a viewer, read once: :func:`load_run`.

A run folder has ``log.parquet`` (one row per logged time ``t``, columns ``<body>.<signal>``),
``config.toml`` and ``summary.json`` (both optional here: an imported field log has neither). From
them a :class:`RunData` gathers

* the **vehicles**: every prefix ``P`` with columns ``P.x``, ``P.y`` and ``P.psi`` (NED north, east,
  heading); ``P.z``, ``P.phi``, ``P.theta`` are used when logged, else 0. ``uuv`` is drawn as a
  torpedo, any other as a surface hull; sizes come from the config (``usv.length_oa``/``beam``,
  ``uuv.length``/``diameter``) or defaults;
* the **cable**: node columns ``cable.x0..``, ``cable.y0..``, ``cable.z0..`` (node 0 at the USV,
  the last at the UUV's tow point) and its tensions: per node ``cable.tension0..`` when logged,
  else the end tensions ``cable.top_tension`` / ``cable.bottom_tension``;
* the **route** (``guidance.waypoints``, north/east pairs) and its acceptance radius;
* the **seabed** (``environment.seabed``: depth at the origin, slope, direction) when it has a depth;
* the **waves** (``environment.waves`` with a ``kind`` other than none): the wave field the run's
  plant had, drawn again from the config and ``sim.seed`` by the same call
  (:meth:`oceangnc.environment.SeaEnvironmentConfig.plant_kwargs`), so its components (amplitude,
  frequency, wave number, direction, phase) are the run's;
* the **geographic origin** (``mavlink.origin_lat_deg``/``origin_lon_deg`` of a MAVLink run's
  config, else ``origin_deg`` of an imported log's ``import.json``) and any logged ``lat``/``lon``
  columns, for a GPS track;
* the **wall-clock start** (UNIX s at t = 0): ``wall_time_start_unix_s`` of ``summary.json`` (a run's,
  a MAVLink session's), else ``start_unix_s`` of ``import.json`` (the log's own clock: a ``.tlog``'s
  record stamps, a ROS 2 bag's time), else None.
"""

from __future__ import annotations

import json
import re
import tomllib
from dataclasses import dataclass, field
from pathlib import Path
from typing import TYPE_CHECKING

import numpy as np

from ..errors import InputError

if TYPE_CHECKING:
    from ..environment.waves import WaveField

_NODE = re.compile(r"^cable\.([xyz])(\d+)$")
_TENSION = re.compile(r"^cable\.tension(\d+)$")


@dataclass
class Body:
    """A vehicle with a pose: its column prefix, how it is drawn and its size (m)."""

    name: str
    kind: str  # "torpedo" (a UUV) or "hull" (a surface vessel)
    length: float
    width: float
    columns: dict[str, str | None]  # x, y, z, phi, theta, psi -> log column (None: not logged, taken as 0)


@dataclass
class RunData:
    """A run folder read for a viewer (module docstring)."""

    path: Path
    columns: dict[str, np.ndarray]  # every numeric log column, float64, in log order
    config: dict = field(default_factory=dict)
    summary: dict = field(default_factory=dict)
    bodies: list[Body] = field(default_factory=list)
    cable_nodes: int = 0  # number of cable nodes (0: no cable logged)
    cable_tension: list[str] = field(default_factory=list)  # per-node tension columns, or the 2 end ones, or []
    route: list[tuple[float, float]] = field(default_factory=list)  # waypoints (north, east), m
    acceptance: float | None = None
    seabed: dict | None = None  # {"depth", "slope_deg", "slope_direction_deg"}
    origin: tuple[float, float] | None = None  # (lat, lon) deg of the NED origin
    latlon: tuple[str, str] | None = None  # logged latitude / longitude columns (deg)
    waves: WaveField | None = None  # the run's wave field (None: calm water)
    start_unix_s: float | None = None  # wall-clock time (UNIX s) of t = 0, when the folder records one

    @property
    def t(self) -> np.ndarray:
        return self.columns["t"]

    @property
    def rows(self) -> int:
        return len(self.columns["t"])

    def col(self, name: str | None, default: float = 0.0) -> np.ndarray:
        """A column, or ``default`` everywhere when ``name`` is None or not logged."""
        if name is not None and name in self.columns:
            return self.columns[name]
        return np.full(self.rows, default)

    def node_columns(self, axis: str) -> list[str]:
        """The cable node columns of ``axis`` ("x", "y" or "z"), node 0 first."""
        return [f"cable.{axis}{i}" for i in range(self.cable_nodes)]

    def seabed_depth(self, n, e):
        """Depth of the plane seabed (m, down) at north ``n``, east ``e`` (as
        :mod:`oceangnc.environment.seabed`: D + tan(slope) (n cos chi + e sin chi))."""
        b = self.seabed
        s = np.tan(np.radians(b["slope_deg"]))
        chi = np.radians(b["slope_direction_deg"])
        return b["depth"] + s * (np.asarray(n) * np.cos(chi) + np.asarray(e) * np.sin(chi))


def _read_columns(path: Path) -> dict[str, np.ndarray]:
    from ..io.log_read import read_table

    log = path / "log.parquet"
    if not log.exists():
        raise InputError(f"{path}: no log.parquet (a run folder written by 'oceangnc run' or 'oceangnc import')")
    import pyarrow as pa

    try:
        table = read_table(log)
    except (pa.ArrowInvalid, OSError, ValueError) as e:
        if isinstance(e, InputError):
            raise
        raise InputError(f"cannot read log {log}: {e}") from None
    cols: dict[str, np.ndarray] = {}
    for name, col in zip(table.column_names, table.columns):
        if pa.types.is_floating(col.type) or pa.types.is_integer(col.type) or pa.types.is_boolean(col.type):
            cols[name] = np.asarray(col.to_numpy(zero_copy_only=False), dtype=float)
    if "t" not in cols:
        raise InputError(f"log {log} has no time column 't'")
    return cols


def _size(cfg: dict, keys: tuple[str, ...], default: float) -> float:
    for k in keys:
        v = cfg.get(k)
        if isinstance(v, (int, float)) and v > 0:
            return float(v)
    return default


def _run_path(run_dir: str | Path) -> Path:
    path = Path(run_dir)
    if path.name == "log.parquet":
        path = path.parent
    if not path.is_dir():
        raise InputError(f"run folder not found: {path}")
    return path


def load_run(run_dir: str | Path) -> RunData:
    """Read the run folder ``run_dir`` (or its ``log.parquet``) for a viewer; InputError if it has no log."""
    path = _run_path(run_dir)
    cols = _read_columns(path)
    return _clock_and_origin(describe(path, cols, *run_meta(path)), path)


def run_meta(path: Path) -> tuple[dict, dict]:
    """A run folder's config and summary as dicts, each read bounded (a regular file of UTF-8 text);
    a config that cannot be read is a one-line InputError, a summary that cannot be is left out."""
    from ..core.files import LIMIT_JSON, LIMIT_TOML, read_text_bounded

    cfg: dict = {}
    if (path / "config.toml").exists():
        text = read_text_bounded(path / "config.toml", LIMIT_TOML, "config file")
        try:
            cfg = tomllib.loads(text)
        except tomllib.TOMLDecodeError as e:
            raise InputError(f"{path / 'config.toml'}: {e}") from None
        except RecursionError:
            raise InputError(f"{path / 'config.toml'}: nested too deeply to be a config") from None
    summary: dict = {}
    if (path / "summary.json").exists():
        try:
            summary = json.loads(read_text_bounded(path / "summary.json", LIMIT_JSON, "summary"))
        except (ValueError, RecursionError, InputError):
            summary = {}
        if not isinstance(summary, dict):
            summary = {}
    return cfg, summary


def _numeric(pa, tp) -> bool:
    return pa.types.is_floating(tp) or pa.types.is_integer(tp) or pa.types.is_boolean(tp)


def iter_run(run_dir: str | Path, batch_rows: int):
    """The run folder ``run_dir`` as a sequence of :class:`RunData` of at most ``batch_rows`` rows each,
    in row order: the log's parts read Parquet row group by row group (``iter_batches``), so that only
    one batch of rows is in memory at a time (the MCAP export of a long log)."""
    import pyarrow as pa
    import pyarrow.parquet as pq

    from ..io.log_read import _dataset_path, _live_parts, readable_dataset

    path = _run_path(run_dir)
    log = readable_dataset(_dataset_path(path / "log.parquet"))
    if not log.exists():
        raise InputError(f"{path}: no log.parquet (a run folder written by 'oceangnc run' or 'oceangnc import')")
    files = _live_parts(log)[0] if log.is_dir() else [log]
    cfg, summary = run_meta(path)
    for p in files:
        try:
            with pq.ParquetFile(p) as f:
                for batch in f.iter_batches(batch_size=batch_rows):
                    cols = {
                        name: np.asarray(col.to_numpy(zero_copy_only=False), dtype=float)
                        for name, col in zip(batch.schema.names, batch.columns)
                        if pa.types.is_floating(col.type)
                        or pa.types.is_integer(col.type)
                        or pa.types.is_boolean(col.type)
                    }
                    if "t" not in cols:
                        raise InputError(f"log {log} has no time column 't'")
                    yield _clock_and_origin(describe(path, cols, cfg, summary), path)
        except (pa.ArrowInvalid, OSError) as e:
            raise InputError(f"cannot read log {p}: {e}") from None


def _number(v) -> float | None:
    return float(v) if isinstance(v, (int, float)) and not isinstance(v, bool) and v == v else None


def _clock_and_origin(rd: RunData, path: Path) -> RunData:
    """``rd`` with the wall-clock start from summary.json, else import.json, and an imported log's origin."""
    from ..core.files import LIMIT_JSON, read_text_bounded

    rd.start_unix_s = _number(rd.summary.get("wall_time_start_unix_s")) if isinstance(rd.summary, dict) else None
    if not (path / "import.json").exists():
        return rd
    try:
        imp = json.loads(read_text_bounded(path / "import.json", LIMIT_JSON, "import record"))
    except (ValueError, RecursionError, InputError):
        return rd
    if not isinstance(imp, dict):
        return rd
    if rd.start_unix_s is None:
        rd.start_unix_s = _number(imp.get("start_unix_s"))
    o = imp.get("origin_deg")
    if rd.origin is None and isinstance(o, list) and len(o) >= 2 and all(_number(v) is not None for v in o[:2]):
        rd.origin = (float(o[0]), float(o[1]))
    return rd


def describe(path: Path, cols: dict[str, np.ndarray], cfg: dict | None = None, summary: dict | None = None) -> RunData:
    """A :class:`RunData` from log columns and a config dict (module docstring): what :func:`load_run`
    does after reading the folder, and what a live stream does with one state (``oceangnc.view.foxglove_ws``)."""
    cfg = cfg or {}
    rd = RunData(path=Path(path), columns=cols, config=cfg, summary=summary or {})

    prefixes = sorted({c.split(".", 1)[0] for c in cols if "." in c})
    for p in prefixes:
        if not all(f"{p}.{s}" in cols for s in ("x", "y", "psi")):
            continue
        bcfg = cfg.get(p, {}) if isinstance(cfg.get(p), dict) else {}
        colmap = {s: (f"{p}.{s}" if f"{p}.{s}" in cols else None) for s in ("x", "y", "z", "phi", "theta", "psi")}
        if p == "uuv":
            body = Body(p, "torpedo", _size(bcfg, ("length",), 1.8), _size(bcfg, ("diameter",), 0.25), colmap)
        elif p == "ship":
            body = Body(p, "hull", _size(bcfg, ("length", "lpp", "L"), 175.0), _size(bcfg, ("beam", "B"), 25.4), colmap)
        else:
            body = Body(p, "hull", _size(bcfg, ("length_oa", "length"), 3.0), _size(bcfg, ("beam",), 1.8), colmap)
        rd.bodies.append(body)

    nodes = {(m.group(1), int(m.group(2))) for c in cols if (m := _NODE.match(c))}
    n = 0
    while all((a, n) in nodes for a in "xyz"):
        n += 1
    rd.cable_nodes = n if n >= 2 else 0
    if rd.cable_nodes:
        per_node = sorted((int(m.group(1)), c) for c in cols if (m := _TENSION.match(c)))
        if len(per_node) >= 2:
            rd.cable_tension = [c for _, c in per_node]
        elif "cable.top_tension" in cols and "cable.bottom_tension" in cols:
            rd.cable_tension = ["cable.top_tension", "cable.bottom_tension"]

    g = cfg.get("guidance", {})
    wps = g.get("waypoints") if isinstance(g, dict) else None
    if isinstance(wps, list):
        rd.route = [(float(w[0]), float(w[1])) for w in wps if isinstance(w, list) and len(w) >= 2]
        acc = g.get("acceptance")
        rd.acceptance = float(acc) if isinstance(acc, (int, float)) else None

    bed = cfg.get("environment", {}).get("seabed", {}) if isinstance(cfg.get("environment"), dict) else {}
    if isinstance(bed, dict) and isinstance(bed.get("depth"), (int, float)):
        rd.seabed = {
            "depth": float(bed["depth"]),
            "slope_deg": float(bed.get("slope_deg", 0.0)),
            "slope_direction_deg": float(bed.get("slope_direction_deg", 0.0)),
        }

    rd.waves = wave_field(cfg)

    mav = cfg.get("mavlink", {})
    if isinstance(mav, dict) and isinstance(mav.get("origin_lat_deg"), (int, float)):
        rd.origin = (float(mav["origin_lat_deg"]), float(mav.get("origin_lon_deg", 0.0)))
    for lat, lon in (("lat", "lon"), ("gps.lat", "gps.lon"), ("usv.lat", "usv.lon")):
        if lat in cols and lon in cols:
            rd.latlon = (lat, lon)
            break
    return rd


def wave_field(cfg: dict):
    """The :class:`~oceangnc.environment.waves.WaveField` of a run's config dict (None in calm water or
    without ``environment.waves``): :meth:`~oceangnc.environment.SeaEnvironmentConfig.plant_kwargs` of
    its ``environment`` section with its ``sim.seed``, the call the scenarios build their plant with.
    A section that does not validate is an InputError naming it."""
    env = cfg.get("environment")
    waves = env.get("waves") if isinstance(env, dict) else None
    if not isinstance(waves, dict) or waves.get("kind", "none") == "none":
        return None
    from pydantic import ValidationError

    from ..environment import SeaEnvironmentConfig

    try:
        sea = SeaEnvironmentConfig.model_validate(env)
    except ValidationError as e:
        err = e.errors()[0]
        raise InputError(f"config environment.{'.'.join(map(str, err['loc']))}: {err['msg']}") from None
    sim = cfg.get("sim")
    seed = sim.get("seed", 0) if isinstance(sim, dict) else 0
    return sea.plant_kwargs(int(seed) if isinstance(seed, int) else 0)["waves"]
