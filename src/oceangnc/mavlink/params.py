"""The parameter protocol of :class:`oceangnc.mavlink.vehicle.MavlinkVehicle`: every tunable of the running
vehicle as a named MAVLink parameter, with ArduPilot Rover's name where Rover has one.

Each parameter is a :class:`Param`: a getter and a setter on the live objects (the controllers' and the
guidance's parameter arrays, read by their laws at the next step on either clock; the endpoint's
settings), a range and a type. The table is built from the blocks the scenario actually has
(:func:`build_params`), so ``usv-remote`` (route pilot + speed / yaw-rate PIDs) and ``combined-survey``
(pure pursuit + speed / heading / yaw-rate PIDs) list what each can change, nothing else.

Protocol (as ArduPilot answers it):

* PARAM_REQUEST_LIST: one PARAM_VALUE per parameter, ``param_count`` and ``param_index`` set;
* PARAM_REQUEST_READ: by ``param_index`` (>= 0) or by name (index -1);
* PARAM_SET: the value is checked (finite, inside the range, a whole number for an integer type, not a
  read-only parameter) and written, and the PARAM_VALUE echo carries the value the vehicle now holds:
  the new one, or the unchanged one when the request is refused (a STATUSTEXT says why). An unknown
  name gets no answer (ArduPilot's behaviour; the client times out).

Values are sent as REAL32 or as an integer type (INT8 / INT16 / INT32) whose value travels as the
float of the same number (ArduPilot's "C cast" encoding, MAV_PROTOCOL_CAPABILITY_PARAM_ENCODE_C_CAST).

The values are saved with the run (``params.json`` in the run folder, rewritten after every accepted
change) and reloaded with ``oceangnc mavlink --params FILE`` (a ``params.json`` or a MAVProxy / Mission
Planner ``.param`` file, ``NAME VALUE`` or ``NAME,VALUE`` per line).
"""

from __future__ import annotations

import json
import math
from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path

from ..errors import InputError
from .protocol import mavlink

M = mavlink

REAL32 = M.MAV_PARAM_TYPE_REAL32
INT8 = M.MAV_PARAM_TYPE_INT8
INT16 = M.MAV_PARAM_TYPE_INT16
INT32 = M.MAV_PARAM_TYPE_INT32


@dataclass
class Param:
    """One parameter: ``get()`` / ``set(value)`` on the live objects, SI units (the unit is in ``unit``)."""

    name: str
    get: Callable[[], float]
    set: Callable[[float], None] | None
    lo: float
    hi: float
    kind: int = REAL32
    unit: str = ""
    doc: str = ""

    def refusal(self, value: float) -> str | None:
        """Why ``value`` cannot be written, or None."""
        if self.set is None:
            return "read-only"
        if not math.isfinite(value):
            return "not finite"
        if not (self.lo <= value <= self.hi):
            return f"outside {self.lo:g}..{self.hi:g}"
        if self.kind != REAL32 and value != round(value):
            return "not a whole number"
        return None


def _attr(obj, name: str) -> tuple[Callable[[], float], Callable[[float], None]]:
    def get() -> float:
        return float(getattr(obj, name))

    def put(v: float) -> None:
        setattr(obj, name, float(v))

    return get, put


def _pid(prefix: str, pid, what: str, unit_p: str, unit_i: str, unit_d: str) -> list[Param]:
    out = []
    for suffix, attr, unit in (("P", "kp", unit_p), ("I", "ki", unit_i), ("D", "kd", unit_d)):
        g, s = _attr(pid, attr)
        out.append(Param(f"{prefix}_{suffix}", g, s, 0.0, 1e5, REAL32, unit, f"{what} PID {attr}"))
    return out


def _route_accept(block) -> tuple[Callable[[], float], Callable[[float], None]]:
    """The acceptance radius (m) of the route pilot: in its parameter array when the block has one with an
    ``accept`` entry (a LawBlock), else in its config (read by its Python law each step)."""
    import sys

    layout = getattr(sys.modules.get(type(block).__module__), "PARAMS", None)
    pa = getattr(block, "pa", None)
    if pa is not None and layout is not None and "accept" in getattr(layout, "names", ()):
        i = layout.names.index("accept")
        i = getattr(layout.at, "accept", i)

        def get() -> float:
            return float(block.pa[i])

        def put(v: float) -> None:
            block.pa[i] = float(v)

        return get, put

    def cget() -> float:
        return float(block.cfg.accept_radius)

    def cput(v: float) -> None:
        block.cfg = block.cfg.model_copy(update={"accept_radius": float(v)})

    return cget, cput


def _spec_range(block, name: str, lo: float, hi: float) -> tuple[float, float]:
    """A gain's range from the block's own ``gain_specs`` (the console's limits) when it lists it."""
    for s in getattr(block, "gain_specs", lambda: [])():
        if s.get("name") == name:
            return float(s["min"]), float(s["max"])
    return lo, hi


def build_params(v) -> dict[str, Param]:
    """The parameter table of vehicle ``v`` (see the module docstring), in a stable order."""
    c = v.cfg_mav
    ps: list[Param] = []

    def cfg_param(name, key, kind=REAL32, unit="", doc="", lo=None, hi=None, to=float, frm=float):
        field = type(c).model_fields[key]
        flo, fhi = lo, hi
        for m in field.metadata:
            for a in ("ge", "gt"):
                if flo is None and getattr(m, a, None) is not None:
                    flo = getattr(m, a)
            if fhi is None and getattr(m, "le", None) is not None:
                fhi = m.le

        def get() -> float:
            return frm(getattr(v.cfg_mav, key))

        def put(x: float) -> None:
            setattr(v.cfg_mav, key, to(x))

        ps.append(Param(name, get, put, float(flo), float(fhi), kind, unit, doc or field.description or ""))

    # -- identity and the endpoint
    ps.append(Param("SYSID_THISMAV", lambda: float(v.cfg_mav.system_id), None, 1, 250, INT16, "", "system id (fixed)"))
    ps.append(
        Param(
            "SYSID_MYGCS",
            lambda: float(v.cfg_mav.gcs_sysid or 0),
            lambda x: setattr(v.cfg_mav, "gcs_sysid", int(x) or None),
            0,
            255,
            INT16,
            "",
            "controlling ground station's system id (0: the one whose arm, mode change or mission start was last accepted)",
        )
    )
    # -- failsafes (ArduPilot Rover's names and numbers)
    cfg_param("FS_GCS_ENABLE", "fs_gcs_enable", INT8, "", "GCS failsafe: 0 off, 1 on, 2 on but AUTO continues",
              to=int, frm=float)  # fmt: skip
    cfg_param("FS_GCS_TIMEOUT", "gcs_timeout_s", REAL32, "s")
    cfg_param("FS_TIMEOUT", "stick_timeout_s", REAL32, "s")
    cfg_param("RC_OVERRIDE_TIME", "rc_override_time_s", REAL32, "s")
    cfg_param("FS_ACTION", "fs_action", INT8, "", "failsafe action: 1 RTL, 2 HOLD, 3 SMART_RTL else RTL, "
              "4 SMART_RTL else HOLD", to=int, frm=float)  # fmt: skip
    # -- navigation
    cfg_param("LOIT_RADIUS", "loiter_radius_m", REAL32, "m")
    # -- the scenario's blocks
    from ..guidance.pure_pursuit import PurePursuit

    for b in v.sim.blocks:
        inner = getattr(b, "block", b)
        kind = type(inner).__name__
        if kind == "RoutePilot":
            g, s = _attr(inner, "cruise_speed")
            ps.append(Param("CRUISE_SPEED", g, s, *_spec_range(inner, "cruise_speed", 0.05, 5.0), REAL32, "m/s",
                            "cruise speed of AUTO, GUIDED, RTL, SMART_RTL and LOITER"))  # fmt: skip
            g, s = _route_accept(inner)
            ps.append(Param("WP_RADIUS", g, s, 0.1, 100.0, REAL32, "m", "waypoint acceptance radius"))
            g, s = _attr(inner, "heading_gain")
            ps.append(Param("ATC_STR_ANG_P", g, s, *_spec_range(inner, "heading_gain", 0.01, 10.0), REAL32, "1/s",
                            "heading error -> yaw-rate setpoint gain"))  # fmt: skip
            g, s = _attr(inner, "lookahead")
            ps.append(Param("PP_LOOKAHEAD", g, s, *_spec_range(inner, "lookahead", 0.5, 100.0), REAL32, "m",
                            "pure-pursuit look-ahead distance (003 eq. 3.5)"))  # fmt: skip
        elif isinstance(inner, PurePursuit):
            g, s = _attr(inner, "acceptance")
            ps.append(Param("WP_RADIUS", g, s, 0.1, 100.0, REAL32, "m", "waypoint acceptance radius"))
            g, s = _attr(inner, "l")
            ps.append(Param("PP_LOOKAHEAD", g, s, 0.5, 1000.0, REAL32, "m",
                            "pure-pursuit look-ahead distance (003 eq. 3.5-3.6)"))  # fmt: skip
        elif kind == "USVRateController":
            ps += _pid("ATC_SPEED", inner.speed_pid, "surge-speed", "N/(m/s)", "N/m", "N s/(m/s)")
            ps += _pid("ATC_STR_RAT", inner.yaw_pid, "yaw-rate", "N/(rad/s)", "N/rad", "N s/(rad/s)")
        elif kind == "USVController":
            g, s = _attr(inner, "u_d")
            ps.append(Param("CRUISE_SPEED", g, s, 0.0, 5.0, REAL32, "m/s", "surge speed target of the autopilot"))
            ps += _pid("ATC_SPEED", inner.speed, "surge-speed", "N/(m/s)", "N/m", "N s/(m/s)")
            ps += _pid("ATC_HDG", inner.heading, "heading", "N/rad", "N/(rad s)", "N s/rad")
            ps += _pid("ATC_STR_RAT", inner.yaw_rate, "yaw-rate (stick modes)", "N/(rad/s)", "N/rad", "N s/(rad/s)")
    # -- battery
    ps.append(Param("BATT_CAPACITY", lambda: float(v.battery.capacity_ah * 1000.0), v._set_battery_capacity,
                    100.0, 1e8, INT32, "mAh", "battery capacity"))  # fmt: skip
    # -- simulation
    ps.append(Param("SIM_SPEEDUP", lambda: float(v.speed), v._set_speedup, 0.01, 100.0, REAL32, "",
                    "simulated seconds per wall second"))  # fmt: skip
    seen: dict[str, Param] = {}
    for p in ps:
        seen.setdefault(p.name, p)  # the first block of a kind wins (one USV per vehicle)
    # the operator's CRUISE_SPEED and WP_RADIUS, under the modes' temporary values (oceangnc.mavlink.nav)
    v._raw, v._user = {}, {}
    for name in ("CRUISE_SPEED", "WP_RADIUS"):
        p = seen.get(name)
        if p is None:
            continue
        v._raw[name] = (p.get, p.set)
        v._user[name] = p.get()
        p.get = lambda n=name: v._user[n]
        p.set = lambda x, n=name: (v._user.__setitem__(n, float(x)), v._apply_overrides())
    return seen


#: the largest parameter file read, bytes (ArduPilot's full parameter list as a .param file is about 30 kB)
MAX_PARAM_FILE_BYTES = 1 << 20


def _read_bounded(p: Path, what: str) -> str:
    """The text of a regular file of at most :data:`MAX_PARAM_FILE_BYTES`, else one InputError line: a device,
    a FIFO or a folder is refused before anything is read from it (``/dev/zero`` read without bound)."""
    import os
    import stat

    try:
        fd = os.open(p, os.O_RDONLY | os.O_NONBLOCK)  # (a FIFO must not block the open)
    except OSError as e:
        raise InputError(f"{what}: cannot read ({e.strerror or e})") from None
    st = os.fstat(fd)
    if not stat.S_ISREG(st.st_mode):
        os.close(fd)
        raise InputError(f"{what}: not a regular file")
    if st.st_size > MAX_PARAM_FILE_BYTES:
        os.close(fd)
        raise InputError(f"{what}: {st.st_size} bytes, more than the {MAX_PARAM_FILE_BYTES} a parameter file may have")
    with os.fdopen(fd, "rb") as f:
        data = f.read(MAX_PARAM_FILE_BYTES + 1)
    if len(data) > MAX_PARAM_FILE_BYTES:  # grew while read
        raise InputError(f"{what}: more than the {MAX_PARAM_FILE_BYTES} bytes a parameter file may have")
    try:
        return data.decode("utf-8")
    except UnicodeDecodeError as e:
        raise InputError(f"{what}: not UTF-8 text (byte {e.start})") from None


def read_param_file(path: str | Path) -> dict[str, float]:
    """``{NAME: value}`` from a ``params.json`` (an object of numbers) or a ``.param`` / ``.parm`` file
    (``NAME VALUE`` or ``NAME,VALUE`` per line, ``#`` comments); InputError naming the file otherwise."""
    p = Path(path)
    text = _read_bounded(p, f"--params {path}")
    if p.suffix == ".json" or text.lstrip().startswith("{"):
        try:
            data = json.loads(text)
        except json.JSONDecodeError as e:
            raise InputError(f"--params {path}: not JSON ({e.msg}, line {e.lineno})") from None
        data = data.get("params", data) if isinstance(data, dict) else data
        if not isinstance(data, dict) or not all(isinstance(x, (int, float)) for x in data.values()):
            raise InputError(f"--params {path}: expected an object of NAME: number")
        return {str(k): float(x) for k, x in data.items()}
    out: dict[str, float] = {}
    for i, line in enumerate(text.splitlines(), 1):
        s = line.split("#", 1)[0].strip()
        if not s:
            continue
        parts = s.replace(",", " ").split()
        try:
            out[parts[0]] = float(parts[1])
        except (IndexError, ValueError):
            raise InputError(f"--params {path}: line {i}: expected NAME VALUE, got {line.strip()!r}") from None
    return out


class ParamsMixin:
    """PARAM_REQUEST_LIST / PARAM_REQUEST_READ / PARAM_SET, the run's ``params.json`` and ``--params``."""

    def _param_value(self, name: str, index: int | None = None) -> None:
        p = self.params[name]
        names = list(self.params)
        i = names.index(name) if index is None else index
        self._send(self.mav.param_value_encode(name.encode(), p.get(), p.kind, len(names), i))

    def _on_param_request_list(self, m) -> None:
        for i, name in enumerate(self.params):
            self._param_value(name, i)

    def _on_param_request_read(self, m) -> None:
        names = list(self.params)
        pid = m.param_id.decode(errors="replace") if isinstance(m.param_id, bytes) else str(m.param_id)
        pid = pid.rstrip("\x00")
        if m.param_index >= 0:
            if m.param_index < len(names):
                self._param_value(names[m.param_index], m.param_index)
        elif pid in self.params:
            self._param_value(pid)

    def _on_param_set(self, m) -> None:
        name = m.param_id.decode(errors="replace") if isinstance(m.param_id, bytes) else str(m.param_id)
        name = name.rstrip("\x00")
        if name not in self.params:
            self.counts["rx_ignored"] += 1
            return
        why = self.set_param(name, float(m.param_value))
        if why is not None:
            self._oor(f"PARAM_SET {name} = {m.param_value}: {why}")
        self._param_value(name)  # the echo: the value the vehicle holds now

    def set_param(self, name: str, value: float) -> str | None:
        """Write parameter ``name`` (checked); returns why it was refused, or None. Saves ``params.json``."""
        p = self.params.get(name)
        if p is None:
            return "unknown parameter"
        why = p.refusal(value)
        if why is None:
            old = p.get()
            try:
                p.set(value)
            except (ValueError, TypeError) as e:  # a pydantic check of the endpoint's settings
                p.set(old)
                why = str(e).splitlines()[0]
        if why is not None:
            return why
        if p.get() != old:
            self.event(f"{name} set to {p.get():g}")
            self._param_changed(name)
        self.save_params()
        return None

    def _param_changed(self, name: str) -> None:
        """Hook: a parameter changed (the vehicle reacts, e.g. the route pilot's radius in a loiter)."""

    def param_values(self) -> dict[str, float]:
        return {k: p.get() for k, p in self.params.items()}

    def save_params(self) -> None:
        """``params.json`` in the run folder (crash-safe write)."""
        if getattr(self, "run_dir", None) is None:
            return
        from ..core.files import atomic_write_text

        atomic_write_text(self.run_dir / "params.json", json.dumps(self.param_values(), indent=2) + "\n")

    def load_params(self, values: dict[str, float], source: str = "--params") -> None:
        """Apply ``values`` at start; an unknown name or a refused value is an InputError (one line)."""
        for name, value in values.items():
            if name not in self.params:
                raise InputError(f"{source}: unknown parameter {name} for {self.scenario.name}")
            p = self.params[name]
            if p.set is None:
                if p.get() != value:
                    raise InputError(f"{source}: {name} is read-only (it is {p.get():g})")
                continue
            why = self.set_param(name, value)
            if why is not None:
                raise InputError(f"{source}: {name} = {value:g} refused: {why}")
