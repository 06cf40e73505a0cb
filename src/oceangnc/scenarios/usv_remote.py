"""``usv-remote``: the USV of 003 ch. 2.1 made ready for the operator console (003 ch. 5.4).

Composition (blocks fire in this order, 50 Hz for the pilot and the thrusters):

* environment (current, wind);
* GPS (:class:`oceangnc.sensors.gps.GPS`, ``sensor.gps``; white-noise error model, 10 Hz, 5 cm,
  configurable outage windows) publishing ``gps.x``, ``gps.y`` and ``gps.valid`` (0/1), so the
  console's sensor-failure lamp has something real to show;
* route pilot (:class:`oceangnc.guidance.route_pilot.RoutePilot`, ``usv.route_pilot``): the stick
  (``console.mode = "remote"``) or pure pursuit along the route (``"auto"``) -> ``usv.u_d``, ``usv.r_d``;
* inner loops (:class:`oceangnc.control.usv_control.USVRateController`, ``usv.rate_pid``): speed and
  yaw-rate PIDs with model feed-forwards, mixed by 003 eq. 3.11; ``console.loop = "open"`` puts the
  stick straight on the thrusters; ``_estop`` clears the integrators;
* thrusters (``usv.thrusters``) and the plant :class:`~oceangnc.models.usv.USVPlant`.

003 eq. 3.6 ties the look-ahead to the minimum turning radius, l = 2 R_min; this boat alone turns
in R_min = 0.36 m (one thruster full, the other off), so l would be 0.73 m, shorter than the boat,
and the 5 cm GPS noise would swing the target heading by several degrees. We take l = 6 m (two
boat lengths; about 8 s of travel at the cruise speed).

Run it offline with ``oceangnc run usv-remote`` (autonomous mode around the route), or live with
``oceangnc console usv-remote``.
"""

from __future__ import annotations

import math
from pathlib import Path
from typing import Literal

import numpy as np
from pydantic import Field

from ..control.actuators import USVThrusterBlock
from ..control.usv_control import RateControlConfig, USVRateController
from ..core.clock import Simulation
from ..environment import EnvironmentConfig
from ..guidance.route_pilot import RouteConfig, RoutePilot, StickConfig
from ..io.config import ScenarioConfig, StrictModel
from ..io.plots import plot_signals, plot_track
from ..models.usv import USVConfig, USVPlant
from ..sensors.gps import GPS, GPSConfig
from ..units import KGF
from ._common import environment_blocks
from .base import Scenario

#: config sections, by their historical names in this scenario
GuidanceConfig, RemoteConfig, ControlConfig = RouteConfig, StickConfig, RateControlConfig


class PilotConfig(StrictModel):
    """Initial console state of the pilot (the console changes it while running)."""

    mode: Literal["remote", "auto"] = Field("auto", description="initial mode: remote (stick) or auto (route)")
    loop: Literal["closed", "open"] = Field("closed", description="stick through the PID loops or to the thrusters")


class USVRemoteConfig(ScenarioConfig):
    usv: USVConfig = USVConfig()
    environment: EnvironmentConfig = EnvironmentConfig()
    pilot: PilotConfig = PilotConfig()
    remote: StickConfig = StickConfig()
    guidance: RouteConfig = RouteConfig()
    control: RateControlConfig = RateControlConfig()
    gps: GPSConfig = GPSConfig(error_model="white", rate=10.0, sigma=0.05)


def build_simulation(cfg: USVRemoteConfig, rng) -> Simulation:
    """Environment, GPS, route pilot, inner loops, thrusters and the USV plant."""
    h = 1.0 / cfg.control.rate
    blocks = [
        *environment_blocks(cfg.environment),
        GPS(cfg.gps, "usv"),
        RoutePilot(cfg.guidance, cfg.remote, h, mode=cfg.pilot.mode),
        USVRateController(cfg.control, cfg.usv, cfg.remote, mode=cfg.pilot.mode, loop=cfg.pilot.loop),
        USVThrusterBlock(cfg.usv, h),
    ]
    sim = Simulation(
        [USVPlant(cfg.usv)],
        blocks,
        cfg.sim.dt,
        1.0 / cfg.sim.log_rate,
        rng,
        external={
            "console.mode": "str",
            "console.loop": "str",
            "console.waypoints": "str",
            "joystick.surge": "1",
            "joystick.yaw": "1",
            "_estop": "bool",
        },
    )
    # initial console state, so that these columns are in the log from its first row
    sim.inject(
        {"console.mode": cfg.pilot.mode, "console.loop": cfg.pilot.loop, "joystick.surge": 0.0, "joystick.yaw": 0.0}
    )
    return sim


class USVRemote(Scenario):
    """See the module docstring."""

    frame = "columns"  # summary and plots read columns only (oceangnc.io.frame)

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
            "bodies": [
                {"name": "usv", "label": "USV", "length": cfg.usv.length_oa, "beam": cfg.usv.beam, "shape": "boat"}
            ],
            "route": [list(w) for w in cfg.guidance.waypoints],
            "gauges": [
                {
                    "key": "usv.thrust_port",
                    "label": "port thruster",
                    "unit": "kgf",
                    "scale": 1 / KGF,
                    "min": -cfg.usv.max_reverse_kgf,
                    "max": t_max / KGF,
                },
                {
                    "key": "usv.thrust_stbd",
                    "label": "stbd thruster",
                    "unit": "kgf",
                    "scale": 1 / KGF,
                    "min": -cfg.usv.max_reverse_kgf,
                    "max": t_max / KGF,
                },
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
            if len(moving)
            else 0.0,
        }

    def plot(self, df, cfg, out_dir: Path) -> list[Path]:
        out_dir = Path(out_dir)
        return [
            plot_track(
                df, ["usv"], out_dir / "trajectory.png", title=self.name, waypoints=np.array(cfg.guidance.waypoints)
            ),
            plot_signals(
                df,
                [
                    ("speed [m/s]", [("usv.u", "u", 1.0), ("usv.u_d", "u_d", 1.0)]),
                    ("yaw rate [deg/s]", [("usv.r", "r", 180 / math.pi), ("usv.r_d", "r_d", 180 / math.pi)]),
                    ("thrust [kgf]", [("usv.thrust_port", "port", 1 / KGF), ("usv.thrust_stbd", "starboard", 1 / KGF)]),
                ],
                out_dir / "control.png",
                title=f"{self.name}: control",
            ),
        ]


SCENARIOS = [USVRemote()]
