"""Tow operations with a winch (issue 16): ``tow-deploy`` and ``tow-survey-depth``.

* ``tow-deploy``: the USV holds station (calm water; 003's USV is not loaded by the cable), the UUV
  (thrusters off) hangs below it on a short line and is lowered to ``winch_control.profile``'s depth
  (default 30 m) by the depth-by-winch loop (:class:`oceangnc.control.winch.WinchDepthController`),
  held there and recovered to the surface. Summary: ``uuv.depth_max_m``, ``uuv.depth_final_m``,
  ``cable.length_max_m``, ``cable.nodes_max``, ``winch.tension_max_N``, ``winch.tension_limit_N``,
  ``winch.tension_limit_exceeded`` (rows above the limit), ``uuv.depth_error_rms_m`` (against the
  profile), ``cable.mass_rel_error_max`` (mass of cable in the water against rho_c A L, every row),
  ``winch.cmd_saturated_rows``, ``winch.at_capacity_rows``. Plots: cable length against depth and
  against tension (``length_depth_tension.png``), time series (``deploy_timeseries.png``).
* ``tow-survey-depth``: the USV tows at ``guidance.speed`` (1 m/s) along a lawnmower (pure pursuit over
  ``guidance.waypoints``) over a sloping seabed (``environment.seabed``); the UUV steers toward the USV
  and holds a surge speed with its own thrusters, and the winch holds its altitude
  (``winch_control.mode = "altitude"``, 5 m). Summary: ``uuv.altitude_rms_error_m`` (after
  ``analysis.settle_s``), ``uuv.altitude_max_error_m``, ``uuv.altitude_min_m``, ``cable.length_min_m`` /
  ``_max_m``, ``winch.tension_max_N``, ``usv.waypoints_reached``, ``t_end_s``. Plots: track and seabed
  (``survey_track.png``), altitude, depth, length and tension (``survey_timeseries.png``).

Both use the implicit cable integrator (``cable.integrator = "imex"``) at the 10 ms control period.
Bad input: a drum command beyond ``winch.speed_max`` is saturated (``winch.cmd_saturated`` logged), a
payout beyond ``winch.capacity`` stops there (``winch.at_capacity``, the warning signal in the log), a
seabed above the cable's attachment point is refused (ConfigError naming
``environment.seabed.depth``).
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
from pydantic import Field

from ..control.actuators import ThrustersOff, USVThrusterBlock, UUVThrusterBlock
from ..control.tow import UUVFollow, UUVFollowConfig
from ..control.usv_control import USVControlConfig, USVController
from ..control.winch import WinchControlConfig, WinchDepthController
from ..core.clock import Simulation
from ..environment import SeaEnvironmentConfig
from ..guidance.pure_pursuit import PurePursuit
from ..io.config import ScenarioConfig, SimConfig, StrictModel
from ..io.plots import plot_signals
from ..models.cable import CableConfig
from ..models.combined import CombinedPlant
from ..models.usv import USVConfig
from ..models.uuv import UUVConfig
from ..models.winch import WinchConfig
from ..units import KGF
from ._common import environment_blocks
from .base import Scenario

CONTROL_PERIOD = 0.01  # s


class TowSimConfig(SimConfig):
    dt: float = Field(0.01, gt=0, le=0.1, description="physics step (implicit cable), s")
    duration: float = Field(360.0, gt=0, le=1e6, description="simulated time, s")
    log_rate: float = Field(5.0, gt=0, le=1000, description="logged rows per second, Hz")


class TowAnalysis(StrictModel):
    settle_s: float = Field(
        150.0, ge=0, le=1e5, description="tow-survey-depth: time after which the altitude error is scored, s"
    )


class TowGuidance(StrictModel):
    waypoints: list[tuple[float, float]] = Field(
        [(0.0, 0.0), (300.0, 0.0), (300.0, 60.0), (0.0, 60.0), (0.0, 120.0), (300.0, 120.0)],
        min_length=2,
        description="lawnmower waypoints (north, east), m",
    )
    speed: float = Field(1.0, gt=0, le=3, description="USV tow speed, m/s")
    look_ahead: float = Field(20.0, gt=0, le=1e3, description="pure-pursuit look-ahead, m")
    acceptance: float = Field(5.0, gt=0, le=100, description="waypoint acceptance radius, m")


class TowDeployConfig(ScenarioConfig):
    sim: TowSimConfig = TowSimConfig()
    usv: USVConfig = USVConfig()
    uuv: UUVConfig = UUVConfig()
    cable: CableConfig = CableConfig()
    winch: WinchConfig = WinchConfig()
    winch_control: WinchControlConfig = WinchControlConfig()
    environment: SeaEnvironmentConfig = SeaEnvironmentConfig()
    analysis: TowAnalysis = TowAnalysis()


class TowSurveyConfig(TowDeployConfig):
    guidance: TowGuidance = TowGuidance()
    usv_control: USVControlConfig = USVControlConfig()
    uuv_follow: UUVFollowConfig = UUVFollowConfig()


def _plant(cfg, top="usv") -> CombinedPlant:
    return CombinedPlant(
        cfg.usv,
        cfg.uuv,
        cfg.cable,
        top=top,
        winch=cfg.winch,
        seabed=cfg.environment.seabed,
        **cfg.environment.plant_kwargs(cfg.sim.seed),
    )


def _common_summary(df, cfg) -> dict:
    from ..models.cable import CableConfig as _C  # noqa: F401

    c = cfg.cable
    rho_a = c.density * c.area
    mass_err = np.abs(df["cable.mass"].to_numpy() / (rho_a * df["cable.length"].to_numpy()) - 1.0)
    T = df["cable.top_tension"].to_numpy()
    return {
        "cable.length_min_m": float(df["cable.length"].min()),
        "cable.length_max_m": float(df["cable.length"].max()),
        "cable.nodes_max": int(df["cable.nodes"].max()),
        "cable.mass_rel_error_max": float(np.max(mass_err)),
        "winch.tension_max_N": float(np.max(T)),
        "winch.tension_limit_N": float(cfg.winch.tension_max),
        "winch.tension_limit_exceeded": int(np.sum(T > cfg.winch.tension_max)),
        "winch.cmd_saturated_rows": int(df["winch.cmd_saturated"].sum()),
        "winch.at_capacity_rows": int(df["winch.at_capacity"].sum()),
        "winch.energy_hauling_kJ": float(
            np.sum(np.maximum(df["winch.power"].to_numpy(), 0.0)) / cfg.sim.log_rate / 1e3
        ),
    }


class TowDeploy(Scenario):
    frame = "columns"  # summary and plots read columns only (oceangnc.io.frame)
    name = "tow-deploy"
    summary = "USV holding station, UUV lowered by the winch from the surface to 30 m and recovered"
    Config = TowDeployConfig
    defaults = {
        "sim": {"duration": 360.0},
        "uuv": {"z0": 1.16},
        "cable": {"length": 1.0, "segment_length": 1.0, "integrator": "imex"},
        "winch": {"enabled": True, "capacity": 40.0, "tension_max": 1000.0, "speed_max": 0.5},
        "winch_control": {
            "mode": "depth",
            "target": 1.3,
            "profile": [(0.0, 1.3), (10.0, 1.3), (150.0, 30.0), (190.0, 30.0), (330.0, 1.3)],
        },
    }

    def build(self, cfg, rng):
        plant = _plant(cfg, top="usv")
        blocks = [
            *environment_blocks(cfg.environment),
            ThrustersOff(
                [
                    "usv.thrust_port_cmd",
                    "usv.thrust_stbd_cmd",
                    "uuv.thrust_port_cmd",
                    "uuv.thrust_stbd_cmd",
                    "uuv.thrust_bow_cmd",
                ]
            ),
            WinchDepthController(cfg.winch_control, cfg.winch.tension_max),
            USVThrusterBlock(cfg.usv, CONTROL_PERIOD),
            UUVThrusterBlock(cfg.uuv, CONTROL_PERIOD),
        ]
        return Simulation([plant], blocks, cfg.sim.dt, 1.0 / cfg.sim.log_rate, rng)

    def summarize(self, df, cfg) -> dict:
        out = _common_summary(df, cfg)
        ref = df["winch.target"].to_numpy()
        err = df["uuv.z"].to_numpy() - ref
        out.update(
            {
                "uuv.depth_max_m": float(df["uuv.z"].max()),
                "uuv.depth_final_m": float(df["uuv.z"].iloc[-1]),
                "uuv.depth_error_rms_m": float(np.sqrt(np.mean(err**2))),
                "uuv.depth_error_max_m": float(np.max(np.abs(err))),
            }
        )
        return out

    def plot(self, df, cfg, out_dir: Path) -> list[Path]:
        import matplotlib.pyplot as plt

        out_dir = Path(out_dir)
        fig, axs = plt.subplots(1, 2, figsize=(10, 4.2))
        sc = axs[0].scatter(df["cable.length"], df["uuv.z"], c=df["t"], s=4, cmap="viridis")
        axs[0].set_xlabel("cable length paid out [m]")
        axs[0].set_ylabel("UUV depth [m]")
        axs[0].invert_yaxis()
        axs[0].grid(alpha=0.3)
        axs[1].scatter(df["cable.length"], df["cable.top_tension"], c=df["t"], s=4, cmap="viridis")
        w = cfg.cable.weight_per_length
        Ls = np.linspace(float(df["cable.length"].min()), float(df["cable.length"].max()), 20)
        axs[1].plot(
            Ls, w * Ls + cfg.uuv.weight_in_water_kgf * KGF, "k--", lw=1, label="submerged weight: cable paid out + UUV"
        )
        axs[1].axhline(cfg.winch.tension_max, color="r", lw=1, label="tension limit")
        axs[1].set_xlabel("cable length paid out [m]")
        axs[1].set_ylabel("top tension [N]")
        axs[1].grid(alpha=0.3)
        axs[1].legend(fontsize=8)
        fig.colorbar(sc, ax=axs, label="t [s]")
        fig.suptitle(f"{self.name}: length against depth and tension")
        p1 = out_dir / "length_depth_tension.png"
        fig.savefig(p1, dpi=110)
        plt.close(fig)
        p2 = plot_signals(
            df,
            [
                ("depth [m]", [("uuv.z", "UUV", 1.0), ("winch.target", "target", 1.0)]),
                ("length [m]", [("cable.length", "paid out", 1.0)]),
                ("line speed [m/s]", [("winch.speed", "drum", 1.0), ("winch.speed_cmd_sat", "command (sat.)", 1.0)]),
                ("tension [N]", [("cable.top_tension", "top", 1.0)]),
                ("power [W]", [("winch.power", "winch", 1.0)]),
                ("nodes [-]", [("cable.nodes", "nodes", 1.0)]),
            ],
            out_dir / "deploy_timeseries.png",
            title=f"{self.name}: depth, length, speed, tension",
        )
        return [p1, p2]


class TowSurveyDepth(Scenario):
    frame = "columns"  # summary and plots read columns only (oceangnc.io.frame)
    name = "tow-survey-depth"
    summary = "Towing at 1 m/s on a lawnmower over a sloping seabed, 5 m altitude held by the winch"
    Config = TowSurveyConfig
    defaults = {
        "sim": {"duration": 1200.0},
        "uuv": {"z0": 15.3},
        "cable": {"length": 15.0, "segment_length": 1.5, "integrator": "imex"},
        "winch": {"enabled": True, "capacity": 150.0, "tension_max": 4000.0, "speed_max": 0.5},
        "winch_control": {"mode": "altitude", "target": 5.0, "kp": 0.08, "ki": 0.002, "kd": 1.5},
        "uuv_follow": {"speed": 0.5},
        "environment": {"seabed": {"depth": 20.0, "slope_deg": 3.0}},
    }

    def build(self, cfg, rng):
        plant = _plant(cfg, top="usv")
        g = cfg.guidance
        blocks = [
            *environment_blocks(cfg.environment),
            PurePursuit(g.waypoints, g.look_ahead, g.acceptance, 0.1),
            USVController(cfg.usv_control, cfg.usv, g.speed, CONTROL_PERIOD),
            UUVFollow(cfg.uuv_follow, cfg.uuv),
            WinchDepthController(cfg.winch_control, cfg.winch.tension_max),
            USVThrusterBlock(cfg.usv, CONTROL_PERIOD),
            UUVThrusterBlock(cfg.uuv, CONTROL_PERIOD),
        ]
        return Simulation([plant], blocks, cfg.sim.dt, 1.0 / cfg.sim.log_rate, rng)

    def summarize(self, df, cfg) -> dict:
        out = _common_summary(df, cfg)
        a = df["uuv.altitude"].to_numpy()
        after = df["t"].to_numpy() >= cfg.analysis.settle_s
        err = a[after] - cfg.winch_control.target if np.any(after) else np.array([np.nan])
        out.update(
            {
                "uuv.altitude_rms_error_m": float(np.sqrt(np.mean(err**2))),
                "uuv.altitude_max_error_m": float(np.max(np.abs(err))),
                "uuv.altitude_min_m": float(np.min(a)),
                "uuv.depth_min_m": float(df["uuv.z"].min()),
                "uuv.depth_max_m": float(df["uuv.z"].max()),
                "usv.waypoints_reached": int(df["guidance.wp_reached"].max()) if "guidance.wp_reached" in df else 0,
                "usv.waypoints_total": len(cfg.guidance.waypoints),
                "t_end_s": float(df["t"].iloc[-1]),
            }
        )
        return out

    def plot(self, df, cfg, out_dir: Path) -> list[Path]:
        import matplotlib.pyplot as plt

        out_dir = Path(out_dir)
        fig, axs = plt.subplots(1, 2, figsize=(11, 4.5))
        axs[0].plot(df["usv.y"], df["usv.x"], label="USV")
        axs[0].plot(df["uuv.y"], df["uuv.x"], label="UUV")
        wp = np.asarray(cfg.guidance.waypoints)
        axs[0].plot(wp[:, 1], wp[:, 0], "k+", ms=10, label="waypoints")
        axs[0].set_xlabel("east [m]")
        axs[0].set_ylabel("north [m]")
        axs[0].set_aspect("equal")
        axs[0].legend(fontsize=8)
        axs[0].grid(alpha=0.3)
        bed = df["uuv.z"] + df["uuv.altitude"]
        axs[1].plot(df["t"], bed, "k", label="seabed under the UUV")
        axs[1].plot(df["t"], df["uuv.z"], label="UUV depth")
        axs[1].plot(df["t"], bed - cfg.winch_control.target, "--", label=f"{cfg.winch_control.target:g} m altitude")
        axs[1].axvline(cfg.analysis.settle_s, color="grey", lw=0.8, ls=":")
        axs[1].invert_yaxis()
        axs[1].set_xlabel("t [s]")
        axs[1].set_ylabel("depth [m]")
        axs[1].legend(fontsize=8)
        axs[1].grid(alpha=0.3)
        fig.suptitle(f"{self.name}: track and depth profile")
        fig.tight_layout()
        p1 = out_dir / "survey_track.png"
        fig.savefig(p1, dpi=110)
        plt.close(fig)
        p2 = plot_signals(
            df,
            [
                ("altitude [m]", [("uuv.altitude", "UUV", 1.0)]),
                ("length [m]", [("cable.length", "paid out", 1.0)]),
                ("line speed [m/s]", [("winch.speed", "drum", 1.0)]),
                ("tension [N]", [("cable.top_tension", "top", 1.0)]),
                ("speed [m/s]", [("usv.speed", "USV", 1.0), ("uuv.u", "UUV u", 1.0)]),
            ],
            out_dir / "survey_timeseries.png",
            title=f"{self.name}: altitude, length, tension",
        )
        return [p1, p2]


SCENARIOS = [TowDeploy(), TowSurveyDepth()]
