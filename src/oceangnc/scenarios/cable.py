"""Cable and towed-UUV scenarios of document 003 (ch. 2.3, its open-loop test printed as sec. 2.2.3.3: fig 2-10
of p. 41 and the tank figs 2-12/2-13 - 003 numbers a second fig 2-10 there, the first being the USV's turn in a
current on p. 25; ch. 4 figs 4-2 to 4-5).

* ``cable-current``: the cable's top node held fixed at the surface, the UUV hanging below with its
  thrusters off, facing the current (heading 180 deg, current toward 0 deg), a uniform current
  ``environment.current.speed`` (m/s) switched on at t = 0 (003 fig 2-10 of p. 41: the cable is pushed back,
  the tension peaks and settles). The UUV starts 3.25 m deep: the straight cable is then stretched
  about as much as in the still-water hanging equilibrium (3.23 m), so the transient is the
  current's, not that of a dropped UUV. Summary:
  ``cable.top_tension_N``, ``cable.bottom_tension_N``, ``cable.angle_deg`` (angle from vertical of
  the top-to-bottom line), ``uuv.offset_m`` (horizontal offset of the UUV's CB from the top point),
  ``uuv.depth_m``, ``cable.settled`` (the last 10 s of these change by less than 1 %, or by less
  than 1 mm / 0.01 N / 0.01 deg where the value itself is near zero) — all at the end of the run.
* ``tow-straight``: the USV holds a heading and a surge speed (anti-windup PIDs, 003 eq. 3.10),
  the UUV's stern thrusters hold its own surge-speed command (PID with drag feed-forward) and its
  bow thruster its heading. Both vehicles first hang still for ``command.start_s`` s (the cable
  settles under the UUV's weight), then the commands start. 003 figs 4-2 to 4-5: USV 0.5 m/s with
  UUV 0.27 m/s gives a large depth change (the slower UUV is dragged up), 0.5 with 0.48 a small one.
  Summary: ``uuv.depth_change_max_m`` (largest |z - z(start)| after the start), ``uuv.depth_final_m``,
  ``cable.top_tension_max_N`` (after the start), ``usv.speed_final_mps``, ``uuv.speed_final_mps``.

The physics step: ``sim.dt = 0`` (default) picks 90 % of the cable's RK4 stability limit
(:func:`oceangnc.models.cable.axial_stability_limit`), rounded down to divide the 10 ms control
period; an explicit ``sim.dt`` above the limit is refused. With ``cable.integrator = "imex"`` there is
no axial limit and ``sim.dt = 0`` gives the 10 ms control period (docs/uuv-and-cable.md).
"""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
from pydantic import Field

from ..control.actuators import USVThrusterBlock, UUVThrusterBlock
from ..control.tow import TowCommand, TowStraightControl
from ..core.clock import Simulation
from ..environment import SeaEnvironmentConfig
from ..io.config import ScenarioConfig, SimConfig, StrictModel
from ..io.plots import plot_signals
from ..models.cable import CableConfig, stable_step
from ..models.combined import CombinedPlant
from ..models.usv import USVConfig
from ..models.uuv import UUVConfig
from ..units import KGF
from ._common import environment_blocks
from .base import Scenario

CONTROL_PERIOD = 0.01  # s, 100 Hz vehicle loops (the tow loops' default period)


class CableSimConfig(SimConfig):
    """Clock settings; ``dt = 0`` chooses the step from the cable's stability limit."""

    dt: float = Field(
        0.0, ge=0, le=0.1, description="physics (RK4) step, 0 = automatic from the cable's stability limit, s"
    )
    duration: float = Field(60.0, gt=0, le=1e6, description="simulated time, s")


class CableAnalysis(StrictModel):
    settle_window_s: float = Field(10.0, gt=0, le=1e4, description="window for the settled test, s")
    settle_tol: float = Field(0.01, gt=0, le=1, description="relative change allowed in the window, -")


class CableCurrentConfig(ScenarioConfig):
    sim: CableSimConfig = CableSimConfig()
    usv: USVConfig = USVConfig()
    uuv: UUVConfig = UUVConfig()
    cable: CableConfig = CableConfig()
    environment: SeaEnvironmentConfig = SeaEnvironmentConfig()
    analysis: CableAnalysis = CableAnalysis()


class TowStraightConfig(CableCurrentConfig):
    command: TowCommand = TowCommand()


def physics_step(cfg, plant: CombinedPlant) -> float:
    """``cfg.sim.dt`` if set, else 90 % of the plant's stability limit rounded to divide 10 ms."""
    return cfg.sim.dt if cfg.sim.dt > 0 else stable_step(plant.stability_limit, CONTROL_PERIOD, 0.9)


def _settled(w, cols, tol) -> bool:
    floors = {
        "cable.top_tension": 0.01,
        "cable.bottom_tension": 0.01,
        "cable.angle_deg": 0.01,
        "uuv.offset": 1e-3,
        "uuv.z": 1e-3,
    }
    for c in cols:
        v = w[c].to_numpy()
        span = float(np.max(v) - np.min(v))
        if span > max(tol * abs(float(np.mean(v))), floors.get(c, 1e-3)):
            return False
    return True


def cable_plots(df, cfg, out_dir: Path, name: str, n_shapes: int = 6) -> list[Path]:
    """3D cable shapes at several instants, tensions and angle, UUV depth and speeds."""
    import matplotlib.pyplot as plt

    out_dir = Path(out_dir)
    n = cfg.cable.segments
    idx = np.linspace(0, len(df) - 1, n_shapes).astype(int)
    fig = plt.figure(figsize=(7, 6))
    ax = fig.add_subplot(111, projection="3d")
    cmap = plt.get_cmap("viridis")
    for j, k in enumerate(idx):
        row = df.iloc[k]
        xs = [row[f"cable.x{i}"] for i in range(n + 1)]
        ys = [row[f"cable.y{i}"] for i in range(n + 1)]
        zs = [row[f"cable.z{i}"] for i in range(n + 1)]
        col = cmap(j / max(1, len(idx) - 1))
        ax.plot(ys, xs, zs, "-o", ms=2, color=col, label=f"t = {row['t']:.0f} s")
        ax.plot([row["uuv.y"]], [row["uuv.x"]], [row["uuv.z"]], "s", color=col, ms=6)
    cols = [f"cable.{a}{i}" for i in range(n + 1) for a in "xy"]
    span = max(1.0, float(np.nanmax(df[cols].to_numpy()) - np.nanmin(df[cols].to_numpy())))
    xs_all = df[[f"cable.x{i}" for i in range(n + 1)]].to_numpy()
    ys_all = df[[f"cable.y{i}" for i in range(n + 1)]].to_numpy()
    cx, cy = 0.5 * (np.nanmax(xs_all) + np.nanmin(xs_all)), 0.5 * (np.nanmax(ys_all) + np.nanmin(ys_all))
    ax.set_xlim(cy - span / 2, cy + span / 2)
    ax.set_ylim(cx - span / 2, cx + span / 2)
    ax.set_xlabel("east y [m]")
    ax.set_ylabel("north x [m]")
    ax.set_zlabel("depth z [m]")
    ax.invert_zaxis()
    ax.legend(fontsize=7, loc="upper left")
    ax.set_title(f"{name}: cable shape (square: UUV centre)")
    fig.tight_layout()
    p3 = out_dir / "cable_3d.png"
    fig.savefig(p3, dpi=110)
    plt.close(fig)
    p1 = plot_signals(
        df,
        [
            ("tension [N]", [("cable.top_tension", "top", 1.0), ("cable.bottom_tension", "bottom (on UUV)", 1.0)]),
            ("cable angle [deg]", [("cable.angle_deg", "from vertical", 1.0)]),
            ("UUV depth [m]", [("uuv.z", "z", 1.0)]),
            ("speed [m/s]", [("usv.speed", "USV", 1.0), ("uuv.u", "UUV u", 1.0)]),
            ("UUV pitch [deg]", [("uuv.theta", "theta", 180 / math.pi)]),
        ],
        out_dir / "tension_depth.png",
        title=f"{name}: tensions, angle, depth",
    )
    return [p3, p1]


class CableCurrent(Scenario):
    name = "cable-current"
    summary = (
        "Cable with fixed top, UUV hanging in a uniform current: equilibrium tension and angle "
        "(003 sec. 2.2.3.3: fig 2-10 of p. 41, figs 2-12/2-13)"
    )
    Config = CableCurrentConfig
    defaults = {
        "sim": {"duration": 60.0, "log_rate": 10.0},
        "environment": {"current": {"speed": 0.5, "direction_deg": 0.0}},
        "uuv": {"psi0_deg": 180.0, "z0": 3.25},
    }

    def build(self, cfg, rng):
        plant = CombinedPlant(cfg.usv, cfg.uuv, cfg.cable, top="fixed", **cfg.environment.plant_kwargs(cfg.sim.seed))
        # the USV is held and no thruster runs: every thrust input is zero by composition
        plant.input_defaults.update({k: 0.0 for k in plant.input_names if ".thrust_" in k})
        dt = physics_step(cfg, plant)
        return Simulation([plant], environment_blocks(cfg.environment), dt, 1.0 / cfg.sim.log_rate, rng)

    def summarize(self, df, cfg) -> dict:
        top = (df["cable.x0"].iloc[0], df["cable.y0"].iloc[0])
        df = df.assign(**{"uuv.offset": np.hypot(df["uuv.x"] - top[0], df["uuv.y"] - top[1])})
        last = df.iloc[-1]
        w = df[df["t"] >= df["t"].iloc[-1] - cfg.analysis.settle_window_s]
        cols = ["cable.top_tension", "cable.bottom_tension", "cable.angle_deg", "uuv.offset", "uuv.z"]
        return {
            "cable.top_tension_N": float(last["cable.top_tension"]),
            "cable.bottom_tension_N": float(last["cable.bottom_tension"]),
            "cable.angle_deg": float(last["cable.angle_deg"]),
            "uuv.offset_m": float(last["uuv.offset"]),
            "uuv.depth_m": float(last["uuv.z"]),
            "uuv.pitch_deg": math.degrees(float(last["uuv.theta"])),
            "cable.top_tension_peak_N": float(df["cable.top_tension"].max()),
            "cable.settled": _settled(w, cols, cfg.analysis.settle_tol),
        }

    def plot(self, df, cfg, out_dir: Path) -> list[Path]:
        return cable_plots(df, cfg, out_dir, self.name)


class TowStraight(Scenario):
    name = "tow-straight"
    summary = "USV tows the UUV straight at 0.5 m/s, UUV at its own speed: depth change (003 figs 4-2 to 4-5)"
    Config = TowStraightConfig
    defaults = {"sim": {"duration": 80.0, "log_rate": 10.0}}

    def build(self, cfg, rng):
        plant = CombinedPlant(cfg.usv, cfg.uuv, cfg.cable, top="usv", **cfg.environment.plant_kwargs(cfg.sim.seed))
        dt = physics_step(cfg, plant)
        blocks = [
            *environment_blocks(cfg.environment),
            TowStraightControl(cfg.command, cfg.usv, cfg.uuv, CONTROL_PERIOD),
            USVThrusterBlock(cfg.usv, CONTROL_PERIOD),
            UUVThrusterBlock(cfg.uuv, CONTROL_PERIOD),
        ]
        return Simulation([plant], blocks, dt, 1.0 / cfg.sim.log_rate, rng)

    def summarize(self, df, cfg) -> dict:
        t0 = cfg.command.start_s
        after = df[df["t"] >= t0]
        if after.empty:
            after = df.iloc[-1:]
        z0 = float(after["uuv.z"].iloc[0])
        last = df.iloc[-1]
        return {
            "uuv.depth_start_m": z0,
            "uuv.depth_change_max_m": float(np.max(np.abs(after["uuv.z"] - z0))),
            "uuv.depth_final_m": float(last["uuv.z"]),
            "cable.top_tension_max_N": float(after["cable.top_tension"].max()),
            "cable.angle_final_deg": float(last["cable.angle_deg"]),
            "usv.speed_final_mps": float(last["usv.speed"]),
            "uuv.speed_final_mps": float(last["uuv.u"]),
        }

    def plot(self, df, cfg, out_dir: Path) -> list[Path]:
        out = cable_plots(df, cfg, out_dir, self.name)
        out.append(
            plot_signals(
                df,
                [
                    ("USV thrust [kgf]", [("usv.thrust_port", "port", 1 / KGF), ("usv.thrust_stbd", "stbd", 1 / KGF)]),
                    (
                        "UUV thrust [kgf]",
                        [
                            ("uuv.thrust_port", "port", 1 / KGF),
                            ("uuv.thrust_stbd", "stbd", 1 / KGF),
                            ("uuv.thrust_bow", "bow", 1 / KGF),
                        ],
                    ),
                ],
                Path(out_dir) / "thrusts.png",
                title=f"{self.name}: thrusts",
            )
        )
        return out


SCENARIOS = [CableCurrent(), TowStraight()]
