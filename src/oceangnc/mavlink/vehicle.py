"""A live scenario as a MAVLink vehicle: ``oceangnc mavlink [SCENARIO] --listen udp:127.0.0.1:14550``.

One loop (default 100 Hz, run in a thread by :meth:`MavlinkVehicle.start` or in the foreground by
:meth:`MavlinkVehicle.serve`) does, each pass,

1. read every UDP datagram waiting (at most ``mavlink.max_packets_per_loop``), parse it with a fresh
   MAVLink 2 parser state (a malformed datagram cannot corrupt the next one), and handle each message
   (commands, modes, sticks, mission and parameter protocols, rates; system 2's in :mod:`.uuv`);
   malformed datagrams, unknown message ids and out-of-range values are counted (``mavlink.rx_bad``,
   ``mavlink.rx_unknown``, ``mavlink.rx_out_of_range`` on the bus and in the log) and otherwise ignored;
2. run ArduPilot Rover's failsafes (:meth:`MavlinkVehicle._watchdog`): the *controlling* ground station
   silent for FS_GCS_TIMEOUT (5 s) in a stick mode, or in any mode but HOLD / RTL / SMART_RTL while armed
   once it has been heard, or a stick stream that was flowing stopped for RC_OVERRIDE_TIME (3 s), runs
   FS_ACTION (HOLD, RTL or SMART_RTL, :mod:`.nav`); other systems' heartbeats do not count;
3. write the vehicle's state onto the simulation bus with ``sim.inject`` (the console's keys, see
   :mod:`oceangnc.console.session`): ``console.mode`` ("auto" while a route is flown: AUTO, or a leg of
   GUIDED / RTL / SMART_RTL / LOITER; "remote" otherwise), ``console.loop`` ("open" in MANUAL, "closed"
   otherwise), ``joystick.surge`` / ``joystick.yaw`` (the stick in MANUAL / ACRO, zero otherwise),
   ``_estop`` (true while disarmed or e-stopped: the thruster blocks output zero), and the logged
   ``mavlink.*`` (battery included) / ``console.failsafe`` / ``console.estop``; when ``_estop`` rises the
   blocks are fired once at that instant (as the console does) so thrust is zero from the next step;
4. advance the simulation by whole clock ticks to ``t_sim(anchor) + speed (t_wall - t_wall(anchor))``
   (the console's pacing, re-anchored when it falls more than 0.5 s behind), in stretches that end where a
   telemetry message falls due in simulated time;
5. after each stretch, follow the mission (MISSION_CURRENT, MISSION_ITEM_REACHED, HOLD at the end) and the
   navigation modes' legs (:mod:`.nav`), draw the battery (:mod:`.battery`), and send the telemetry that is
   due (:data:`oceangnc.mavlink.protocol.TELEMETRY`, at the rates ground stations set, per simulated second
   when the simulation runs faster than real time and per wall second otherwise:
   :meth:`~oceangnc.mavlink.telemetry.TelemetryMixin._due`).

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
``<out_root>/mavlink-<scenario>-<time>/log.parquet`` with ``config.toml``, ``params.json`` (the parameters,
:mod:`.params`, rewritten on every change) and ``summary.json``.
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

from ..errors import DivergenceError, InputError, Terminated
from ..io.logs import LogWriter
from .battery import Battery, thruster_power
from .commands import INT16_MAX, CommandsMixin
from .config import MavlinkConfig
from .link import LinkMixin, _Sender, parse_endpoint
from .live import RouteHook, builds_live, live_scenarios, reads_stick
from .live import gate_pilots as _gate_pilots
from .live import warm_up as _warm_up
from .mission import MissionMixin
from .nav import NavMixin
from .params import ParamsMixin, build_params, read_param_file
from .protocol import AUTO, HOLD, MANUAL, RTL, SMART_RTL, STICK_MODES, TELEMETRY, mavlink, mode_name
from .sub import SubAutopilot, sub_mode_name
from .telemetry import TelemetryMixin
from .uuv import UUVMixin, build_uuv_params, rov_params

__all__ = [
    "INT16_MAX",
    "MavlinkVehicle",
    "RouteHook",
    "builds_live",
    "live_scenarios",
    "parse_endpoint",
    "reads_stick",
]

M = mavlink


def _vehicle_kind(name_or_path: str) -> str:
    """ "underwater" or "surface" of a scenario's vehicle file (:mod:`oceangnc.models.vehicle`)."""
    from ..models.vehicle import load_vehicle

    return load_vehicle(name_or_path).kind


def _ardusub_overrides(cfg, overrides: dict) -> dict:
    """Overrides that give a scenario's ArduSub systems their laws: the winch (and its depth reference) of a
    combined scenario's towed UUV, the ArduSub pilot (``control.pilot = "ardusub"``) of an underwater
    vehicle of a file; none where the operator set the key."""
    keys = {str(k) for k in overrides}
    out: dict = {}
    combined = getattr(cfg, "winch", None) is not None and hasattr(cfg, "formation")  # the towed-UUV family
    if combined and "winch.enabled" not in keys:
        out["winch.enabled"] = True
    ctl = getattr(cfg, "control", None)
    vname = getattr(cfg, "vehicle", None)
    if hasattr(ctl, "pilot") and isinstance(vname, str) and "control.pilot" not in keys:
        if _vehicle_kind(vname) == "underwater":
            out["control.pilot"] = "ardusub"
    return out


class MavlinkVehicle(LinkMixin, CommandsMixin, ParamsMixin, NavMixin, MissionMixin, TelemetryMixin, UUVMixin):
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
    params : dict, path or None
        Parameter values to start with (``{NAME: value}``, or a ``params.json`` / ``.param`` file; see
        :mod:`oceangnc.mavlink.params`); an unknown name or a refused value is an InputError.
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
        params: dict | str | Path | None = None,
    ):
        from ..api import new_run_dir, resolve_config
        from ..io.config import dump_toml, to_dict, validate

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
        start_params = params if isinstance(params, dict) or params is None else read_param_file(params)
        fixed = [parse_endpoint(g) for g in (gcs or [])]
        sc, cfg = resolve_config(scenario or "usv-remote", overrides=overrides)
        if not builds_live(sc):
            raise InputError(
                f"scenario {sc.name} has no live simulation; live scenarios: {', '.join(live_scenarios())}"
            )
        extra = _ardusub_overrides(cfg, overrides or {})
        if extra:  # the ArduSub systems' laws (oceangnc.control.ardusub) are part of the scenario's build
            sc, cfg = resolve_config(scenario or "usv-remote", overrides={**(overrides or {}), **extra})
        self.scenario, self.cfg = sc, cfg
        self.sim = sim = sc.build(cfg, np.random.default_rng(cfg.sim.seed))
        _gate_pilots(sim)
        self.route = RouteHook(sc, sim)
        self.reads_stick = reads_stick(sim)
        self.has_uuv = "uuv.x" in sim.bus
        # system 1's body on the bus: the 003 USV's "usv", or a vehicle file's "vehicle" (issue 30)
        self.body = "vehicle" if "usv.x" not in sim.bus and "vehicle.x" in sim.bus else "usv"
        vname = getattr(cfg, "vehicle", None)
        kind = _vehicle_kind(vname) if isinstance(vname, str) else "surface"
        self.mav_type = mavlink.MAV_TYPE_SUBMARINE if kind == "underwater" else mavlink.MAV_TYPE_SURFACE_BOAT
        # ArduSub systems (oceangnc.mavlink.sub): the towed UUV (system 2), a ROV of a vehicle file (system 1)
        c = self.cfg_mav
        self.sub2 = SubAutopilot(self, c.uuv_system_id, "uuv", None, horizontal=False) if self.has_uuv else None
        if self.sub2 is not None and not any(type(b).__name__ == "SubDepth" for b in sim.blocks):
            self.sub2.available = False  # no depth law in this scenario (e.g. the tow scenarios): seen, not flown
        rov = next((b for b in sim.blocks if type(b).__name__ == "SubROV"), None)
        self.sub1 = SubAutopilot(self, c.system_id, self.body, None, horizontal=True) if rov is not None else None
        # -- state
        self.armed = False
        self.estop = False
        self.failsafe = False  # the GCS failsafe (cleared by the controlling ground station's heartbeat)
        self.stick_failsafe = False  # the stick failsafe (cleared when the stick is back or the mode is set)
        self.mode = HOLD
        self.stick = (0.0, 0.0)
        self.t_gcs = -math.inf  # wall time of the last message from the controlling ground station
        self.gcs_sysid: int | None = None  # the ground station whose control act was last accepted
        self._src_sysid = 255  # system id of the message being handled
        self._acked: tuple[int, int] | None = None  # (command, result) of the last COMMAND_ACK sent
        self.t_stick = -math.inf  # wall time of the last stick message in a stick mode
        self.stick_flowing = False
        self.counts = {
            "rx_packets": 0,
            "rx_bad": 0,
            "rx_unknown": 0,
            "rx_out_of_range": 0,
            "rx_ignored": 0,
            "ftp_naks": 0,
            "tx_packets": 0,
            "tx_errors": 0,
        }
        self.events: list[tuple[float, str]] = []
        self.reached: list[int] = []  # mission seqs reported reached, in order
        self.ended = False
        self.error: str | None = None
        self.stopped_by: str | None = None  # "SIGINT" / "SIGTERM" when a signal ended serve()
        # -- mission: list of dicts (seq, frame, command, current, autocontinue, p1..p4, lat, lon, alt)
        self.mission: list[dict] = []
        self.mission_current = 1
        self._route_seqs: list[int] = []  # mission seq of each route point given to the guidance
        self._progress = 0
        self._upload: dict | None = None
        self._set_initial_mission()
        self._nav_init()
        c = self.cfg_mav
        self.battery = Battery(c.battery_capacity_ah, c.battery_cells, c.battery_r_int_ohm, c.battery_soc0)
        self._batt_t = 0.0
        self._batt_warned = 1.0
        self.params = build_params(self)
        if self.sub1 is not None:  # ArduSub's failsafes in place of Rover's (oceangnc.mavlink.sub)
            for name in ("FS_GCS_ENABLE", "FS_TIMEOUT", "RC_OVERRIDE_TIME", "FS_ACTION", "LOIT_RADIUS"):
                self.params.pop(name, None)
            self.params.update({p.name: p for p in rov_params(self, self.sub1, rov, vname)})
        self.uuv_params = build_uuv_params(self) if self.has_uuv else {}
        self.run_dir = None
        self.load_params(dict(start_params or {}))  # before the socket: a refused value leaves nothing open
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
        if self.sub2 is not None:
            self.sub2.mav = self.mav_uuv
        if self.sub1 is not None:
            self.sub1.mav = self.mav
        self._parser = M.MAVLink(None)
        self._parser.robust_parsing = True
        self._next_tx = {k: 0.0 for k in TELEMETRY}  # wall time each message is next due at, s
        self._next_sim = {k: -math.inf for k in TELEMETRY}  # simulated time each message is next due at, s
        self.rates = {k: float(v[0]) for k, v in TELEMETRY.items()}
        # -- log
        self.run_dir = None
        self.writer = None
        self.wall_start_unix_s = time.time()  # t = 0 on the wall clock (the MCAP export's log times)
        if out_root is not None:
            self.run_dir = new_run_dir(out_root, f"mavlink-{sc.name}")
            self.run_dir.mkdir(parents=True, exist_ok=True)
            # the endpoint's settings with the scenario's: the geographic origin of the log's GPS track
            dump_toml(cfg, self.run_dir / "config.toml", extra={"mavlink": to_dict(self.cfg_mav)})
            self.save_params()
            self.writer = LogWriter(self.run_dir / "log.parquet")
        if self._tlog_name is not None:
            tp = Path(self._tlog_name)
            if not tp.is_absolute() and self.run_dir is not None:
                tp = self.run_dir / tp
            self.tlog = open(tp, "wb")  # noqa: SIM115 (closed in close())
            self.tlog_path = tp
        self._lock = threading.RLock()
        #: called with the vehicle after every loop pass, under its lock (the live Foxglove stream:
        #: oceangnc.view.foxglove_ws.VehicleStates.hook); must be quick and must not raise
        self.state_hooks: list = []
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
            + f", listening on udp:{self.address[0]}:{self.address[1]}, disarmed, {self._mode_text()}"
        )

    def _mode_text(self) -> str:
        """The flight mode as the ground station sees it: Rover's, or ArduSub's for a ROV (and the towed UUV's)."""
        text = mode_name(self.mode) if self.sub1 is None else sub_mode_name(self.sub1.mode)
        return text + (f" (UUV {sub_mode_name(self.sub2.mode)})" if self.sub2 is not None else "")

    def _battery_step(self) -> None:
        """Draw the thrusters' and the hotel load's power from the battery since the last pass
        (:mod:`oceangnc.mavlink.battery`)."""
        dt = float(self.sim.t) - self._batt_t
        self._batt_t = float(self.sim.t)
        c = self.cfg_mav
        b = self.sim.bus
        usv = getattr(self.cfg, "usv", None)
        t_max = getattr(usv, "max_thrust_kgf", 0.0) * 9.80665
        thrusts = [b[k] for k in ("usv.thrust_port", "usv.thrust_stbd") if k in b]
        self.battery.step(thruster_power(thrusts, t_max, c.thruster_power_w) + c.hotel_power_w, dt)
        soc = self.battery.soc
        for level, text, sev in ((0.2, "Battery low", M.MAV_SEVERITY_WARNING),
                                 (0.0, "Battery empty", M.MAV_SEVERITY_CRITICAL)):  # fmt: skip
            if soc <= level < self._batt_warned:
                self._batt_warned = level
                self.event(f"{text}: {100 * soc:.0f} %, {self.battery.voltage:.1f} V", sev)

    def _set_battery_capacity(self, mah: float) -> None:
        self.cfg_mav.battery_capacity_ah = float(mah) / 1000.0
        self.battery.capacity_ah = self.cfg_mav.battery_capacity_ah

    def _set_speedup(self, speed: float) -> None:
        """SIM_SPEEDUP: simulated seconds per wall second from now on (the pacing is re-anchored)."""
        self.speed = float(speed)
        self._anchor = (self.clock(), self.sim.t)

    # -- events ------------------------------------------------------------------------------------------
    def event(self, text: str, severity: int = M.MAV_SEVERITY_INFO) -> None:
        self.events.append((float(self.sim.t), text))
        if self.verbose:
            print(f"[t={self.sim.t:8.2f}] {text}", flush=True)
        if hasattr(self, "mav"):
            self._send(self.mav.statustext_encode(severity, text[:50].encode()))

    # -- failsafe, bus, pacing ---------------------------------------------------------------------------
    def _watchdog(self, now: float) -> None:
        """ArduPilot Rover's failsafes (see :mod:`oceangnc.mavlink.nav` for the actions):

        * GCS (FS_GCS_ENABLE, on by default): the *controlling* ground station silent for ``gcs_timeout_s``
          (FS_GCS_TIMEOUT, 5 s) in a stick mode, or in any other mode but HOLD / RTL / SMART_RTL while armed
          once that ground station has been heard; FS_GCS_ENABLE = 2 lets a mission in AUTO continue;
        * stick (RC_OVERRIDE_TIME, 3 s, or FS_TIMEOUT if longer): a MANUAL_CONTROL / RC_CHANNELS_OVERRIDE stream
          that was flowing in a stick mode stops (ArduPilot: an override holds for RC_OVERRIDE_TIME; a ground
          station without a joystick never starts one, so MANUAL with 1 Hz
          heartbeats stays MANUAL);

        either runs FS_ACTION (HOLD by default; RTL, SMART_RTL) once, until the link is back."""
        c = self.cfg_mav
        silent = now - self.t_gcs > c.gcs_timeout_s
        watched = self.mode in STICK_MODES or (self.armed and math.isfinite(self.t_gcs))
        stick_s = max(c.stick_timeout_s, c.rc_override_time_s)  # an override holds for RC_OVERRIDE_TIME
        if not self.failsafe and c.fs_gcs_enable and silent and watched and self.mode not in (HOLD, RTL, SMART_RTL):
            why = "GCS link lost"
            self.failsafe = True
        elif (
            not self.stick_failsafe and self.mode in STICK_MODES and self.stick_flowing and now - self.t_stick > stick_s
        ):
            why = "stick stream lost"  # (not the GCS link: its heartbeats may still come, and clear nothing)
            self.stick_failsafe = True
        else:
            return
        self.stick = (0.0, 0.0)
        self.stick_flowing = False
        if why == "GCS link lost" and self.mode == AUTO and c.fs_gcs_enable == 2:
            self.event("Failsafe: GCS link lost, continuing AUTO", M.MAV_SEVERITY_CRITICAL)
            return
        self._failsafe_action(why)

    def _push_bus(self) -> None:
        # thrust zero while disarmed or e-stopped, and when holding (HOLD, a loiter inside its radius) if the
        # scenario cannot take a zero stick
        driving = self.mode in STICK_MODES or self.route_active() or self.sub1 is not None
        stop = (not self.armed) or self.estop or (not driving and not self.reads_stick)
        stick = self.stick if self.mode in STICK_MODES else (0.0, 0.0)
        vals = {
            "console.mode": "auto" if self.route_active() else "remote",
            "console.loop": "open" if self.mode == MANUAL else "closed",
            "joystick.surge": float(stick[0]),
            "joystick.yaw": float(stick[1]),
            "_estop": bool(stop),
            "console.failsafe": float(self.failsafe or self.stick_failsafe),
            "console.estop": float(self.estop),
            "mavlink.armed": float(self.armed),
            "mavlink.mode": float(self.mode if self.sub1 is None else self.sub1.mode),
            "mavlink.mission_current": float(self.mission_current),
            "mavlink.batt_v": float(self.battery.voltage),
            "mavlink.batt_a": float(self.battery.current),
            "mavlink.batt_soc": float(self.battery.soc),
        }
        vals.update({f"mavlink.{k}": float(v) for k, v in self.counts.items() if not k.startswith("tx_")})
        for sub in (self.sub1, self.sub2):
            if sub is not None:
                vals.update(sub.bus_values())
        self.sim.inject(vals)

    def step_once(self) -> None:
        """One loop pass (see the module docstring)."""
        with self._lock:
            now = self.clock()
            self._receive()
            self._upload_watchdog(now)
            self._watchdog(now)
            for sub in (self.sub1, self.sub2):
                if sub is not None:
                    sub._upload_watchdog(now)
                    sub.watchdog(now, gcs=sub is self.sub1)
            n = self._ticks_due(now)
            k = 0  # the first stretch is empty: what is due at the present instant goes out before time moves
            while True:
                self._advance(k)
                n -= k
                self._follow_mission()
                for sub in (self.sub1, self.sub2):
                    if sub is not None:
                        sub._follow_mission()
                self._nav_step()
                self._battery_step()
                try:
                    self._telemetry(now)
                except Exception as e:  # noqa: BLE001 a value outside a field's range must not stop the run
                    self.counts["tx_errors"] = self.counts.get("tx_errors", 0) + 1
                    if self.counts["tx_errors"] in (1, 100):
                        self.events.append((float(self.sim.t), f"telemetry error: {type(e).__name__}: {e}"))
                if n < 1 or self.ended:
                    break
                k = min(n, self._ticks_to_telemetry())
            for hook in self.state_hooks:
                hook(self)

    def _ticks_due(self, now: float) -> int:
        """Whole clock ticks the simulation is behind ``t_sim(anchor) + speed (now - t_wall(anchor))`` (the
        pacing is re-anchored when that exceeds ``max_lag``), cut at ``duration``; 0 once the run has ended."""
        if self.ended:
            return 0
        sim = self.sim
        w0, s0 = self._anchor
        lag = s0 + self.speed * (now - w0) - sim.t
        if lag > self.max_lag:
            self._anchor = (now, sim.t)
            lag = self.max_lag
        n = math.floor(lag / self.tick_s + 1e-9)
        if self.duration is not None:
            n = min(n, math.ceil((self.duration - sim.t) / self.tick_s - 1e-9))
        return max(0, n)

    def _advance(self, n: int) -> None:
        """Write the vehicle's state on the bus (firing the blocks once when ``_estop`` rises), run ``n``
        clock ticks, and end the run on a divergence, a failure, the scenario's ``_stop`` or ``duration``."""
        sim = self.sim
        was = bool(sim.bus.get("_estop", False))
        self._push_bus()
        if sim.bus["_estop"] and not was:
            for b in sim.blocks:  # thrust zero before the next integration step
                b.step(sim.t, sim.bus)
        if self.ended:
            return
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

    def _end(self, text: str) -> None:
        self.ended = True
        self.armed = False
        self.error = text if "diverged" in text or "failed" in text else None
        self.event(text, M.MAV_SEVERITY_WARNING)

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
        except KeyboardInterrupt as e:  # Ctrl-C, or SIGTERM under the command line (Terminated): summary says so
            self.stopped_by = "SIGTERM" if isinstance(e, Terminated) else "SIGINT"
            raise
        finally:
            self.close()

    def stop(self) -> None:
        self._stop.set()
        if self._thread is not None:
            self._thread.join(timeout=10)
            self._thread = None
        self.close()

    def _battery_summary(self) -> dict:
        b = self.battery
        t = float(self.sim.t)
        mean_w = b.energy_j / t if t > 0 else 0.0
        usable_j = self.cfg_mav.battery_soc0 * b.capacity_ah * 3600.0 * b.cells * 3.2  # at 3.2 V a cell
        return {
            "soc_end": b.soc,
            "voltage_end_v": b.voltage,
            "energy_wh": b.energy_j / 3600.0,
            "charge_ah": b.charge_ah,
            "mean_power_w": mean_w,
            "endurance_h_at_mean_power": usable_j / mean_w / 3600.0 if mean_w > 0 else None,
        }

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
            status = "interrupted" if self.stopped_by else ("error" if self.error else "ok")
            summary = {
                "scenario": self.scenario.name,
                "source": "mavlink",
                "status": status,
                **({"signal": self.stopped_by} if self.stopped_by else {}),
                "duration_s": float(self.sim.t),
                "wall_time_start_unix_s": self.wall_start_unix_s,
                "armed_at_end": self.armed,
                "mode_at_end": mode_name(self.mode) if self.sub1 is None else sub_mode_name(self.sub1.mode),
                "waypoints_reached": list(self.reached if self.sub1 is None else self.sub1.reached),
                "battery": self._battery_summary(),
                "params": self.param_values(),
                **{f"mavlink.{k}": v for k, v in self.counts.items()},
                "events": [f"{t:.2f} {s}" for t, s in self.events[-200:]],
            }
            if self.sub2 is not None:
                summary["uuv_mode_at_end"] = sub_mode_name(self.sub2.mode)
                summary["uuv_waypoints_reached"] = list(self.sub2.reached)
            if self.error:
                summary["error"] = self.error
            (self.run_dir / "summary.json").write_text(json.dumps(summary, indent=2))
            self.writer = None
