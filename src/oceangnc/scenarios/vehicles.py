"""Scenarios of a vehicle defined by a file (issue 30; :mod:`oceangnc.models.vehicle`, docs/vehicles.md).

* ``rov-station-keeping``: a ROV (default ``bluerov2-heavy``) starts at the surface and holds a
  position and depth in a current: 6-DOF PID (``vehicle.pid``) -> thrust allocation
  (``vehicle.allocation``) -> the generic plant. Summary: ``vehicle.position_error_rms_m`` and
  ``vehicle.depth_error_rms_m`` after ``analysis.settle_s``, ``vehicle.heading_error_rms_deg``,
  ``vehicle.thrust_max_N``, ``vehicle.thrust_saturated_fraction``.
* ``otter-waypoints``: a surface craft (default ``otter``) on an LOS route (``usv.los``) with a speed
  and heading PID. Summary: ``guidance.cross_track_rms_m`` (after the first leg is joined),
  ``guidance.cross_track_max_m``, ``vehicle.speed_mean_mps``, ``guidance.final_leg``.

``vehicle`` is a shipped name or a path to your own file (``--set vehicle=path/to/my.toml``); the
controller's gains are per DOF (``control.gains.<dof> = [k_p, k_i, k_d]``). A file of the other ``kind``
is refused naming ``vehicle`` (an underwater ROV on the surface route, a surface boat asked to hold a depth).
The plant is :class:`~oceangnc.models.vehicle_plant.VehiclePlant`: the logged ``vehicle.thrust_<name>`` of a
thruster without ``time_constant`` is the thrust it applies (its saturated command).
"""

from __future__ import annotations

import math
from pathlib import Path
from typing import Literal

import numpy as np
from pydantic import Field

from ..control.ardusub import SubROV, axis_limits
from ..control.thrust_allocation import VehiclePID, allocation_block, allocation_matrix
from ..core.clock import Simulation
from ..environment import EnvironmentConfig
from ..errors import ConfigError
from ..guidance.los import WaypointGuidance
from ..io.config import ScenarioConfig, StrictModel
from ..io.plots import plot_signals, plot_track
from ..models._shaft import thrusts_from_states
from ..models.vehicle import DOF_NAMES, load_vehicle, thruster_state, vehicle_model
from ..models.vehicle_plant import VehiclePlant
from ._common import environment_blocks
from .base import Scenario

Gains = tuple[float, float, float]


class VehicleControl(StrictModel):
    rate: float = Field(20.0, gt=0, le=1000, description="controller and allocation rate, Hz")
    gains: dict[str, Gains] = Field(description="per DOF (surge, sway, heave, roll, pitch, yaw): [k_p, k_i, k_d]")
    i_max: float = Field(50.0, gt=0, le=1e6, description="integral clamp per DOF, m s or rad s")
    pilot: Literal["pid", "ardusub"] = Field(
        "pid",
        description="controller: 'pid' holds the set point (vehicle.pid); 'ardusub' flies ArduSub's modes "
        "from a ground station (oceangnc.control.ardusub; set by 'oceangnc mavlink' for an underwater vehicle)",
    )


class Setpoint(StrictModel):
    x: float = Field(0.0, ge=-1e5, le=1e5, description="north, m")
    y: float = Field(0.0, ge=-1e5, le=1e5, description="east, m")
    z: float = Field(5.0, ge=-10, le=1e4, description="depth, m")
    psi_deg: float = Field(0.0, ge=-360, le=360, description="heading, deg")


class Start(StrictModel):
    x: float = Field(0.0, ge=-1e5, le=1e5, description="north, m")
    y: float = Field(0.0, ge=-1e5, le=1e5, description="east, m")
    z: float = Field(0.0, ge=-10, le=1e4, description="depth (surface craft: heave from equilibrium), m")
    psi_deg: float = Field(0.0, ge=-360, le=360, description="heading, deg")
    u: float = Field(0.0, ge=-20, le=20, description="surge speed, m/s")


class Route(StrictModel):
    waypoints: list[tuple[float, float]] = Field(min_length=2, description="(north, east), m")
    speed: float = Field(1.5, gt=0, le=20, description="speed command, m/s")
    R: float = Field(6.0, gt=0, le=1e4, description="LOS circle radius, m")
    accept_radius: float = Field(4.0, gt=0, le=1e4, description="waypoint acceptance radius, m")


class Analysis(StrictModel):
    settle_s: float = Field(30.0, ge=0, le=1e5, description="time after which errors are scored, s")


class VehicleScenarioConfig(ScenarioConfig):
    vehicle: str = Field("bluerov2-heavy", min_length=1, description="shipped vehicle name or path to a vehicle file")
    environment: EnvironmentConfig = EnvironmentConfig()
    start: Start = Start()
    setpoint: Setpoint = Setpoint()
    route: Route | None = None
    control: VehicleControl
    analysis: Analysis = Analysis()


def _plant(cfg: VehicleScenarioConfig, vf):
    m = vehicle_model(vf)
    x0 = np.zeros(m.nx)
    s = cfg.start
    x0[[0, 1, 2, 5, 6]] = [s.x, s.y, s.z, math.radians(s.psi_deg), s.u]
    names = [f"vehicle.thrust_{t.name}_cmd" for t in vf.thrusters] + [f"vehicle.fin_{f.name}_cmd" for f in vf.fins]
    names += ["env.current_n", "env.current_e"]
    return VehiclePlant(m, "vehicle", x0, names)  # publishes the thrust of lag-free thrusters too


class VehicleScenario(Scenario):
    Config = VehicleScenarioConfig

    def __init__(self, name: str, summary: str, defaults: dict, route: bool, kind: str):
        self.name, self.summary, self.defaults, self.route = name, summary, defaults, route
        self.kind = kind  #: the vehicle file's ``kind`` the scenario flies (a surface route, an ROV at depth)

    def build(self, cfg, rng):
        vf = load_vehicle(cfg.vehicle)
        if vf.kind != self.kind:  # an ROV on a surface route, or a boat asked to hold a depth
            raise ConfigError(
                f"vehicle: '{vf.name}' is a vehicle of kind = '{vf.kind}'; {self.name} flies kind = '{self.kind}' "
                f"(choose a {self.kind} vehicle file)"
            )
        default = self.defaults["control"]["gains"]
        gains = {}
        for dof, g in cfg.control.gains.items():
            if dof not in DOF_NAMES:
                raise ConfigError(f"control.gains.{dof}: not a DOF; allowed: {', '.join(DOF_NAMES)}")
            if dof not in vf.control.dofs and tuple(g) == tuple(default.get(dof, ())):
                continue  # the scenario's default for its own vehicle: another vehicle may not control it
            gains[dof] = g
            if dof not in vf.control.dofs:
                raise ConfigError(
                    f"control.gains.{dof}: vehicle '{vf.name}' does not control {dof} "
                    f"(its control.dofs: {', '.join(vf.control.dofs)})"
                )
        h = 1.0 / cfg.control.rate
        sp = cfg.setpoint
        setpoint = {"x": sp.x, "y": sp.y, "z": sp.z, "psi": math.radians(sp.psi_deg)}
        blocks = list(environment_blocks(cfg.environment))
        if self.route:
            if cfg.route is None:
                raise ConfigError(f"route: {self.name} needs route.waypoints")
            r = cfg.route
            blocks.append(
                WaypointGuidance(
                    r.waypoints, mode="los", R=r.R, accept_radius=r.accept_radius, speed=r.speed, period=h,
                    body="vehicle", stop_at_end=True,
                )
            )  # fmt: skip
        if cfg.control.pilot == "ardusub":
            if self.route or vf.kind != "underwater":
                raise ConfigError(f"control.pilot = 'ardusub': an underwater vehicle holding station, not {self.name}")
            tau_max = axis_limits(
                allocation_matrix(vf), [t.max_forward for t in vf.thrusters], [t.max_reverse for t in vf.thrusters]
            )
            blocks.append(SubROV(gains, tau_max, setpoint, h, "vehicle"))
        else:
            blocks.append(VehiclePID(gains, setpoint, h, "vehicle", self.route, cfg.control.i_max))
        blocks.append(allocation_block(vf, h, "vehicle"))
        return Simulation([_plant(cfg, vf)], blocks, cfg.sim.dt, 1.0 / cfg.sim.log_rate, rng)

    def summarize(self, df, cfg) -> dict:
        vf = load_vehicle(cfg.vehicle)
        states = np.column_stack([df[f"vehicle.{thruster_state(t)[0]}"].to_numpy() for t in vf.thrusters])
        thr = thrusts_from_states(vf, states)
        lim = np.array([t.max_forward for t in vf.thrusters])
        limr = np.array([t.max_reverse for t in vf.thrusters])
        sat = (thr >= lim * 0.999) | (thr <= -limr * 0.999)
        out = {"vehicle": vf.name, "vehicle.thrust_max_N": float(np.abs(thr).max())}
        out["vehicle.thrust_saturated_fraction"] = float(sat.any(axis=1).mean())
        settle = cfg.analysis.settle_s if df["t"].iloc[-1] > cfg.analysis.settle_s else 0.5 * df["t"].iloc[-1]
        out["vehicle.scored_from_s"] = float(settle)  # a run shorter than settle_s: its second half
        w = df[df["t"] >= settle]
        if self.route:
            e = w["guidance.e"].to_numpy()
            out["guidance.cross_track_rms_m"] = float(np.sqrt(np.mean(e**2))) if e.size else float("nan")
            out["guidance.cross_track_max_m"] = float(np.abs(e).max()) if e.size else float("nan")
            out["vehicle.speed_mean_mps"] = float(np.hypot(w["vehicle.u"], w["vehicle.v"]).mean())
            out["guidance.final_leg"] = int(df["guidance.leg"].iloc[-1])
        else:
            sp = cfg.setpoint
            d = np.hypot(w["vehicle.x"] - sp.x, w["vehicle.y"] - sp.y)
            out["vehicle.position_error_rms_m"] = float(np.sqrt(np.mean(d**2)))
            out["vehicle.depth_error_rms_m"] = float(np.sqrt(np.mean((w["vehicle.z"] - sp.z) ** 2)))
            e = (w["vehicle.psi"] - math.radians(sp.psi_deg) + np.pi) % (2 * np.pi) - np.pi
            out["vehicle.heading_error_rms_deg"] = float(np.degrees(np.sqrt(np.mean(e**2))))
        return out

    def plot(self, df, cfg, out_dir: Path) -> list[Path]:
        out_dir = Path(out_dir)
        deg = 180 / math.pi
        return [
            plot_track(df, ["vehicle"], out_dir / "track.png", title=f"{self.name} ({cfg.vehicle})"),
            plot_signals(
                df,
                [
                    ("depth [m]", [("vehicle.z", "z", 1.0)]),
                    ("speed [m/s]", [("vehicle.u", "u", 1.0), ("vehicle.v", "v", 1.0), ("vehicle.w", "w", 1.0)]),
                    (
                        "attitude [deg]",
                        [("vehicle.phi", "roll", deg), ("vehicle.theta", "pitch", deg), ("vehicle.psi", "yaw", deg)],
                    ),
                ],
                out_dir / "states.png",
                title=f"{self.name}: states",
            ),
        ]


_ROV_GAINS = {
    "surge": (60.0, 6.0, 50.0),
    "sway": (60.0, 6.0, 50.0),
    "heave": (80.0, 10.0, 60.0),
    "roll": (25.0, 10.0, 6.0),
    "pitch": (25.0, 10.0, 6.0),
    "yaw": (8.0, 0.5, 4.0),
}
_OTTER_GAINS = {"surge": (200.0, 40.0, 0.0), "yaw": (60.0, 0.0, 40.0)}

SCENARIOS = [
    VehicleScenario(
        "rov-station-keeping",
        "BlueROV2 Heavy (a vehicle file) holding position and 5 m depth in a 0.2 m/s current",
        {
            "vehicle": "bluerov2-heavy",
            "sim": {"duration": 90.0, "dt": 0.005},
            "environment": {"current": {"speed": 0.2, "direction_deg": 45.0}},
            "setpoint": {"x": 2.0, "y": 1.0, "z": 5.0, "psi_deg": 30.0},
            "control": {"gains": _ROV_GAINS},
        },
        route=False,
        kind="underwater",
    ),
    VehicleScenario(
        "otter-waypoints",
        "Otter USV (a vehicle file) on an LOS route at 1.5 m/s with speed and heading PIDs",
        {
            "vehicle": "otter",
            "sim": {"duration": 300.0, "dt": 0.01},
            "route": {"waypoints": [(0.0, 0.0), (60.0, 0.0), (60.0, 60.0), (0.0, 60.0), (0.0, 0.0)]},
            "control": {"gains": _OTTER_GAINS},
            "analysis": {"settle_s": 20.0},
        },
        route=True,
        kind="surface",
    ),
]
