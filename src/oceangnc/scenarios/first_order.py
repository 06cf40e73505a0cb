"""Scenarios of document 000: pole-placed autopilots, waypoints, UUV-based planning (trials: :mod:`.trials`).

* ``autopilot-heading``: heading 0 -> 100 deg with the pole-placed PD (000 fig. 17).
* ``autopilot-speed``: speed 0 -> 5 m/s with the pole-placed P (000 fig. 18).
* ``usv-waypoints-7``: seven waypoints from heading 90 deg and zero speed (000 fig. 21).
* ``uuv-profile-plan``: the UUV plan of 000 table 3, the USV plan from it (eq. 32-34), the USV
  following its waypoints with conventional LOS or the hybrid guidance, the UUV towed as a trailer
  (000 figs. 22-26).
"""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
from pydantic import Field, model_validator

from ..control.commands import StepCommand
from ..control.pole_placement import (
    predicted_overshoot,
)
from ..core.clock import Simulation
from ..io.config import StrictModel
from ..io.plots import plot_signals, plot_track
from ..models.first_order import FirstOrderUSV
from ._first_order_common import (
    RAD2DEG,
    ClosedLoopConfig,
    GuidanceConfig,
    _settling_time,
    closed_loop_blocks,
    waypoint_guidance,
)
from .base import Scenario

#: units of the commanded set points
_UNITS = {"usv.psi_cmd": "rad", "usv.u_cmd": "m/s"}

# -- autopilots -------------------------------------------------------------------------------------------


class HeadingCommand(StrictModel):
    heading_deg: float = Field(100.0, ge=-180, le=180, description="commanded heading after the step, deg")
    step_time_s: float = Field(1.0, ge=0, le=1e4, description="time of the heading step, s")
    speed_mps: float = Field(6.0, ge=0.5, le=20, description="speed held by the trim rpm during the manoeuvre, m/s")


class AutopilotHeadingConfig(ClosedLoopConfig):
    command: HeadingCommand = HeadingCommand()


class AutopilotHeading(Scenario):
    frame = "columns"  # summary and plots read columns only (oceangnc.io.frame)
    name = "autopilot-heading"
    summary = "Pole-placed heading PD on the first-order USV: 0 -> 100 deg (000 fig. 17)"
    Config = AutopilotHeadingConfig
    defaults = {"sim": {"duration": 40.0, "dt": 0.01}}

    def build(self, cfg, rng):
        c = cfg.command
        usv = cfg.usv.model_copy(update={"u0": c.speed_mps})
        cfg_u = cfg.model_copy(update={"usv": usv})
        psi_c = math.radians(c.heading_deg)
        cmd = StepCommand("command", 1.0 / cfg.control_rate, c.step_time_s, {"usv.psi_cmd": (0.0, psi_c)}, _UNITS)
        blocks = closed_loop_blocks(cfg_u, [cmd], rpm_open_loop=usv.trim_rpm(c.speed_mps))
        return Simulation([FirstOrderUSV(usv)], blocks, cfg.sim.dt, 1.0 / cfg.sim.log_rate, rng)

    def summarize(self, df, cfg) -> dict:
        c = cfg.command
        t = df["t"].to_numpy()
        psi = np.unwrap(df["usv.psi"].to_numpy())
        target = math.radians(c.heading_deg)
        after = t >= c.step_time_s
        step = target
        over = (np.max(np.sign(step) * psi[after]) - abs(target)) / abs(step) if step else 0.0
        ts = _settling_time(t[after], psi[after], target, 0.02 * abs(step), c.step_time_s)
        dmax = math.radians(cfg.usv.rudder_limit_deg)
        sat = float(np.mean(np.abs(df["usv.delta_s"].to_numpy()[after]) >= dmax * (1 - 1e-9)))
        return {
            "heading.overshoot_pct": 100.0 * max(over, 0.0),
            "heading.predicted_overshoot_pct": 100.0 * predicted_overshoot(cfg.heading.zeta),
            "heading.settling_time_s": ts,
            "heading.final_error_deg": math.degrees(target - psi[-1]),
            "heading.rudder_saturated_frac": sat,
        }

    def plot(self, df, cfg, out_dir: Path) -> list[Path]:
        out_dir = Path(out_dir)
        return [
            plot_signals(
                df,
                [
                    ("heading [deg]", [("usv.psi_cmd", "command", RAD2DEG), ("usv.psi", "psi", RAD2DEG)]),
                    ("yaw rate [deg/s]", [("usv.r", "r", RAD2DEG)]),
                    ("rudder [deg]", [("usv.delta_s", "delta_S", RAD2DEG)]),
                ],
                out_dir / "heading.png",
                title="autopilot-heading (000 fig. 17)",
            )
        ]


class SpeedCommand(StrictModel):
    speed_mps: float = Field(5.0, ge=0.5, le=20, description="commanded speed after the step, m/s")
    step_time_s: float = Field(1.0, ge=0, le=1e4, description="time of the speed step, s")
    window_s: float = Field(10.0, gt=0, le=1e4, description="final window for the steady error, s")


class AutopilotSpeedConfig(ClosedLoopConfig):
    command: SpeedCommand = SpeedCommand()


class AutopilotSpeed(Scenario):
    frame = "columns"  # summary and plots read columns only (oceangnc.io.frame)
    name = "autopilot-speed"
    summary = "Pole-placed speed P on the first-order USV: 0 -> 5 m/s, steady error of P control (000 fig. 18)"
    Config = AutopilotSpeedConfig
    defaults = {"sim": {"duration": 40.0, "dt": 0.01}}

    def build(self, cfg, rng):
        c = cfg.command
        usv = cfg.usv.model_copy(update={"u0": 0.0})
        steps = {"usv.u_cmd": (0.0, c.speed_mps), "usv.psi_cmd": (0.0, 0.0)}
        blocks = closed_loop_blocks(cfg, [StepCommand("command", 1.0 / cfg.control_rate, c.step_time_s, steps, _UNITS)])
        return Simulation([FirstOrderUSV(usv)], blocks, cfg.sim.dt, 1.0 / cfg.sim.log_rate, rng)

    def summarize(self, df, cfg) -> dict:
        c = cfg.command
        t = df["t"].to_numpy()
        u = df["usv.u"].to_numpy()
        fin = float(np.mean(u[t >= t[-1] - c.window_s]))
        after = t >= c.step_time_s
        ta, ua = t[after], u[after]
        i10 = np.nonzero(ua >= 0.1 * fin)[0]
        i90 = np.nonzero(ua >= 0.9 * fin)[0]
        rise = float(ta[i90[0]] - ta[i10[0]]) if i10.size and i90.size else float("nan")
        co = cfg.usv.coefficients(c.speed_mps)
        a = 2 * cfg.speed_control.zeta * cfg.speed_control.wn * co["T_v"]
        return {
            "speed.steady_error_mps": c.speed_mps - fin,
            "speed.rise_time_s": rise,
            "speed.final_mps": fin,
            "speed.predicted_steady_error_mps": c.speed_mps / a,
            "speed.rpm_final": float(df["usv.rpm"].iloc[-1]),
        }

    def plot(self, df, cfg, out_dir: Path) -> list[Path]:
        out_dir = Path(out_dir)
        return [
            plot_signals(
                df,
                [
                    ("speed [m/s]", [("usv.u_cmd", "command", 1.0), ("usv.u", "u", 1.0)]),
                    ("shaft speed [rpm]", [("usv.rpm", "delta_T", 1.0)]),
                ],
                out_dir / "speed.png",
                title="autopilot-speed (000 fig. 18)",
            )
        ]


# -- waypoints ------------------------------------------------------------------------------------------------


_WP7 = [
    [150.0, 400.0],
    [600.0, 400.0],
    [600.0, 900.0],
    [250.0, 1250.0],
    [250.0, 1700.0],
    [700.0, 2000.0],
    [1000.0, 1700.0],
]


class Waypoints7Config(ClosedLoopConfig):
    guidance: GuidanceConfig = GuidanceConfig()
    waypoints: list[list[float]] = Field(_WP7, min_length=2, description="waypoints [north, east], m")
    speed_mps: float = Field(6.0, ge=0.5, le=16, description="commanded speed, m/s")

    @model_validator(mode="after")
    def _wp(self):
        if any(len(w) != 2 for w in self.waypoints):
            raise ValueError("each waypoint is [north, east] in m")
        return self


class USVWaypoints7(Scenario):
    frame = "columns"  # summary and plots read columns only (oceangnc.io.frame)
    name = "usv-waypoints-7"
    summary = "First-order USV through seven waypoints from heading 90 deg, rest; hybrid/LOS guidance (000 fig. 21)"
    Config = Waypoints7Config
    defaults = {"sim": {"duration": 900.0, "dt": 0.01, "log_rate": 5.0}, "usv": {"psi0_deg": 90.0, "u0": 0.0}}

    def build(self, cfg, rng):
        g = waypoint_guidance(cfg.guidance, cfg.waypoints, cfg.speed_mps)
        return Simulation(
            [FirstOrderUSV(cfg.usv)], closed_loop_blocks(cfg, [g]), cfg.sim.dt, 1.0 / cfg.sim.log_rate, rng
        )

    def summarize(self, df, cfg) -> dict:
        from ..guidance.los import distance_to_polyline

        wp = np.asarray(cfg.waypoints, float)
        x, y = df["usv.x"].to_numpy(), df["usv.y"].to_numpy()
        # cross-track error once on the route (after first reaching within R of the first leg)
        d = distance_to_polyline(x, y, wp[:, 0], wp[:, 1])
        on = np.nonzero(d < cfg.guidance.R)[0]
        dd = d[on[0] :] if on.size else d
        reached = [float(np.min(np.hypot(x - a, y - b))) for a, b in wp]
        return {
            "usv.path_error_rms_m": float(np.sqrt(np.mean(dd**2))),
            "usv.path_error_max_m": float(np.max(dd)),
            "usv.join_time_s": float(df["t"].iloc[on[0]]) if on.size else float("nan"),
            "usv.waypoint_miss_max_m": max(reached),
            "usv.final_leg": float(df["guidance.leg"].iloc[-1]),
        }

    def plot(self, df, cfg, out_dir: Path) -> list[Path]:
        out_dir = Path(out_dir)
        return [
            plot_track(
                df,
                ["usv"],
                out_dir / "track.png",
                waypoints=cfg.waypoints,
                title=f"usv-waypoints-7, {cfg.guidance.mode} (000 fig. 21)",
            ),
            plot_signals(
                df,
                [
                    ("speed [m/s]", [("usv.u_cmd", "command", 1.0), ("usv.u", "u", 1.0)]),
                    ("heading [deg]", [("usv.psi_cmd", "command", RAD2DEG), ("usv.psi", "psi", RAD2DEG)]),
                    ("d [m]", [("guidance.d", "perpendicular distance", 1.0)]),
                ],
                out_dir / "states.png",
                title="usv-waypoints-7 (000 figs. 19-20)",
            ),
        ]


# -- UUV-based planning -----------------------------------------------------------------------------------------


class ProfileConfig(StrictModel):
    """The UUV plan of 000 table 3."""

    speed_mps: float = Field(4.0, gt=0, le=10, description="UUV speed, m/s")
    turn_radius_m: float = Field(40.0, gt=0, le=1e4, description="radius of the half turns, m")
    leg_m: float = Field(200.0, gt=0, le=1e5, description="length of the straight legs, m")
    psi0_deg: float = Field(45.0, ge=-360, le=360, description="heading of the first leg, deg")


class TowConfig(StrictModel):
    cable_length_m: float = Field(30.0, gt=0, le=1e4, description="cable length L, m")
    waypoint_spacing_s: float = Field(
        5.0, gt=0, le=1e3, description="time between USV waypoints sampled from the plan, s"
    )


class StartPose(StrictModel):
    """Where the USV (and the UUV, aligned a cable length behind it) start, relative to the UUV plan's start."""

    behind_m: float = Field(
        150.0, ge=-1e4, le=1e4, description="distance behind the plan's start along its first leg, m"
    )
    port_m: float = Field(80.0, ge=-1e4, le=1e4, description="distance to port (left) of the first leg's line, m")
    heading_deg: float = Field(90.0, ge=-360, le=360, description="initial heading of USV and UUV, deg")
    speed_mps: float = Field(0.0, ge=0, le=16, description="initial USV speed, m/s")


class ProfilePlanConfig(ClosedLoopConfig):
    guidance: GuidanceConfig = GuidanceConfig()
    profile: ProfileConfig = ProfileConfig()
    tow: TowConfig = TowConfig()
    start: StartPose = StartPose()


def _plan(cfg):
    from ..guidance.towed_planning import plan_usv, table3_profile, waypoints_from_plan

    p = cfg.profile
    prof = table3_profile(p.speed_mps, p.turn_radius_m, p.leg_m, p.psi0_deg)
    plan = plan_usv(prof, cfg.tow.cable_length_m)
    wp, sp = waypoints_from_plan(plan, cfg.tow.waypoint_spacing_s)
    return prof, plan, wp, sp


class UUVProfilePlan(Scenario):
    frame = "columns"  # summary and plots read columns only (oceangnc.io.frame)
    name = "uuv-profile-plan"
    summary = "USV planned from the towed UUV's plan (000 table 3, eq. 32-34), LOS or hybrid guidance (figs. 22-26)"
    Config = ProfilePlanConfig
    defaults = {"sim": {"duration": 300.0, "dt": 0.01, "log_rate": 10.0}}

    def build(self, cfg, rng):
        from ..models.towed_trailer import TowedTrailer

        prof, plan, wp, sp = _plan(cfg)
        st = cfg.start
        a = float(prof.psi[0])
        # start pose: behind the USV plan's start along the first leg and to port, UUV aligned behind the USV
        x0 = plan.x[0] - st.behind_m * math.cos(a) + st.port_m * math.sin(a)
        y0 = plan.y[0] - st.behind_m * math.sin(a) - st.port_m * math.cos(a)
        usv = cfg.usv.model_copy(
            update={"x0": float(x0), "y0": float(y0), "psi0_deg": st.heading_deg, "u0": st.speed_mps}
        )
        cfg_u = cfg.model_copy(update={"usv": usv})
        g = waypoint_guidance(cfg.guidance, wp, speeds=sp)
        plants = [FirstOrderUSV(usv), TowedTrailer(cfg.tow.cable_length_m, math.radians(st.heading_deg))]
        return Simulation(plants, closed_loop_blocks(cfg_u, [g]), cfg.sim.dt, 1.0 / cfg.sim.log_rate, rng)

    def summarize(self, df, cfg) -> dict:
        from ..guidance.los import distance_to_polyline

        prof, plan, wp, sp = _plan(cfg)
        a = float(prof.psi[0])
        c, s = math.cos(a), math.sin(a)

        def joined(body, px, py):
            # samples from the moment the body comes abreast of its plan's start (along-track >= 0)
            x, y = df[f"{body}.x"].to_numpy(), df[f"{body}.y"].to_numpy()
            k = np.nonzero(c * (x - px) + s * (y - py) >= 0.0)[0]
            k0 = int(k[0]) if k.size else x.size - 1
            return x[k0:], y[k0:], float(df["t"].iloc[k0])

        ux, uy, tu = joined("uuv", prof.x[0], prof.y[0])
        sx, sy, ts = joined("usv", plan.x[0], plan.y[0])
        eu = distance_to_polyline(ux, uy, prof.x, prof.y)
        es = distance_to_polyline(sx, sy, plan.x, plan.y)
        return {
            "uuv.join_time_s": tu,
            "usv.join_time_s": ts,
            "uuv.path_error_rms_m": float(np.sqrt(np.mean(eu**2))),
            "uuv.path_error_max_m": float(np.max(eu)),
            "usv.path_error_rms_m": float(np.sqrt(np.mean(es**2))),
            "usv.path_error_max_m": float(np.max(es)),
            "plan.waypoints": float(len(wp)),
            "plan.phi_max_deg": float(np.max(np.abs(plan.phi)) * RAD2DEG),
            "plan.usv_speed_max_mps": float(np.max(plan.u)),
        }

    def plot(self, df, cfg, out_dir: Path) -> list[Path]:
        import matplotlib.pyplot as plt

        from ..io.plots import _save

        out_dir = Path(out_dir)
        prof, plan, wp, sp = _plan(cfg)
        paths = []
        fig, axes = plt.subplots(2, 1, figsize=(8, 5.5), sharex=True)
        axes[0].plot(prof.t, prof.u, label="UUV profile")
        axes[0].plot(plan.t, plan.u, label="USV plan (eq. 34)")
        axes[0].set_ylabel("speed [m/s]")
        axes[1].plot(prof.t, np.degrees(prof.psi), label="UUV profile")
        axes[1].plot(plan.t, np.degrees(plan.psi), label="USV plan (eq. 33)")
        axes[1].plot(plan.t, np.degrees(plan.phi), label="phi_d (eq. 32)")
        axes[1].set_ylabel("heading [deg]")
        axes[1].set_xlabel("time t [s]")
        for a in axes:
            a.grid(True, alpha=0.3)
            a.legend(fontsize=7)
        axes[0].set_title("USV speed and heading planned from the UUV profile (000 figs. 22-23)")
        paths.append(_save(fig, out_dir / "plan.png"))

        def extra(ax):
            ax.plot(prof.y, prof.x, "g-", lw=2, alpha=0.5, label="UUV plan")
            ax.plot(plan.y, plan.x, "b-", lw=2, alpha=0.3, label="USV plan")

        mode = cfg.guidance.mode
        fig_no = "25" if mode == "los" else "26"
        paths.append(
            plot_track(
                df,
                ["usv", "uuv"],
                out_dir / "paths.png",
                waypoints=None,
                extra=extra,
                title=f"uuv-profile-plan, {mode} guidance (000 figs. 24, {fig_no})",
            )
        )
        return paths


SCENARIOS = [AutopilotHeading(), AutopilotSpeed(), USVWaypoints7(), UUVProfilePlan()]
