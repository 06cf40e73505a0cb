"""``usv-remote``: the USV of 003 ch. 2.1 made ready for the operator console (003 ch. 5.4).

The vehicle is :class:`~oceangnc.models.usv.USVPlant` with :class:`~oceangnc.models.usv.USVThrusters`.
One pilot block (:class:`USVPilot`, 50 Hz) reads the console's bus keys (the shared remote-control
protocol):

* ``console.mode``: ``"remote"`` or ``"auto"``;
* ``console.loop``: ``"closed"`` (stick -> speed / yaw-rate setpoints -> PID) or ``"open"`` (stick ->
  thrusters directly);
* ``joystick.surge``, ``joystick.yaw``: stick deflections in [-1, 1] (surge ahead positive, yaw to
  starboard positive);
* ``console.waypoints``: a tuple of (north, east) points (m) that replaces the route;
* ``_estop``: emergency stop (the thrusters zero their output; the pilot also clears its integrators
  so that nothing has wound up when the stop is reset).

Remote, closed loop: ``u_d = surge * u_max`` (``surge * u_rev`` astern) and ``r_d = yaw * r_max``.
Autonomous: pure pursuit along the legs of the route (003 ch. 3.1, table 3-1, with the geometry of
:mod:`oceangnc.guidance.pure_pursuit`): the target heading points at the look-ahead point G on the
current leg at distance ``l`` from the vehicle (turning radius R = l^2 / (2 d), 003 eq. 3.5). The
next waypoint is taken within the acceptance radius or past the end of the leg; the first leg starts
where the vehicle is when the route is set (a route clicked on the console's map starts there). A
proportional heading law gives ``r_d = sat(k_psi wrap(psi_d - psi), r_max)`` and the speed setpoint
is the cruise speed times max(0, cos(heading error)), so the boat turns before it speeds off.

003 eq. 3.6 ties the look-ahead to the minimum turning radius, l = 2 R_min; this boat alone turns
in R_min = 0.36 m (one thruster full, the other off), so l would be 0.73 m, shorter than the boat,
and the 5 cm GPS noise would swing the target heading by several degrees. We take l = 6 m (two
boat lengths; about 8 s of travel at the cruise speed).

Inner loops (both modes): anti-windup PIDs (003 eq. 3.10) on the surge speed and the yaw rate, with
the steady-state feedforwards of the linear model (003 eq. 2.3): ``U_speed = d11 u_d / 2 + PID``
(N per thruster) and ``U_heading = d33 r_d / B + PID`` (N), mixed by 003 eq. 3.11

    U_port = U_speed + U_heading,   U_stbd = U_speed - U_heading.

A yaw to starboard needs port thrust above starboard thrust, N = (T_p - T_s) B / 2 (003 eq. 2.4).

A GPS block (10 Hz, Gaussian noise, configurable outage windows) publishes ``gps.x``, ``gps.y`` and
``gps.valid`` (0/1); the guidance steers on the GPS fix and holds the last fix through an outage,
so the console's sensor-failure lamp has something real to show.

Run it offline with ``oceangnc run usv-remote`` (autonomous mode around the route), or live with
``oceangnc console usv-remote``.
"""

from __future__ import annotations

import math
from pathlib import Path
from typing import Literal

import numpy as np
from pydantic import Field

from ..control.pid import PID
from ..control.actuators import USVThrusterBlock
from ..core.rotations import wrap
from ..core.blocks import Block
from ..core.clock import Simulation
from ..guidance.pure_pursuit import closest_point, look_ahead_point, pursuit_command
from ..environment import EnvironmentConfig
from ..io.config import ScenarioConfig, StrictModel
from ..io.plots import plot_signals, plot_track
from ..models.usv import USVConfig, USVPlant
from ..units import KGF
from ._common import environment_blocks
from .base import Scenario


class PilotConfig(StrictModel):
    """Initial console state of the pilot (the console changes it while running)."""

    mode: Literal["remote", "auto"] = Field("auto", description="initial mode: remote (stick) or auto (route)")
    loop: Literal["closed", "open"] = Field("closed", description="stick through the PID loops or to the thrusters")


class RemoteConfig(StrictModel):
    """Stick scaling (003 ch. 5.4 remote mode; 001 eq. 26 data flow: stick axes -> speed, yaw rate)."""

    max_speed: float = Field(0.9, gt=0, le=5, description="surge speed at full stick ahead, m/s")
    max_reverse_speed: float = Field(0.3, ge=0, le=5, description="surge speed at full stick astern, m/s")
    max_yaw_rate_degps: float = Field(20.0, gt=0, le=90, description="yaw rate at full stick, deg/s")
    open_loop_thrust_kgf: float = Field(36.2, gt=0, le=100, description="open loop: per-thruster thrust at full surge stick, kgf")
    open_loop_reverse_kgf: float = Field(13.83, ge=0, le=100, description="open loop: per-thruster astern thrust at full stick, kgf")
    open_loop_diff_kgf: float = Field(15.0, ge=0, le=100, description="open loop: differential thrust U_heading at full yaw stick, kgf")


class GuidanceConfig(StrictModel):
    """Route and pure-pursuit guidance of the autonomous mode."""

    waypoints: list[tuple[float, float]] = Field(
        [(50.0, 0.0), (50.0, 50.0), (0.0, 50.0), (0.0, 0.0)], min_length=1, max_length=200,
        description="route, list of (north, east) points, m")
    speed: float = Field(0.7, gt=0, le=5, description="cruise speed, m/s")
    lookahead: float = Field(6.0, gt=0, le=1000, description="pure-pursuit look-ahead distance l (003 eq. 3.5), m")
    accept_radius: float = Field(3.0, gt=0, le=1000, description="waypoint acceptance radius, m")
    heading_gain: float = Field(0.8, gt=0, le=20, description="heading error -> yaw-rate setpoint gain k_psi, 1/s")


class ControlConfig(StrictModel):
    """Inner-loop PID gains (003 eq. 3.10); adjustable from the console while running."""

    rate: float = Field(50.0, gt=0, le=1000, description="pilot (guidance + control) rate, Hz")
    speed_kp: float = Field(300.0, ge=0, le=1e5, description="surge-speed PID proportional gain, N/(m/s)")
    speed_ki: float = Field(150.0, ge=0, le=1e5, description="surge-speed PID integral gain, N/m")
    yaw_kp: float = Field(300.0, ge=0, le=1e5, description="yaw-rate PID proportional gain, N/(rad/s)")
    yaw_ki: float = Field(200.0, ge=0, le=1e5, description="yaw-rate PID integral gain, N/rad")


class GPSConfig(StrictModel):
    """GPS position fix (003 ch. 6.1: cm-level when still)."""

    rate: float = Field(10.0, gt=0, le=100, description="fix rate, Hz")
    sigma: float = Field(0.05, ge=0, le=50, description="position noise standard deviation, m")
    outages: list[tuple[float, float]] = Field([], max_length=100,
                                               description="(start, end) windows without a fix, s")


class USVRemoteConfig(ScenarioConfig):
    usv: USVConfig = USVConfig()
    environment: EnvironmentConfig = EnvironmentConfig()
    pilot: PilotConfig = PilotConfig()
    remote: RemoteConfig = RemoteConfig()
    guidance: GuidanceConfig = GuidanceConfig()
    control: ControlConfig = ControlConfig()
    gps: GPSConfig = GPSConfig()


class GPSSensor(Block):
    """GPS fix: ``gps.x``, ``gps.y`` (m, NED) = true position + N(0, sigma^2); ``gps.valid`` 0 in outages."""

    name = "gps"

    def __init__(self, cfg: GPSConfig, body: str = "usv"):
        self.cfg = cfg
        self.period = 1.0 / cfg.rate
        self.body = body
        self.inputs = {f"{body}.x": "m", f"{body}.y": "m"}
        self.outputs = {"gps.x": "m", "gps.y": "m", "gps.valid": "bool"}

    def reset(self, rng: np.random.Generator) -> None:
        self.rng = rng

    def step(self, t: float, bus: dict) -> None:
        out = any(a <= t < b for a, b in self.cfg.outages)
        bus["gps.valid"] = 0.0 if out else 1.0
        if not out:
            n = self.rng.normal(0.0, self.cfg.sigma, 2) if self.cfg.sigma > 0 else (0.0, 0.0)
            bus["gps.x"] = bus[f"{self.body}.x"] + float(n[0])
            bus["gps.y"] = bus[f"{self.body}.y"] + float(n[1])
        else:  # hold the last fix
            bus.setdefault("gps.x", bus[f"{self.body}.x"])
            bus.setdefault("gps.y", bus[f"{self.body}.y"])


class USVPilot(Block):
    """Remote (stick) or autonomous (pure-pursuit) guidance, speed / yaw-rate PIDs and 003 eq. 3.11 mixing.

    Writes ``usv.thrust_port_cmd`` / ``usv.thrust_stbd_cmd`` (N), the setpoints ``usv.u_d`` (m/s)
    and ``usv.r_d`` (rad/s), and ``guidance.psi_d`` (rad), ``guidance.cross_track`` (m),
    ``guidance.wp_index`` (index of the waypoint steered to; equal to the number of waypoints when
    the route is complete). See the module docstring for the laws.
    """

    name = "usv_pilot"

    def __init__(self, cfg: USVRemoteConfig):
        self.cfg = cfg
        self.period = 1.0 / cfg.control.rate
        c = cfg.control
        hi = cfg.usv.max_thrust_kgf * KGF
        lo = cfg.usv.max_reverse_kgf * KGF
        self.speed_pid = PID(c.speed_kp, c.speed_ki, 0.0, -lo, hi)
        self.yaw_pid = PID(c.yaw_kp, c.yaw_ki, 0.0, -hi, hi)
        self.heading_gain = cfg.guidance.heading_gain
        self.cruise_speed = cfg.guidance.speed
        self.lookahead = cfg.guidance.lookahead
        self.inputs = {"usv.u": "m/s", "usv.r": "rad/s", "usv.psi": "rad", "usv.x": "m", "usv.y": "m"}
        self.optional_inputs = {"console.mode": "str", "console.loop": "str", "console.waypoints": "str",
                                "joystick.surge": "1", "joystick.yaw": "1", "gps.x": "m", "gps.y": "m", "_estop": "bool"}
        self.outputs = {"usv.thrust_port_cmd": "N", "usv.thrust_stbd_cmd": "N", "usv.u_d": "m/s", "usv.r_d": "rad/s",
                        "guidance.psi_d": "rad", "guidance.cross_track": "m", "guidance.wp_index": "count"}

    # -- console protocol: adjustable gains ---------------------------------------------------------
    def gain_specs(self) -> list[dict]:
        """The gains an operator may change while running: name, value, range, unit, description."""
        return [
            {"name": "speed_kp", "value": self.speed_pid.kp, "min": 0.0, "max": 5000.0, "unit": "N/(m/s)",
             "description": "surge-speed PID proportional gain"},
            {"name": "speed_ki", "value": self.speed_pid.ki, "min": 0.0, "max": 5000.0, "unit": "N/m",
             "description": "surge-speed PID integral gain"},
            {"name": "yaw_kp", "value": self.yaw_pid.kp, "min": 0.0, "max": 5000.0, "unit": "N/(rad/s)",
             "description": "yaw-rate PID proportional gain"},
            {"name": "yaw_ki", "value": self.yaw_pid.ki, "min": 0.0, "max": 5000.0, "unit": "N/rad",
             "description": "yaw-rate PID integral gain"},
            {"name": "heading_gain", "value": self.heading_gain, "min": 0.01, "max": 10.0, "unit": "1/s",
             "description": "autonomous heading error -> yaw-rate setpoint gain"},
            {"name": "cruise_speed", "value": self.cruise_speed, "min": 0.05, "max": 1.2, "unit": "m/s",
             "description": "autonomous cruise speed"},
            {"name": "lookahead", "value": self.lookahead, "min": 0.5, "max": 100.0, "unit": "m",
             "description": "pure-pursuit look-ahead distance"},
        ]

    def set_gain(self, name: str, value: float) -> None:
        """Set one gain listed by :meth:`gain_specs` (the console validates the range first)."""
        target = {"speed_kp": (self.speed_pid, "kp"), "speed_ki": (self.speed_pid, "ki"),
                  "yaw_kp": (self.yaw_pid, "kp"), "yaw_ki": (self.yaw_pid, "ki"),
                  "heading_gain": (self, "heading_gain"), "cruise_speed": (self, "cruise_speed"),
                  "lookahead": (self, "lookahead")}
        if name not in target:
            raise KeyError(name)
        obj, attr = target[name]
        setattr(obj, attr, float(value))

    # -- block ---------------------------------------------------------------------------------------
    def reset(self, rng: np.random.Generator) -> None:
        self.speed_pid.reset()
        self.yaw_pid.reset()
        self.route = tuple((float(n), float(e)) for n, e in self.cfg.guidance.waypoints)
        self.wp = 0
        self.leg_start: tuple[float, float] | None = None
        self.route_done = False

    def _los(self, x: float, y: float, psi: float) -> tuple[float, float, float]:
        """Pure pursuit on the current leg (003 table 3-1, :mod:`oceangnc.guidance.pure_pursuit`).

        Returns (psi_d rad, cross-track error m, distance to the waypoint m); psi_d is NaN once the
        route is complete. The first leg starts where the vehicle is when the route is (re)set.
        """
        g = self.cfg.guidance
        p = (x, y)
        while True:
            if self.leg_start is None:
                self.leg_start = p
            b = self.route[self.wp]
            a = self.leg_start
            leg = math.hypot(b[0] - a[0], b[1] - a[1])
            dist = math.hypot(b[0] - x, b[1] - y)
            along = 0.0
            if leg > 1e-9:
                _, along, _ = closest_point(p, a, b)
            if dist < g.accept_radius or leg <= 1e-9 or along > leg:
                self.leg_start = b
                self.wp += 1
                if self.wp >= len(self.route):
                    self.route_done = True
                    return math.nan, 0.0, 0.0
                continue
            last = self.wp == len(self.route) - 1
            target, _, e = look_ahead_point(p, a, b, self.lookahead, clamp_end=last)
            psi_d = pursuit_command(p, psi, target)[0]
            return psi_d, e, dist

    def step(self, t: float, bus: dict) -> None:
        cfg = self.cfg
        h = self.period
        u = bus["usv.u"]
        r = bus["usv.r"]
        psi = bus["usv.psi"]
        mode = bus.get("console.mode", cfg.pilot.mode)
        loop = bus.get("console.loop", cfg.pilot.loop)
        wps = bus.get("console.waypoints")
        if wps is not None and tuple(wps) != self.route and len(wps) > 0:
            self.route = tuple((float(a), float(b)) for a, b in wps)
            self.wp = 0
            self.leg_start = None
            self.route_done = False
        surge = max(-1.0, min(1.0, float(bus.get("joystick.surge", 0.0))))
        yaw = max(-1.0, min(1.0, float(bus.get("joystick.yaw", 0.0))))
        rm = cfg.remote
        r_max = math.radians(rm.max_yaw_rate_degps)
        psi_d = math.nan
        xte = 0.0
        if mode == "remote":
            u_d = surge * (rm.max_speed if surge >= 0 else rm.max_reverse_speed)
            r_d = yaw * r_max
        else:
            if self.route_done:
                u_d, r_d = 0.0, 0.0
            else:
                psi_d, xte, _ = self._los(bus.get("gps.x", bus["usv.x"]), bus.get("gps.y", bus["usv.y"]), psi)
                if self.route_done:
                    u_d, r_d = 0.0, 0.0
                else:
                    err = wrap(psi_d - psi)
                    r_d = max(-r_max, min(r_max, self.heading_gain * err))
                    u_d = self.cruise_speed * max(0.0, math.cos(err))
        p = cfg.usv
        if bus.get("_estop", False):
            self.speed_pid.reset()
            self.yaw_pid.reset()
            u_speed = u_head = 0.0
        elif mode == "remote" and loop == "open":
            u_speed = surge * (rm.open_loop_thrust_kgf if surge >= 0 else rm.open_loop_reverse_kgf) * KGF
            u_head = yaw * rm.open_loop_diff_kgf * KGF
            self.speed_pid.reset()
            self.yaw_pid.reset()
        else:
            u_speed = self.speed_pid.step(u_d - u, h, feedforward=0.5 * p.d11 * u_d)
            u_head = self.yaw_pid.step(r_d - r, h, feedforward=p.d33 * r_d / p.thruster_spacing)
        bus["usv.thrust_port_cmd"] = u_speed + u_head  # 003 eq. 3.11
        bus["usv.thrust_stbd_cmd"] = u_speed - u_head
        bus["usv.u_d"] = u_d
        bus["usv.r_d"] = r_d
        bus["guidance.psi_d"] = psi_d if math.isfinite(psi_d) else psi
        bus["guidance.cross_track"] = xte
        bus["guidance.wp_index"] = float(self.wp)


def build_simulation(cfg: USVRemoteConfig, rng) -> Simulation:
    """Environment, GPS, pilot, thrusters and the USV plant."""
    blocks = [*environment_blocks(cfg.environment), GPSSensor(cfg.gps), USVPilot(cfg),
              USVThrusterBlock(cfg.usv, 1.0 / cfg.control.rate)]
    sim = Simulation([USVPlant(cfg.usv)], blocks, cfg.sim.dt, 1.0 / cfg.sim.log_rate, rng)
    # initial console state, so that these columns are in the log from its first row
    sim.inject({"console.mode": cfg.pilot.mode, "console.loop": cfg.pilot.loop,
                "joystick.surge": 0.0, "joystick.yaw": 0.0})
    return sim


class USVRemote(Scenario):
    """See the module docstring."""

    name = "usv-remote"
    summary = "USV for the operator console: stick (speed / yaw-rate PIDs) or pure-pursuit waypoint autopilot"
    Config = USVRemoteConfig
    defaults = {"sim": {"duration": 400.0, "dt": 0.002}}
    #: the console's failsafe cannot station-keep this underactuated boat: it zeroes the thrust
    failsafe_station_keep = False
    #: the pilot reads ``console.loop``: the page may switch the stick between closed and open loop
    console_loop_switch = True
    #: the pilot reads ``console.waypoints``: routes clicked on the console's map are flown
    console_route_edit = True

    def build(self, cfg, rng):
        return build_simulation(cfg, rng)

    def console_view(self, cfg) -> dict:
        """What the operator console draws: bodies, route, gauges and read-outs (see oceangnc.console)."""
        t_max = cfg.usv.max_thrust_kgf * KGF
        return {
            "bodies": [{"name": "usv", "label": "USV", "length": cfg.usv.length_oa, "beam": cfg.usv.beam,
                        "shape": "boat"}],
            "route": [list(w) for w in cfg.guidance.waypoints],
            "gauges": [
                {"key": "usv.thrust_port", "label": "port thruster", "unit": "kgf", "scale": 1 / KGF,
                 "min": -cfg.usv.max_reverse_kgf, "max": t_max / KGF},
                {"key": "usv.thrust_stbd", "label": "stbd thruster", "unit": "kgf", "scale": 1 / KGF,
                 "min": -cfg.usv.max_reverse_kgf, "max": t_max / KGF},
            ],
            "readouts": [
                {"key": "usv.speed", "label": "speed", "unit": "m/s", "scale": 1.0},
                {"key": "usv.psi", "label": "heading", "unit": "deg", "scale": 180 / math.pi, "wrap360": True},
                {"key": "usv.u_d", "label": "speed setpoint", "unit": "m/s", "scale": 1.0},
                {"key": "usv.r", "label": "yaw rate", "unit": "deg/s", "scale": 180 / math.pi},
                {"key": "guidance.cross_track", "label": "cross-track", "unit": "m", "scale": 1.0},
            ],
            "sensors": [{"key": "gps.valid", "label": "GPS"}],
        }

    def summarize(self, df, cfg) -> dict:
        n_wp = len(cfg.guidance.waypoints)
        reached = float(df["guidance.wp_index"].max()) if "guidance.wp_index" in df else 0.0
        moving = df[df["usv.u_d"] > 0.05] if "usv.u_d" in df else df
        return {
            "usv.mean_speed_mps": float(df["usv.speed"].mean()),
            "guidance.waypoints_reached": min(reached, n_wp),
            "guidance.cross_track_rms_m": float(np.sqrt(np.mean(moving["guidance.cross_track"] ** 2)))
            if len(moving) else 0.0,
        }

    def plot(self, df, cfg, out_dir: Path) -> list[Path]:
        out_dir = Path(out_dir)
        return [
            plot_track(df, ["usv"], out_dir / "trajectory.png", title=self.name,
                       waypoints=np.array(cfg.guidance.waypoints)),
            plot_signals(df, [
                ("speed [m/s]", [("usv.u", "u", 1.0), ("usv.u_d", "u_d", 1.0)]),
                ("yaw rate [deg/s]", [("usv.r", "r", 180 / math.pi), ("usv.r_d", "r_d", 180 / math.pi)]),
                ("thrust [kgf]", [("usv.thrust_port", "port", 1 / KGF), ("usv.thrust_stbd", "starboard", 1 / KGF)]),
            ], out_dir / "control.png", title=f"{self.name}: control"),
        ]


SCENARIOS = [USVRemote()]
