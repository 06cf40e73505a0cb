"""USV open-loop trials of document 003 figs 2-7 to 2-10.

* ``usv-straight``: 30 kgf on both thrusters; steady speed (fig 2-7: about 0.8 m/s).
* ``usv-turn``: 30 kgf port, 15 kgf starboard; turning radius and yaw rate (fig 2-8: about 1.75 m
  at about 16 deg/s).
* ``usv-turn-wind``: the same turn in 1 m/s wind (fig 2-9; direction settable,
  ``environment.wind.direction_deg``): the circle drifts downwind.
* ``usv-turn-current``: the same turn in a 0.1 m/s current toward 45 deg (fig 2-10 of p. 25): the circle's
  centre drifts with the current.

Metrics are computed over the last ``analysis.window_s`` seconds: ``usv.steady_speed_mps`` (mean
ground speed), ``usv.turn_radius_m``, ``usv.yaw_rate_degps`` (mean), and ``usv.drift_speed_mps`` /
``usv.drift_direction_deg`` (velocity of the circle's centre, deg from north, toward), from
:func:`oceangnc.scenarios._common.circle_fit_drifting`.
"""

from __future__ import annotations

import math
from pathlib import Path
from typing import Literal

from pydantic import Field

from ..control.actuators import USVThrusterBlock
from ..core.blocks import ConstantBlock
from ..core.clock import Simulation
from ..environment import EnvironmentConfig
from ..io.config import ScenarioConfig, StrictModel
from ..io.plots import plot_signals, plot_track
from ..models.usv import USVConfig, USVPlant
from ..units import KGF
from ._common import circle_fit_drifting, environment_blocks
from .base import Scenario


class ThrustCommand(StrictModel):
    """Constant open-loop thruster command."""

    mode: Literal["thrust", "voltage"] = "thrust"
    thrust_port_kgf: float = Field(30.0, ge=-50, le=50, description="port thrust command, kgf")
    thrust_stbd_kgf: float = Field(30.0, ge=-50, le=50, description="starboard thrust command, kgf")
    volt_port: float = Field(2.4, ge=0.0, le=5.0, description="port DAC voltage (mode voltage), V")
    volt_stbd: float = Field(2.4, ge=0.0, le=5.0, description="starboard DAC voltage (mode voltage), V")


class Analysis(StrictModel):
    window_s: float = Field(40.0, gt=0, le=1e5, description="final interval used for the metrics, s")


class USVOpenLoopConfig(ScenarioConfig):
    usv: USVConfig = USVConfig()
    environment: EnvironmentConfig = EnvironmentConfig()
    command: ThrustCommand = ThrustCommand()
    analysis: Analysis = Analysis()
    control_rate: float = Field(100.0, gt=0, le=1000, description="command/actuator update rate, Hz")


def build_simulation(cfg: USVOpenLoopConfig, rng) -> Simulation:
    """Plant, environment, constant command and thrusters."""
    c = cfg.command
    h = 1.0 / cfg.control_rate

    command = ConstantBlock(
        "command",
        h,
        {
            "usv.thrust_port_cmd": c.thrust_port_kgf * KGF,
            "usv.thrust_stbd_cmd": c.thrust_stbd_kgf * KGF,
            "usv.volt_port_cmd": c.volt_port,
            "usv.volt_stbd_cmd": c.volt_stbd,
        },
        units={
            "usv.thrust_port_cmd": "N",
            "usv.thrust_stbd_cmd": "N",
            "usv.volt_port_cmd": "V",
            "usv.volt_stbd_cmd": "V",
        },
    )
    blocks = [*environment_blocks(cfg.environment), command, USVThrusterBlock(cfg.usv, h, mode=c.mode)]
    return Simulation([USVPlant(cfg.usv)], blocks, cfg.sim.dt, 1.0 / cfg.sim.log_rate, rng)


class USVOpenLoop(Scenario):
    Config = USVOpenLoopConfig
    frame = "columns"  # summary and plots read columns only (oceangnc.io.frame)

    def __init__(self, name: str, summary: str, defaults: dict, turning: bool):
        self.name = name
        self.summary = summary
        self.defaults = defaults
        self.turning = turning

    def build(self, cfg, rng):
        return build_simulation(cfg, rng)

    def summarize(self, df, cfg) -> dict:
        w = df[df["t"] >= df["t"].iloc[-1] - cfg.analysis.window_s]
        out = {"usv.steady_speed_mps": float(w["usv.speed"].mean())}
        if self.turning:
            rad, vd, dd, res = circle_fit_drifting(w["t"], w["usv.x"], w["usv.y"], w["usv.psi"])
            out.update(
                {
                    "usv.turn_radius_m": rad,
                    "usv.yaw_rate_degps": math.degrees(float(w["usv.r"].mean())),
                    "usv.drift_speed_mps": vd,
                    "usv.drift_direction_deg": dd,
                    "usv.circle_fit_rms_m": res,
                }
            )
        return out

    def plot(self, df, cfg, out_dir: Path) -> list[Path]:
        out_dir = Path(out_dir)
        return [
            plot_track(df, ["usv"], out_dir / "trajectory.png", title=self.name),
            plot_signals(
                df,
                [
                    ("speed [m/s]", [("usv.u", "u", 1.0), ("usv.v", "v", 1.0), ("usv.speed", "|V|", 1.0)]),
                    ("yaw rate [deg/s]", [("usv.r", "r", 180 / math.pi)]),
                    ("heading [deg]", [("usv.psi", "psi", 180 / math.pi)]),
                ],
                out_dir / "states.png",
                title=f"{self.name}: states",
            ),
            plot_signals(
                df,
                [
                    ("thrust [kgf]", [("usv.thrust_port", "port", 1 / KGF), ("usv.thrust_stbd", "starboard", 1 / KGF)]),
                    ("current / wind [m/s]", [("env.current_speed", "current", 1.0), ("env.wind_speed", "wind", 1.0)]),
                ],
                out_dir / "actuators.png",
                title=f"{self.name}: actuators and environment",
            ),
        ]


_TURN = {"command": {"thrust_port_kgf": 30.0, "thrust_stbd_kgf": 15.0}, "sim": {"duration": 90.0}}

SCENARIOS = [
    USVOpenLoop(
        "usv-straight",
        "USV, 30 kgf on both thrusters: steady speed (003 fig 2-7, ~0.8 m/s)",
        {
            "command": {"thrust_port_kgf": 30.0, "thrust_stbd_kgf": 30.0},
            "sim": {"duration": 30.0},
            "analysis": {"window_s": 10.0},
        },
        turning=False,
    ),
    USVOpenLoop("usv-turn", "USV, 30/15 kgf: turning circle (003 fig 2-8, R ~1.75 m, ~16 deg/s)", _TURN, True),
    USVOpenLoop(
        "usv-turn-wind",
        "USV turning in 1 m/s wind, direction settable (003 fig 2-9)",
        {**_TURN, "environment": {"wind": {"speed": 1.0, "direction_deg": 0.0}}},
        True,
    ),
    USVOpenLoop(
        "usv-turn-current",
        "USV turning in a 0.1 m/s current toward 45 deg (003 fig 2-10 of p. 25)",
        {**_TURN, "environment": {"current": {"speed": 0.1, "direction_deg": 45.0}}},
        True,
    ),
]
