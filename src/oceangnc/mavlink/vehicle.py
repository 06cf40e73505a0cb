"""A live scenario as a MAVLink vehicle: ``oceangnc mavlink [SCENARIO] --listen udp:127.0.0.1:14550``.

One loop (default 100 Hz, run in a thread by :meth:`MavlinkVehicle.start` or in the foreground by
:meth:`MavlinkVehicle.serve`) does, each pass,

1. read every UDP datagram waiting (at most ``mavlink.max_packets_per_loop``), parse it with a fresh
   MAVLink 2 parser state (a malformed datagram cannot corrupt the next one), and handle each message
   (commands, modes, sticks, mission protocol); malformed datagrams, unknown message ids and
   out-of-range values are counted (``mavlink.rx_bad``, ``mavlink.rx_unknown``,
   ``mavlink.rx_out_of_range`` on the bus and in the log) and otherwise ignored;
2. run the GCS-link watchdog: in a stick mode (MANUAL, ACRO) no message from the ground station for
   ``mavlink.gcs_timeout_s`` (0.7 s) switches to HOLD (failsafe; the stick is zeroed);
3. write the vehicle's state onto the simulation bus with ``sim.inject`` (the console's keys, see
   :mod:`oceangnc.console.session`): ``console.mode`` ("remote" in MANUAL / ACRO / HOLD, "auto" in AUTO),
   ``console.loop`` ("open" in MANUAL, "closed" otherwise), ``joystick.surge`` / ``joystick.yaw``
   (the stick in MANUAL / ACRO, zero in HOLD), ``_estop`` (true while disarmed or e-stopped: the
   thruster blocks output zero), and the logged ``mavlink.*`` / ``console.failsafe`` / ``console.estop``;
   when ``_estop`` rises the blocks are fired once at that instant (as the console does) so thrust is
   zero from the next integration step;
4. advance the simulation by whole clock ticks to ``t_sim(anchor) + speed (t_wall - t_wall(anchor))``
   (the console's pacing, re-anchored when it falls more than 0.5 s behind);
5. follow the mission (MISSION_CURRENT, MISSION_ITEM_REACHED, HOLD at the end) and send the
   telemetry that is due (:data:`oceangnc.mavlink.protocol.TELEMETRY`).

The mission feeds the scenario's own guidance through :class:`RouteHook`: a scenario that reads
``console.waypoints`` (``console_route_edit = True``, e.g. ``usv-remote``) gets the route on that
bus key; a scenario whose guidance is a :class:`oceangnc.guidance.pure_pursuit.PurePursuit` block
(``combined-survey`` and friends) gets it through that block's waypoint array (``wp``) and leg
counters, reset as the block's own ``reset`` does, with ``stop_at_end`` off so the run continues in
HOLD after the mission; a scenario with neither runs its own guidance in AUTO and refuses uploads.
A scenario whose blocks do not follow the stick (:func:`reads_stick`) refuses MANUAL / ACRO and gets
thrust zero (``_estop``) in HOLD. ArduPilot's convention is kept: mission item 0 is home, items 1..n are
flown; only MAV_CMD_NAV_WAYPOINT items are route points (other items are stored and reported as
reached in passing).

Safety: the vehicle starts disarmed (thrust zero); arming is refused while the e-stop is latched;
MAV_CMD_DO_FLIGHTTERMINATION param1 = 1 is the e-stop (disarm, thrust zero, latched until a
MAV_CMD_DO_FLIGHTTERMINATION with param1 = 0). The run's Parquet log is written to
``<out_root>/mavlink-<scenario>-<time>/log.parquet`` with ``config.toml`` and ``summary.json``.
"""

from __future__ import annotations

import json
import math
import socket
import threading
import time
import traceback
from pathlib import Path
from typing import Any

import numpy as np

from ..errors import DivergenceError, InputError
from ..io.logs import LogWriter
from .config import MavlinkConfig
from .geo import latlon_to_ned, ned_to_latlon
from .protocol import (
    AUTO,
    HOLD,
    MANUAL,
    ROVER_MODES,
    ROVER_OTHER,
    STICK_MODES,
    TELEMETRY,
    mavlink,
    mode_name,
)

M = mavlink
INT16_MAX = 32767
_GCS_TYPES = (M.MAV_TYPE_GCS,)


def parse_endpoint(text: str) -> tuple[str, int]:
    """``udp:HOST:PORT`` (or ``HOST:PORT``) -> (host, port); InputError otherwise."""
    s = text.strip()
    for pre in ("udpin:", "udp:", "udpout:"):
        if s.startswith(pre):
            s = s[len(pre) :]
            break
    host, _, port = s.rpartition(":")
    try:
        p = int(port)
    except ValueError:
        p = -1
    if not host or not (0 <= p <= 65535):
        raise InputError(f"endpoint {text!r}: expected udp:HOST:PORT, e.g. udp:127.0.0.1:14550")
    return host, p


class _Sender:
    """File-like object for ``MAVLink(file)``: every packed message goes to all live peers."""

    def __init__(self, vehicle):
        self.v = vehicle

    def write(self, buf: bytes) -> None:
        self.v._sendto_peers(bytes(buf))
        if self.v.tlog is not None:  # telemetry log: 8-byte big-endian time stamp (us) + the frame
            stamp = round((self.v.tlog_epoch + self.v.sim.t) * 1e6)
            self.v.tlog.write(stamp.to_bytes(8, "big") + bytes(buf))


class RouteHook:
    """How a mission reaches the scenario's guidance (see the module docstring).

    ``set_route(points)`` gives the route as (north, east) m; ``progress(bus)`` is the number of route
    points reached since; ``available`` says whether the scenario can fly a route at all.
    """

    def __init__(self, scenario, sim):
        self.sim = sim
        self.kind = "none"
        self.block = None
        self.n = 0
        if getattr(scenario, "console_route_edit", False):
            self.kind = "console"
        else:
            from ..guidance.pure_pursuit import PurePursuit

            for b in sim.blocks:
                inner = getattr(b, "block", b)
                if isinstance(inner, PurePursuit):
                    self.kind = "pure_pursuit"
                    self.block = inner
                    inner.stop_at_end = False  # a live vehicle holds after the mission, it does not stop
                    break
        self._base = 0

    @property
    def available(self) -> bool:
        return self.kind != "none"

    def initial_route(self, cfg) -> list[tuple[float, float]]:
        g = getattr(cfg, "guidance", None)
        wps = getattr(g, "waypoints", None) if g is not None else None
        return [(float(a), float(b)) for a, b in (wps or [])]

    def set_route(self, points) -> None:
        pts = tuple((float(a), float(b)) for a, b in points)
        self.n = len(pts)
        bus = self.sim.bus
        if self.kind == "console":
            # the pilot restarts its route when the tuple changes; a repeated identical route is
            # made distinct by a sub-millimetre offset of the first point
            if tuple(bus.get("console.waypoints", ())) == pts and pts:
                pts = ((pts[0][0] + 1e-6, pts[0][1]),) + pts[1:]
            self.sim.inject({"console.waypoints": pts})
            self._base = 0
        elif self.kind == "pure_pursuit":
            b = self.block
            here = (float(bus.get(b.pos_keys[0], 0.0)), float(bus.get(b.pos_keys[1], 0.0)))
            wp = [here]
            for p in pts:
                if math.hypot(p[0] - wp[-1][0], p[1] - wp[-1][1]) > 1e-6:
                    wp.append(p)
            if len(wp) < 2:
                wp.append((here[0] + 1e-3, here[1]))
            b.wp = np.asarray(wp, float)
            b.reset(None)
            b._started = True
            b.reached = 1  # the start point (where the vehicle is)
            self._base = 1 - (len(pts) + 1 - len(wp))  # points dropped as coincident count as reached

    def progress(self, bus) -> int:
        if self.kind == "console":
            if "console.waypoints" not in bus:
                return 0
            return int(bus.get("guidance.wp_index", 0.0))
        if self.kind == "pure_pursuit":
            return int(self.block.reached) - self._base
        return 0


def builds_live(sc) -> bool:
    """A scenario runs live if it overrides ``Scenario.build`` (one Simulation the loop can step)."""
    from ..scenarios.base import Scenario

    return type(sc).build is not Scenario.build


def live_scenarios() -> list[str]:
    from ..scenarios.base import registry

    return [n for n, s in registry().items() if builds_live(s)]


#: blocks that follow ``console.mode`` / ``joystick.*`` but do not declare them yet (core contract 4e36fa4:
#: blocks declare their inputs; until these do, they are known by class)
_STICK_BLOCKS = ("USVPilot", "USVController", "_RemoteGate")


def reads_stick(sim) -> bool:
    """Whether the scenario's blocks follow the operator's stick (``console.mode`` = "remote")."""
    for b in sim.blocks:
        for decl in (getattr(b, "inputs", None), getattr(b, "optional_inputs", None)):
            if isinstance(decl, dict) and ("console.mode" in decl or "joystick.surge" in decl):
                return True
        if type(b).__name__ in _STICK_BLOCKS:
            return True
    return False


def _gate_pilots(sim) -> None:
    """Silence a scenario's own stick pilot while the operator's stick drives (the console's gate)."""
    try:
        from ..console.session import gate_pilots
    except ImportError:  # the console's optional dependencies are absent: no scripted pilots to gate then
        return
    gate_pilots(sim)


def _warm_up(sim, seconds: float = 0.5) -> None:
    """Run the simulation ``seconds`` ahead and restore it exactly (blocks' ``get_state`` / ``set_state``,
    plant states, bus, clock: the checkpoint of the core contract), so that numba compiles every path
    now and not inside the served loop, where a multi-second compile would delay the link watchdog."""
    import copy

    blocks = [b.get_state() for b in sim.blocks]
    xs = [pl.x.copy() for pl in sim.plants]
    bus = copy.deepcopy(sim.bus)
    clock = (sim.k, sim.t, sim._done_k, list(sim.fire_count))
    try:
        sim.run(seconds)
    except Exception:  # noqa: BLE001, S110 a warm-up only; the real run reports any error
        pass
    finally:
        for blk, st in zip(sim.blocks, blocks):
            blk.set_state(st)
        for pl, x in zip(sim.plants, xs):
            pl.x[:] = x
        sim.bus.clear()
        sim.bus.update(bus)
        sim.k, sim.t, sim._done_k, sim.fire_count = clock[0], clock[1], clock[2], list(clock[3])


class MavlinkVehicle:
    """A scenario's live simulation served as a MAVLink vehicle (see the module docstring).

    Parameters
    ----------
    scenario : str
        A live scenario (one with ``build``), default ``usv-remote``.
    overrides : dict
        Scenario config overrides (dotted keys).
    mav : MavlinkConfig or dict
        Endpoint settings (origin, ids, failsafe timeout).
    listen : str
        ``udp:HOST:PORT`` to bind; ground stations that send to it get telemetry back.
    gcs : list of str
        ``udp:HOST:PORT`` addresses that get telemetry from the start (a GCS listening, e.g.
        QGroundControl on 14550 when the vehicle listens elsewhere).
    speed : float
        Simulated seconds per wall second (0 < speed <= 100).
    out_root : path or None
        Folder for the run's log (None: no log).
    duration : float or None
        End the run after this much simulated time (None: until stopped).
    """

    def __init__(
        self,
        scenario: str | None = None,
        overrides: dict | None = None,
        mav: MavlinkConfig | dict | None = None,
        listen: str = "udp:127.0.0.1:14550",
        gcs: list[str] | None = None,
        speed: float = 1.0,
        out_root: str | Path | None = "runs",
        duration: float | None = None,
        loop_hz: float = 100.0,
        max_lag: float = 0.5,
        clock=time.monotonic,
        verbose: bool = False,
        tlog: str | Path | None = None,
        tlog_epoch: float = 1.7e9,
    ):
        from ..api import new_run_dir, resolve_config
        from ..io.config import dump_toml, validate

        if not (0 < speed <= 100 and math.isfinite(speed)):
            raise InputError(f"--speed {speed}: allowed range 0 < speed <= 100 (simulated s per wall s)")
        self.cfg_mav = mav if isinstance(mav, MavlinkConfig) else validate(MavlinkConfig, dict(mav or {}))
        self.speed = float(speed)
        self.duration = duration
        self.loop_period = 1.0 / loop_hz
        self.max_lag = max_lag
        self.clock = clock
        self.verbose = verbose
        host, port = parse_endpoint(listen)  # cheap checks first
        fixed = [parse_endpoint(g) for g in (gcs or [])]
        sc, cfg = resolve_config(scenario or "usv-remote", overrides=overrides)
        if not builds_live(sc):
            raise InputError(
                f"scenario {sc.name} has no live simulation; live scenarios: {', '.join(live_scenarios())}"
            )
        self.scenario, self.cfg = sc, cfg
        self.sim = sim = sc.build(cfg, np.random.default_rng(cfg.sim.seed))
        _gate_pilots(sim)
        self.route = RouteHook(sc, sim)
        self.reads_stick = reads_stick(sim)
        self.has_uuv = "uuv.x" in sim.bus
        # -- state
        self.armed = False
        self.estop = False
        self.failsafe = False
        self.mode = HOLD
        self.stick = (0.0, 0.0)
        self.t_gcs = -math.inf  # wall time of the last message from a ground station
        self.gcs_sysid: int | None = None
        self.counts = {
            "rx_packets": 0,
            "rx_bad": 0,
            "rx_unknown": 0,
            "rx_out_of_range": 0,
            "rx_ignored": 0,
            "tx_packets": 0,
            "tx_errors": 0,
        }
        self.events: list[tuple[float, str]] = []
        self.reached: list[int] = []  # mission seqs reported reached, in order
        self.ended = False
        self.error: str | None = None
        # -- mission: list of dicts (seq, frame, command, current, autocontinue, p1..p4, lat, lon, alt)
        self.mission: list[dict] = []
        self.mission_current = 1
        self._route_seqs: list[int] = []  # mission seq of each route point given to the guidance
        self._progress = 0
        self._upload: dict | None = None
        self._set_initial_mission()
        # -- network
        self.sock = socket.socket(socket.AF_INET, socket.SOCK_DGRAM)
        try:
            self.sock.bind((host, port))
        except OSError as e:
            self.sock.close()
            raise InputError(f"--listen {listen}: cannot bind ({e.strerror or e})") from None
        self.sock.setblocking(False)
        self.address = self.sock.getsockname()
        self.peers: dict[tuple, float] = {}
        self.fixed_peers = fixed
        self._tx = _Sender(self)
        self._tlog_name = tlog  # opened with the log below (a relative name goes into the run folder)
        self.tlog: Any = None
        self.tlog_epoch = float(tlog_epoch)
        c = self.cfg_mav
        self.mav = M.MAVLink(self._tx, srcSystem=c.system_id, srcComponent=M.MAV_COMP_ID_AUTOPILOT1)
        self.mav_uuv = M.MAVLink(self._tx, srcSystem=c.uuv_system_id, srcComponent=M.MAV_COMP_ID_AUTOPILOT1)
        self._parser = M.MAVLink(None)
        self._parser.robust_parsing = True
        self._next_tx = {k: 0.0 for k in TELEMETRY}
        # -- log
        self.run_dir = None
        self.writer = None
        if out_root is not None:
            self.run_dir = new_run_dir(out_root, f"mavlink-{sc.name}")
            self.run_dir.mkdir(parents=True, exist_ok=True)
            dump_toml(cfg, self.run_dir / "config.toml")
            self.writer = LogWriter(self.run_dir / "log.parquet")
        if self._tlog_name is not None:
            tp = Path(self._tlog_name)
            if not tp.is_absolute() and self.run_dir is not None:
                tp = self.run_dir / tp
            self.tlog = open(tp, "wb")  # noqa: SIM115 (closed in close())
            self.tlog_path = tp
        self._lock = threading.RLock()
        self._stop = threading.Event()
        self._thread: threading.Thread | None = None
        self.tick_s = sim.tick * sim.dt
        _warm_up(sim)
        self._push_bus()
        sim.run(0.0, log=self.writer)
        self._anchor = (self.clock(), sim.t)
        self.event(
            f"vehicle up: scenario {sc.name}, system {c.system_id}"
            + (f" + UUV system {c.uuv_system_id}" if self.has_uuv else "")
            + f", listening on udp:{self.address[0]}:{self.address[1]}, disarmed, HOLD"
        )

    # -- mission store -------------------------------------------------------------------------------
    def _item(self, seq: int, n: float, e: float, command: int = M.MAV_CMD_NAV_WAYPOINT, alt: float = 0.0) -> dict:
        c = self.cfg_mav
        lat, lon = ned_to_latlon(n, e, c.origin_lat_deg, c.origin_lon_deg)
        return {
            "seq": seq,
            "frame": M.MAV_FRAME_GLOBAL_RELATIVE_ALT_INT if seq else M.MAV_FRAME_GLOBAL_INT,
            "command": command,
            "current": 0,
            "autocontinue": 1,
            "p1": 0.0,
            "p2": 0.0,
            "p3": 0.0,
            "p4": 0.0,
            "lat": lat,
            "lon": lon,
            "alt": alt,
        }

    def _set_initial_mission(self) -> None:
        pts = self.route.initial_route(self.cfg) if self.route.available else []
        self.mission = [self._item(0, 0.0, 0.0, alt=self.cfg_mav.origin_alt_m)]
        self.mission += [self._item(i + 1, n, e) for i, (n, e) in enumerate(pts)]
        self.mission_current = 1

    def _nav_points(self, start: int) -> tuple[list[tuple[float, float]], list[int]]:
        c = self.cfg_mav
        pts, seqs = [], []
        for it in self.mission[max(1, start) :]:
            if it["command"] == M.MAV_CMD_NAV_WAYPOINT:
                pts.append(latlon_to_ned(it["lat"], it["lon"], c.origin_lat_deg, c.origin_lon_deg))
                seqs.append(it["seq"])
        return pts, seqs

    def _start_mission(self) -> None:
        """Hand the mission from ``mission_current`` on to the guidance."""
        pts, seqs = self._nav_points(self.mission_current)
        self._route_seqs = seqs
        self._progress = 0
        if pts:
            self.route.set_route(pts)
            self._progress = self.route.progress(self.sim.bus) if self.route.kind == "pure_pursuit" else 0

    # -- events ------------------------------------------------------------------------------------------
    def event(self, text: str, severity: int = M.MAV_SEVERITY_INFO) -> None:
        self.events.append((float(self.sim.t), text))
        if self.verbose:
            print(f"[t={self.sim.t:8.2f}] {text}", flush=True)
        if hasattr(self, "mav"):
            self._send(self.mav.statustext_encode(severity, text[:50].encode()))

    # -- network ---------------------------------------------------------------------------------------
    def _sendto_peers(self, buf: bytes) -> None:
        now = self.clock()
        dests = set(self.fixed_peers)
        dests.update(a for a, t in self.peers.items() if now - t <= self.cfg_mav.peer_timeout_s)
        for a in dests:
            try:
                self.sock.sendto(buf, a)
                self.counts["tx_packets"] += 1
            except OSError:
                pass

    def _send(self, msg, uuv: bool = False) -> None:
        (self.mav_uuv if uuv else self.mav).send(msg)

    def _receive(self) -> None:
        c = self.cfg_mav
        p = self._parser
        for _ in range(c.max_packets_per_loop):
            try:
                data, addr = self.sock.recvfrom(65535)
            except (BlockingIOError, InterruptedError):
                return
            except OSError:
                return
            self.counts["rx_packets"] += 1
            p.buf = bytearray()
            p.buf_index = 0
            p.expected_length = M.HEADER_LEN_V1 + 2
            p.have_prefix_error = False
            try:
                msgs = p.parse_buffer(data) or []
            except Exception:  # noqa: BLE001
                self.counts["rx_bad"] += 1
                continue
            if p.buf_len() > 0:  # a truncated message at the end of the datagram
                self.counts["rx_bad"] += 1
            good = False
            for m in msgs:
                kind = m.get_type()
                if kind == "BAD_DATA":
                    reason = str(getattr(m, "reason", ""))
                    self.counts["rx_unknown" if "unknown MAVLink message ID" in reason else "rx_bad"] += 1
                    continue
                if kind.startswith("UNKNOWN_"):  # a well-formed frame of a message id outside the dialect
                    self.counts["rx_unknown"] += 1
                    continue
                if m.get_srcSystem() in (c.system_id, c.uuv_system_id) and m.get_srcComponent() == 1:
                    continue  # our own echo
                good = True
                try:
                    self._handle(m)
                except Exception as e:  # noqa: BLE001 a message must never stop the run
                    self.counts["rx_bad"] += 1
                    self.event(f"{m.get_type()} failed: {type(e).__name__}", M.MAV_SEVERITY_WARNING)
            if good:
                self.peers[addr] = self.clock()

    # -- message handling -------------------------------------------------------------------------------
    def _for_us(self, m) -> bool:
        ts = getattr(m, "target_system", 0)
        return ts in (0, self.cfg_mav.system_id)

    def _link_alive(self, m) -> None:
        self.t_gcs = self.clock()
        if self.gcs_sysid is None:
            self.gcs_sysid = m.get_srcSystem()
        if self.failsafe:
            self.failsafe = False
            self.event("GCS link restored; failsafe cleared (mode stays HOLD)")

    def _oor(self, what: str) -> None:
        self.counts["rx_out_of_range"] += 1
        if self.counts["rx_out_of_range"] in (1, 10, 100, 1000):
            self.event(f"ignored out-of-range {what}", M.MAV_SEVERITY_WARNING)

    def _handle(self, m) -> None:
        kind = m.get_type()
        if kind == "HEARTBEAT":
            if m.type in _GCS_TYPES or m.get_srcSystem() not in (self.cfg_mav.system_id, self.cfg_mav.uuv_system_id):
                self._link_alive(m)
            return
        if kind in ("RADIO_STATUS", "TIMESYNC", "SYSTEM_TIME", "REQUEST_DATA_STREAM", "MISSION_ACK", "GCS_HEARTBEAT"):
            self._link_alive(m)
            if kind == "MISSION_ACK":
                pass
            return
        if not self._for_us(m):
            if getattr(m, "target_system", 0) == self.cfg_mav.uuv_system_id and kind == "COMMAND_LONG":
                self._send(self.mav_uuv.command_ack_encode(m.command, M.MAV_RESULT_UNSUPPORTED))
            self.counts["rx_ignored"] += 1
            return
        self._link_alive(m)
        h = getattr(self, "_on_" + kind.lower(), None)
        if h is None:
            self.counts["rx_ignored"] += 1
            return
        h(m)

    def _ack(self, command: int, result: int) -> None:
        self._send(self.mav.command_ack_encode(command, result))

    def _on_command_long(self, m) -> None:
        cmd = m.command
        if cmd == M.MAV_CMD_COMPONENT_ARM_DISARM:
            self._ack(cmd, self._arm(m.param1 > 0.5))
        elif cmd == M.MAV_CMD_DO_SET_MODE:
            self._ack(cmd, self._set_mode(round(m.param2), "DO_SET_MODE"))
        elif cmd == M.MAV_CMD_DO_FLIGHTTERMINATION:
            self._ack(cmd, self._estop(m.param1 > 0.5))
        elif cmd == M.MAV_CMD_MISSION_START:  # ArduPilot: start the mission in AUTO from param1 (0: current)
            first = round(m.param1)
            if first >= 1:
                self._set_current(first)
            self._ack(cmd, self._set_mode(AUTO, "MISSION_START"))
        elif cmd == M.MAV_CMD_DO_SET_MISSION_CURRENT:
            self._ack(cmd, self._set_current(round(m.param1)))
        elif cmd == M.MAV_CMD_REQUEST_MESSAGE:
            mid = round(m.param1)
            if mid == M.MAVLINK_MSG_ID_AUTOPILOT_VERSION:
                self._ack(cmd, M.MAV_RESULT_ACCEPTED)
                self._send_autopilot_version()
            elif mid == M.MAVLINK_MSG_ID_HOME_POSITION:
                self._ack(cmd, M.MAV_RESULT_ACCEPTED)
                self._send_home()
            else:
                self._ack(cmd, M.MAV_RESULT_UNSUPPORTED)
        elif cmd == M.MAV_CMD_REQUEST_AUTOPILOT_CAPABILITIES:
            self._ack(cmd, M.MAV_RESULT_ACCEPTED)
            self._send_autopilot_version()
        elif cmd == M.MAV_CMD_GET_HOME_POSITION:
            self._ack(cmd, M.MAV_RESULT_ACCEPTED)
            self._send_home()
        else:
            self.counts["rx_ignored"] += 1
            self._ack(cmd, M.MAV_RESULT_UNSUPPORTED)

    def _on_command_int(self, m) -> None:
        if m.command == M.MAV_CMD_DO_SET_MODE:
            self._ack(m.command, self._set_mode(round(m.param2), "DO_SET_MODE"))
        else:
            self.counts["rx_ignored"] += 1
            self._ack(m.command, M.MAV_RESULT_UNSUPPORTED)

    def _on_set_mode(self, m) -> None:
        res = self._set_mode(int(m.custom_mode), "SET_MODE")
        self._ack(M.MAVLINK_MSG_ID_SET_MODE, res)

    def _arm(self, arm: bool) -> int:
        if arm:
            if self.estop:
                self.event("Arm: refused, e-stop latched", M.MAV_SEVERITY_WARNING)
                return M.MAV_RESULT_DENIED
            if self.ended:
                return M.MAV_RESULT_DENIED
            if not self.armed:
                self.armed = True
                self.event("Throttle armed")
        elif self.armed:
            self.armed = False
            self.event("Throttle disarmed")
        return M.MAV_RESULT_ACCEPTED

    def _set_mode(self, num: int, via: str) -> int:
        if num not in ROVER_MODES:
            self._oor(f"{via} mode {num} ({ROVER_OTHER.get(num, 'unknown')})")
            return M.MAV_RESULT_DENIED
        if num in STICK_MODES and not self.reads_stick:
            self.event(f"{mode_name(num)} refused: {self.scenario.name} takes no stick", M.MAV_SEVERITY_WARNING)
            return M.MAV_RESULT_DENIED
        if num == AUTO and num != self.mode and self.route.available:
            start = self.mission_current if self.mission_current < len(self.mission) else 1
            if not self._nav_points(start)[0]:
                self.event("AUTO refused: no waypoint in the mission", M.MAV_SEVERITY_WARNING)
                return M.MAV_RESULT_DENIED
        if num != self.mode:
            self.mode = num
            self.stick = (0.0, 0.0)
            if num in STICK_MODES:
                self.t_gcs = max(self.t_gcs, self.clock())  # grace for the first stick message
            if num == AUTO and self.route.available:
                if self.mission_current >= len(self.mission):
                    self.mission_current = 1
                self._start_mission()
            self.event(
                f"Mode {mode_name(num)}"
                + ("" if num != AUTO or self.route.available else ": the scenario's own guidance (no mission upload)")
            )
        return M.MAV_RESULT_ACCEPTED

    def _estop(self, engage: bool) -> int:
        if engage and not self.estop:
            self.estop = True
            self.armed = False
            self.event("EMERGENCY STOP: thrust zero, disarmed (latched)", M.MAV_SEVERITY_EMERGENCY)
        elif not engage and self.estop:
            self.estop = False
            self.stick = (0.0, 0.0)
            self.event("e-stop reset (still disarmed)")
        return M.MAV_RESULT_ACCEPTED

    def _on_manual_control(self, m) -> None:
        if m.target not in (0, self.cfg_mav.system_id):
            return
        x = 0 if m.x == INT16_MAX else m.x
        r = 0 if m.r == INT16_MAX else m.r
        if abs(x) > 1000 or abs(r) > 1000:
            self._oor(f"MANUAL_CONTROL x={m.x} r={m.r}")
            return
        if self.mode in STICK_MODES:
            self.stick = (x / 1000.0, r / 1000.0)

    def _on_rc_channels_override(self, m) -> None:
        def axis(pwm):
            if pwm in (0, 65535):
                return None
            if not (800 <= pwm <= 2200):
                raise ValueError(pwm)
            return max(-1.0, min(1.0, (pwm - 1500) / 400.0))

        try:
            yaw = axis(m.chan1_raw)
            surge = axis(m.chan3_raw)
        except ValueError:
            self._oor(f"RC_CHANNELS_OVERRIDE ch1={m.chan1_raw} ch3={m.chan3_raw}")
            return
        if self.mode in STICK_MODES:
            self.stick = (self.stick[0] if surge is None else surge, self.stick[1] if yaw is None else yaw)

    def _on_param_request_list(self, m) -> None:
        params = self._params()
        for i, (k, v) in enumerate(params.items()):
            self._send(self.mav.param_value_encode(k.encode(), v, M.MAV_PARAM_TYPE_REAL32, len(params), i))

    def _on_param_request_read(self, m) -> None:
        params = self._params()
        names = list(params)
        pid = m.param_id.decode() if isinstance(m.param_id, bytes) else str(m.param_id)
        idx = m.param_index if 0 <= m.param_index < len(names) else (names.index(pid) if pid in names else -1)
        if idx >= 0:
            k = names[idx]
            self._send(self.mav.param_value_encode(k.encode(), params[k], M.MAV_PARAM_TYPE_REAL32, len(names), idx))

    def _params(self) -> dict[str, float]:
        return {
            "FS_GCS_TIMEOUT": float(self.cfg_mav.gcs_timeout_s),
            "SYSID_THISMAV": float(self.cfg_mav.system_id),
            "SIM_SPEEDUP": float(self.speed),
        }

    # -- mission protocol --------------------------------------------------------------------------------
    def _mission_ack(self, result: int, mission_type: int = 0) -> None:
        sysid = self.gcs_sysid or 255
        self._send(self.mav.mission_ack_encode(sysid, 0, result, mission_type))

    def _on_mission_count(self, m) -> None:
        mt = getattr(m, "mission_type", 0)
        if mt != M.MAV_MISSION_TYPE_MISSION or not self.route.available:
            if mt == M.MAV_MISSION_TYPE_MISSION:
                self.event(f"Mission refused: {self.scenario.name} flies its own route", M.MAV_SEVERITY_WARNING)
            self._mission_ack(M.MAV_MISSION_UNSUPPORTED, mt)
            return
        if m.count > self.cfg_mav.max_mission_items:
            self._oor(f"MISSION_COUNT {m.count}")
            self._mission_ack(M.MAV_MISSION_NO_SPACE)
            return
        if m.count == 0:
            self.mission = self.mission[:1]
            self._mission_ack(M.MAV_MISSION_ACCEPTED)
            self.event("Mission cleared")
            return
        self._upload = {
            "count": int(m.count),
            "items": [],
            "t": self.clock(),
            "tries": 0,
            "sys": m.get_srcSystem(),
            "comp": m.get_srcComponent(),
        }
        self._request_item()

    def _request_item(self) -> None:
        u = self._upload
        if u is None:
            return
        seq = len(u["items"])
        self._send(self.mav.mission_request_int_encode(u["sys"], u["comp"], seq, 0))

    def _on_mission_item_int(self, m, scale: float = 1e-7) -> None:
        u = self._upload
        if u is None or getattr(m, "mission_type", 0) != 0:
            self.counts["rx_ignored"] += 1
            return
        seq = len(u["items"])
        if m.seq != seq:
            self._request_item()  # ask again for the one we need
            return
        lat, lon = m.x * scale, m.y * scale
        if m.command == M.MAV_CMD_NAV_WAYPOINT and m.seq > 0 and not (-90 <= lat <= 90 and -180 <= lon <= 180):
            self._oor(f"MISSION_ITEM seq {m.seq} lat {lat} lon {lon}")
            self._upload = None
            self._mission_ack(M.MAV_MISSION_INVALID_PARAM5 if abs(lat) > 90 else M.MAV_MISSION_INVALID_PARAM6)
            return
        u["items"].append(
            {
                "seq": m.seq,
                "frame": m.frame,
                "command": m.command,
                "current": m.current,
                "autocontinue": m.autocontinue,
                "p1": m.param1,
                "p2": m.param2,
                "p3": m.param3,
                "p4": m.param4,
                "lat": lat,
                "lon": lon,
                "alt": float(m.z),
            }
        )
        u["t"] = self.clock()
        u["tries"] = 0
        if len(u["items"]) < u["count"]:
            self._request_item()
            return
        self.mission = u["items"]
        self._upload = None
        self.mission_current = 1
        self._mission_ack(M.MAV_MISSION_ACCEPTED)
        n_nav = len(self._nav_points(1)[0])
        self.event(f"Mission: {len(self.mission)} items, {n_nav} waypoints")
        if self.mode == AUTO:
            self._start_mission()

    def _on_mission_item(self, m) -> None:
        self._on_mission_item_int(m, scale=1.0)

    def _on_mission_request_list(self, m) -> None:
        if getattr(m, "mission_type", 0) != 0:
            self._send(self.mav.mission_count_encode(m.get_srcSystem(), m.get_srcComponent(), 0, m.mission_type))
            return
        self._send(self.mav.mission_count_encode(m.get_srcSystem(), m.get_srcComponent(), len(self.mission), 0))

    def _send_item(self, m, as_int: bool) -> None:
        if getattr(m, "mission_type", 0) != 0 or not (0 <= m.seq < len(self.mission)):
            self._oor(f"mission request seq {m.seq}")
            self._mission_ack(M.MAV_MISSION_INVALID_SEQUENCE)
            return
        it = self.mission[m.seq]
        cur = 1 if it["seq"] == self.mission_current else 0
        args = (
            m.get_srcSystem(),
            m.get_srcComponent(),
            it["seq"],
            it["frame"],
            it["command"],
            cur,
            it["autocontinue"],
            it["p1"],
            it["p2"],
            it["p3"],
            it["p4"],
        )
        if as_int:
            self._send(
                self.mav.mission_item_int_encode(*args, round(it["lat"] * 1e7), round(it["lon"] * 1e7), it["alt"], 0)
            )
        else:
            self._send(self.mav.mission_item_encode(*args, it["lat"], it["lon"], it["alt"], 0))

    def _on_mission_request_int(self, m) -> None:
        self._send_item(m, True)

    def _on_mission_request(self, m) -> None:
        self._send_item(m, False)

    def _on_mission_clear_all(self, m) -> None:
        self.mission = self.mission[:1]
        self.mission_current = 1
        self._mission_ack(M.MAV_MISSION_ACCEPTED)
        self.event("Mission cleared")

    def _set_current(self, seq: int) -> int:
        if not (1 <= seq < len(self.mission)):
            self._oor(f"mission current {seq}")
            return M.MAV_RESULT_DENIED
        self.mission_current = seq
        if self.mode == AUTO:
            self._start_mission()
        self._send(self.mav.mission_current_encode(seq))
        return M.MAV_RESULT_ACCEPTED

    def _on_mission_set_current(self, m) -> None:
        self._set_current(int(m.seq))

    def _upload_watchdog(self, now: float) -> None:
        u = self._upload
        if u is None or now - u["t"] < 1.0:
            return
        u["tries"] += 1
        u["t"] = now
        if u["tries"] * 1.0 > self.cfg_mav.mission_timeout_s:
            self._upload = None
            self._mission_ack(M.MAV_MISSION_OPERATION_CANCELLED)
            self.event("Mission upload timed out", M.MAV_SEVERITY_WARNING)
        else:
            self._request_item()

    def _follow_mission(self) -> None:
        if self.mode != AUTO or not self._route_seqs:
            return
        k = min(self.route.progress(self.sim.bus), len(self._route_seqs))
        while self._progress < k:
            seq = self._route_seqs[self._progress]
            self._progress += 1
            self.reached.append(seq)
            self._send(self.mav.mission_item_reached_encode(seq))
            self.event(f"Reached waypoint #{seq}")
            self.mission_current = self._route_seqs[self._progress] if self._progress < len(self._route_seqs) else seq
            self._send(self.mav.mission_current_encode(self.mission_current))
        if self._progress >= len(self._route_seqs):
            self._route_seqs = []
            self.mode = HOLD
            self.mission_current = len(self.mission)  # past the end: AUTO restarts from item 1
            self.event("Mission complete, changing mode to Hold")

    # -- failsafe, bus, pacing ---------------------------------------------------------------------------
    def _watchdog(self, now: float) -> None:
        if self.mode in STICK_MODES and not self.failsafe and now - self.t_gcs > self.cfg_mav.gcs_timeout_s:
            self.failsafe = True
            self.mode = HOLD
            self.stick = (0.0, 0.0)
            self.event("Failsafe: GCS link lost, HOLD", M.MAV_SEVERITY_CRITICAL)

    def _push_bus(self) -> None:
        # thrust zero while disarmed or e-stopped, and in HOLD when the scenario cannot take a zero stick
        stop = (not self.armed) or self.estop or (self.mode == HOLD and not self.reads_stick)
        stick = self.stick if self.mode in STICK_MODES else (0.0, 0.0)
        vals = {
            "console.mode": "auto" if self.mode == AUTO else "remote",
            "console.loop": "open" if self.mode == MANUAL else "closed",
            "joystick.surge": float(stick[0]),
            "joystick.yaw": float(stick[1]),
            "_estop": bool(stop),
            "console.failsafe": float(self.failsafe),
            "console.estop": float(self.estop),
            "mavlink.armed": float(self.armed),
            "mavlink.mode": float(self.mode),
            "mavlink.mission_current": float(self.mission_current),
        }
        vals.update({f"mavlink.{k}": float(v) for k, v in self.counts.items() if not k.startswith("tx_")})
        self.sim.inject(vals)

    def step_once(self) -> None:
        """One loop pass (see the module docstring)."""
        with self._lock:
            now = self.clock()
            self._receive()
            self._upload_watchdog(now)
            self._watchdog(now)
            sim = self.sim
            was = bool(sim.bus.get("_estop", False))
            self._push_bus()
            if sim.bus["_estop"] and not was:
                for b in sim.blocks:  # thrust zero before the next integration step
                    b.step(sim.t, sim.bus)
            if not self.ended:
                w0, s0 = self._anchor
                lag = s0 + self.speed * (now - w0) - sim.t
                if lag > self.max_lag:
                    self._anchor = (now, sim.t)
                    lag = self.max_lag
                n = math.floor(lag / self.tick_s + 1e-9)
                if self.duration is not None:
                    n = min(n, math.ceil((self.duration - sim.t) / self.tick_s - 1e-9))
                if n >= 1:
                    try:
                        sim.run(n * self.tick_s, log=self.writer)
                    except DivergenceError as e:
                        self._end(f"simulation diverged: {e}")
                    except Exception as e:  # noqa: BLE001
                        traceback.print_exc()
                        self._end(f"simulation failed: {type(e).__name__}: {e}")
                    else:
                        if sim.bus.get("_stop", False):
                            self._end(f"scenario finished at t = {sim.t:.1f} s")
                if self.duration is not None and sim.t >= self.duration - 1e-9 and not self.ended:
                    self._end(f"duration {self.duration:g} s reached")
            self._follow_mission()
            try:
                self._telemetry(now)
            except Exception as e:  # noqa: BLE001 a value outside a field's range must not stop the run
                self.counts["tx_errors"] = self.counts.get("tx_errors", 0) + 1
                if self.counts["tx_errors"] in (1, 100):
                    self.events.append((float(self.sim.t), f"telemetry error: {type(e).__name__}: {e}"))

    def _end(self, text: str) -> None:
        self.ended = True
        self.armed = False
        self.error = text if "diverged" in text or "failed" in text else None
        self.event(text, M.MAV_SEVERITY_WARNING)

    # -- telemetry -------------------------------------------------------------------------------------
    def _due(self, name: str, now: float) -> bool:
        if now >= self._next_tx[name]:
            rate = TELEMETRY[name][0]
            self._next_tx[name] = max(self._next_tx[name] + 1.0 / rate, now)
            return True
        return False

    def _heartbeat(self, uuv: bool = False) -> None:
        base = M.MAV_MODE_FLAG_CUSTOM_MODE_ENABLED
        if self.armed:
            base |= M.MAV_MODE_FLAG_SAFETY_ARMED
        if self.mode in STICK_MODES:
            base |= M.MAV_MODE_FLAG_MANUAL_INPUT_ENABLED
        elif self.mode == AUTO:
            base |= M.MAV_MODE_FLAG_AUTO_ENABLED | M.MAV_MODE_FLAG_GUIDED_ENABLED | M.MAV_MODE_FLAG_STABILIZE_ENABLED
        if self.estop:
            status = M.MAV_STATE_EMERGENCY
        elif self.failsafe:
            status = M.MAV_STATE_CRITICAL
        else:
            status = M.MAV_STATE_ACTIVE if self.armed else M.MAV_STATE_STANDBY
        typ = M.MAV_TYPE_SUBMARINE if uuv else M.MAV_TYPE_SURFACE_BOAT
        self._send(
            (self.mav_uuv if uuv else self.mav).heartbeat_encode(
                typ, M.MAV_AUTOPILOT_ARDUPILOTMEGA, base, self.mode, status
            ),
            uuv=uuv,
        )

    def _body(self, name: str) -> dict:
        b = self.sim.bus

        def g(k, d=0.0):
            return float(b.get(f"{name}.{k}", d))

        x, y, z = g("x"), g("y"), g("z")
        psi, u, v, w = g("psi"), g("u"), g("v"), g("w")
        vn = u * math.cos(psi) - v * math.sin(psi)
        ve = u * math.sin(psi) + v * math.cos(psi)
        return {
            "x": x,
            "y": y,
            "z": z,
            "psi": psi,
            "phi": g("phi"),
            "theta": g("theta"),
            "p": g("p"),
            "q": g("q"),
            "r": g("r"),
            "vn": vn,
            "ve": ve,
            "vd": w if name == "uuv" else 0.0,
            "speed": math.hypot(vn, ve),
        }

    def _global_position(self, s: dict, uuv: bool) -> None:
        c = self.cfg_mav
        lat, lon = ned_to_latlon(s["x"], s["y"], c.origin_lat_deg, c.origin_lon_deg)
        depth = s["z"] if uuv else 0.0
        hdg = round(math.degrees(s["psi"]) % 360.0 * 100) % 36000
        tms = int(self.sim.t * 1000) & 0xFFFFFFFF

        def cl(v):
            return int(max(-32767, min(32767, round(v * 100))))

        self._send(
            (self.mav_uuv if uuv else self.mav).global_position_int_encode(
                tms,
                round(lat * 1e7),
                round(lon * 1e7),
                round((c.origin_alt_m - depth) * 1000),
                round(-depth * 1000),
                cl(s["vn"]),
                cl(s["ve"]),
                cl(s["vd"]),
                hdg,
            ),
            uuv=uuv,
        )

    def _attitude(self, s: dict, uuv: bool) -> None:
        psi = math.atan2(math.sin(s["psi"]), math.cos(s["psi"]))
        self._send(
            (self.mav_uuv if uuv else self.mav).attitude_encode(
                int(self.sim.t * 1000) & 0xFFFFFFFF, s["phi"], s["theta"], psi, s["p"], s["q"], s["r"]
            ),
            uuv=uuv,
        )

    def _throttle(self) -> int:
        b = self.sim.bus
        usv = getattr(self.cfg, "usv", None)
        tmax = getattr(usv, "max_thrust_kgf", None)
        if tmax is None or "usv.thrust_port" not in b:
            return 0
        mean = 0.5 * (float(b["usv.thrust_port"]) + float(b.get("usv.thrust_stbd", b["usv.thrust_port"])))
        return round(min(100.0, 100.0 * abs(mean) / (tmax * 9.80665)))  # VFR_HUD.throttle is 0..100

    def _pwm(self, side: str) -> int:
        """Thruster ``side`` as servo PWM: 1500 + 400 T / T_max ahead (T / T_rev astern), us."""
        usv = getattr(self.cfg, "usv", None)
        T = float(self.sim.bus.get(f"usv.thrust_{side}", 0.0))
        hi = getattr(usv, "max_thrust_kgf", None)
        lo = getattr(usv, "max_reverse_kgf", hi)
        if not hi:
            return 1500
        full = (hi if T >= 0 else (lo or hi)) * 9.80665
        return round(1500 + 400 * max(-1.0, min(1.0, T / full)))

    def _telemetry(self, now: float) -> None:
        if not self.peers and not self.fixed_peers and self.tlog is None:
            return
        c = self.cfg_mav
        usv = self._body("usv")
        uuv = self._body("uuv") if self.has_uuv else None
        if self._due("HEARTBEAT", now):
            self._heartbeat()
            if uuv is not None:
                self._heartbeat(uuv=True)
        if self._due("SYS_STATUS", now):
            sensors = (
                M.MAV_SYS_STATUS_SENSOR_GPS | M.MAV_SYS_STATUS_SENSOR_3D_GYRO | M.MAV_SYS_STATUS_SENSOR_MOTOR_OUTPUTS
            )
            gps_ok = float(self.sim.bus.get("gps.valid", 1.0)) > 0.5
            healthy = sensors if gps_ok else sensors & ~M.MAV_SYS_STATUS_SENSOR_GPS
            n = max(1, self.counts["rx_packets"])
            drop = int(min(10000, 10000 * self.counts["rx_bad"] / n))

            def cap(v):
                return min(65535, int(v))

            self._send(
                self.mav.sys_status_encode(
                    sensors,
                    sensors,
                    healthy,
                    0,
                    0,
                    -1,
                    -1,
                    drop,
                    0,
                    cap(self.counts["rx_bad"]),
                    cap(self.counts["rx_unknown"]),
                    cap(self.counts["rx_out_of_range"]),
                    0,
                )
            )
        if self._due("GPS_RAW_INT", now):
            b = self.sim.bus
            gx, gy = float(b.get("gps.x", usv["x"])), float(b.get("gps.y", usv["y"]))
            lat, lon = ned_to_latlon(gx, gy, c.origin_lat_deg, c.origin_lon_deg)
            fix = 3 if float(b.get("gps.valid", 1.0)) > 0.5 else 0
            cog = round(math.degrees(math.atan2(usv["ve"], usv["vn"])) % 360.0 * 100) % 36000
            self._send(
                self.mav.gps_raw_int_encode(
                    int(self.sim.t * 1e6),
                    fix,
                    round(lat * 1e7),
                    round(lon * 1e7),
                    round(c.origin_alt_m * 1000),
                    100,
                    100,
                    round(usv["speed"] * 100),
                    cog,
                    12,
                )
            )
        if self._due("GLOBAL_POSITION_INT", now):
            self._global_position(usv, False)
            if uuv is not None:
                self._global_position(uuv, True)
        if self._due("ATTITUDE", now):
            self._attitude(usv, False)
            if uuv is not None:
                self._attitude(uuv, True)
        if self._due("VFR_HUD", now):
            hdg = round(math.degrees(usv["psi"])) % 360
            self._send(self.mav.vfr_hud_encode(usv["speed"], usv["speed"], hdg, self._throttle(), c.origin_alt_m, 0.0))
            if uuv is not None:
                self._send(
                    self.mav_uuv.vfr_hud_encode(
                        uuv["speed"],
                        uuv["speed"],
                        round(math.degrees(uuv["psi"])) % 360,
                        0,
                        c.origin_alt_m - uuv["z"],
                        -uuv["vd"],
                    ),
                    uuv=True,
                )
        if self._due("NAMED_VALUE_FLOAT", now):
            tms = int(self.sim.t * 1000) & 0xFFFFFFFF
            b = self.sim.bus
            if "cable.top_tension" in b:
                self._send(self.mav.named_value_float_encode(tms, b"cable_T", float(b["cable.top_tension"])))
            if uuv is not None:
                self._send(self.mav.named_value_float_encode(tms, b"uuv_depth", uuv["z"]))
            self._send(self.mav.named_value_float_encode(tms, b"rx_bad", float(self.counts["rx_bad"])))
        if self._due("SERVO_OUTPUT_RAW", now):
            self._send(
                self.mav.servo_output_raw_encode(
                    int(self.sim.t * 1e6) & 0xFFFFFFFF, 0, self._pwm("port"), 1500, self._pwm("stbd"), 1500, 0, 0, 0, 0
                )
            )
        if self._due("MISSION_CURRENT", now):
            self._send(self.mav.mission_current_encode(min(self.mission_current, max(0, len(self.mission) - 1))))

    def _send_autopilot_version(self) -> None:
        caps = (
            M.MAV_PROTOCOL_CAPABILITY_MISSION_INT
            | M.MAV_PROTOCOL_CAPABILITY_MAVLINK2
            | M.MAV_PROTOCOL_CAPABILITY_COMMAND_INT
        )
        self._send(self.mav.autopilot_version_encode(caps, 0, 0, 0, 0, [0] * 8, [0] * 8, [0] * 8, 0, 0, 0))

    def _send_home(self) -> None:
        c = self.cfg_mav
        self._send(
            self.mav.home_position_encode(
                round(c.origin_lat_deg * 1e7),
                round(c.origin_lon_deg * 1e7),
                round(c.origin_alt_m * 1000),
                0.0,
                0.0,
                0.0,
                [1, 0, 0, 0],
                0.0,
                0.0,
                0.0,
            )
        )

    # -- running ---------------------------------------------------------------------------------------
    def _loop(self) -> None:
        while not self._stop.is_set():
            t0 = self.clock()
            try:
                self.step_once()
            except Exception as e:  # noqa: BLE001 keep serving whatever happens
                traceback.print_exc()
                self.events.append((float(self.sim.t), f"loop error: {type(e).__name__}: {e}"))
            self._stop.wait(max(0.0005, self.loop_period - (self.clock() - t0)))

    def start(self) -> MavlinkVehicle:
        """Serve in a background thread (tests); :meth:`stop` ends it and closes the log."""
        if self._thread is None:
            self._anchor = (self.clock(), self.sim.t)
            self._thread = threading.Thread(target=self._loop, name="oceangnc-mavlink", daemon=True)
            self._thread.start()
        return self

    def serve(self, wall_limit: float | None = None) -> None:
        """Serve in the foreground until Ctrl-C, the end of ``duration`` or ``wall_limit`` s."""
        self._anchor = (self.clock(), self.sim.t)
        t_end = None if wall_limit is None else self.clock() + wall_limit
        try:
            while not self.ended and (t_end is None or self.clock() < t_end):
                t0 = self.clock()
                self.step_once()
                time.sleep(max(0.0005, self.loop_period - (self.clock() - t0)))
        finally:
            self.close()

    def stop(self) -> None:
        self._stop.set()
        if self._thread is not None:
            self._thread.join(timeout=10)
            self._thread = None
        self.close()

    def close(self) -> None:
        """Close the socket and the log (writes summary.json); safe to call twice."""
        with self._lock:
            try:
                self.sock.close()
            except OSError:
                pass
            if self.tlog is not None:
                self.tlog.close()
                self.tlog = None
            if self.writer is None or self.run_dir is None:
                return
            self.writer.close()
            summary = {
                "scenario": self.scenario.name,
                "source": "mavlink",
                "duration_s": float(self.sim.t),
                "armed_at_end": self.armed,
                "mode_at_end": mode_name(self.mode),
                "waypoints_reached": list(self.reached),
                **{f"mavlink.{k}": v for k, v in self.counts.items()},
                "events": [f"{t:.2f} {s}" for t, s in self.events[-200:]],
            }
            if self.error:
                summary["error"] = self.error
            (self.run_dir / "summary.json").write_text(json.dumps(summary, indent=2))
            self.writer = None
