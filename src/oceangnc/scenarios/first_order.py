"""Scenarios of document 000: trials for identification, pole-placed autopilots, waypoints, UUV-based planning.

* ``trials``: straight-run (thrust step from rest) and turning (10 deg rudder step) trials and ITTC
  zig-zags generated from a model (``vehicle = "usv-first-order"`` or ``"usv-3dof"``, the 3-DOF USV of
  :mod:`oceangnc.models.usv`), one trial after another in one log with ``trial.id`` / ``trial.kind``
  and the measured signals ``trial.*`` (optionally noisy) that ``oceangnc identify first-order``
  reads by default; the true K, T of each trial are logged (``trial.true_k``, ``trial.true_t``) and
  the summary identifies the log and reports the errors.
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
from typing import Literal

import numpy as np
from pydantic import Field, model_validator

from ..control.pole_placement import HeadingAutopilot, SpeedAutopilot, predicted_overshoot
from ..control.actuators import RudderEngineBlock, USVThrusterBlock
from ..identification.trials import TrialNoise, TrialSensors, ZigZag
from ..core.rotations import wrap
from ..core.blocks import Block, FunctionBlock
from ..core.clock import Simulation
from ..errors import ConfigError
from ..io.config import ScenarioConfig, StrictModel
from ..io.plots import plot_signals, plot_track
from ..models.first_order import FirstOrderConfig, FirstOrderUSV
from ..models.usv import USVConfig
from ..units import KGF
from .base import Scenario

RAD2DEG = 180.0 / math.pi


# -- shared config ----------------------------------------------------------------------------------------

class HeadingDesign(StrictModel):
    """Pole placement of the heading PD (000 eq. 26-27)."""

    zeta: float = Field(0.7, gt=0, le=2, description="closed-loop damping ratio, -")
    wn: float = Field(0.6, gt=0, le=10, description="closed-loop natural frequency, rad/s")


class SpeedDesign(StrictModel):
    """Pole placement of the speed P controller (000 eq. 31)."""

    zeta: float = Field(1.0, gt=0, le=2, description="damping ratio used in eq. 31, -")
    wn: float = Field(2.0, gt=0, le=20, description="natural frequency used in eq. 31 (pole at 2 zeta w_n), rad/s")


class ClosedLoopConfig(ScenarioConfig):
    """The first-order USV with both autopilots."""

    usv: FirstOrderConfig = FirstOrderConfig()
    heading: HeadingDesign = HeadingDesign()
    speed_control: SpeedDesign = SpeedDesign()
    control_rate: float = Field(20.0, gt=0, le=1000, description="autopilot and actuator rate, Hz")


def check_design(cfg) -> None:
    """Refuse a design with 2 zeta w_n T <= 1 anywhere in the trial ranges (000 eq. 26/31), naming the key."""
    from ..control.pole_placement import heading_gains, speed_gain

    u = cfg.usv
    for sec, law, fn, speeds in (("heading", ("K_r", "T_r"), heading_gains, (u.turn_lo_mps, u.turn_hi_mps)),
                                 ("speed_control", ("K_v", "T_v"), speed_gain, (u.straight_lo_mps, u.straight_hi_mps))):
        d = getattr(cfg, sec)
        for sp in speeds:
            c = u.coefficients(sp)
            try:
                fn(c[law[0]], c[law[1]], d.zeta, d.wn)
            except ConfigError as e:
                raise ConfigError(f"config error: {sec}.wn = {d.wn:g} / {sec}.zeta = {d.zeta:g}: at {sp:g} m/s "
                                  f"{str(e).split(': ', 1)[1]}") from None


def _nomoto(cfg):
    def f(u):
        c = cfg.usv.coefficients(u)
        return c["K_r"], c["T_r"]
    return f


def _speedlaw(cfg):
    def f(u):
        c = cfg.usv.coefficients(u)
        return c["K_v"], c["T_v"]
    return f


def closed_loop_blocks(cfg, guidance_blocks, rpm_open_loop: float | None = None):
    """Guidance/command blocks, heading PD, speed P (or a fixed rpm) and the actuators."""
    check_design(cfg)
    h = 1.0 / cfg.control_rate
    blocks = list(guidance_blocks)
    blocks.append(HeadingAutopilot(_nomoto(cfg), cfg.heading.zeta, cfg.heading.wn, h))
    if rpm_open_loop is None:
        blocks.append(SpeedAutopilot(_speedlaw(cfg), cfg.speed_control.zeta, cfg.speed_control.wn, h))
    else:
        n = float(rpm_open_loop)
        blocks.append(FunctionBlock("engine", h, lambda t, bus: bus.__setitem__("usv.rpm_cmd", n),
                                    inputs={}, outputs={"usv.rpm_cmd": "rpm"}))
    blocks.append(RudderEngineBlock(cfg.usv, h))
    return blocks


def _settling_time(t, y, target, band, t0):
    out = np.nonzero(np.abs(y - target) > band)[0]
    if out.size == 0:
        return 0.0
    if out[-1] == y.size - 1:
        return float("nan")
    return float(t[out[-1] + 1] - t0)


# -- autopilots -------------------------------------------------------------------------------------------

class HeadingCommand(StrictModel):
    heading_deg: float = Field(100.0, ge=-180, le=180, description="commanded heading after the step, deg")
    step_time_s: float = Field(1.0, ge=0, le=1e4, description="time of the heading step, s")
    speed_mps: float = Field(6.0, ge=0.5, le=20, description="speed held by the trim rpm during the manoeuvre, m/s")


class AutopilotHeadingConfig(ClosedLoopConfig):
    command: HeadingCommand = HeadingCommand()


class AutopilotHeading(Scenario):
    name = "autopilot-heading"
    summary = "Pole-placed heading PD on the first-order USV: 0 -> 100 deg (000 fig. 17)"
    Config = AutopilotHeadingConfig
    defaults = {"sim": {"duration": 40.0, "dt": 0.01}}

    def build(self, cfg, rng):
        c = cfg.command
        usv = cfg.usv.model_copy(update={"u0": c.speed_mps})
        cfg_u = cfg.model_copy(update={"usv": usv})
        psi_c = math.radians(c.heading_deg)
        cmd = FunctionBlock("command", 1.0 / cfg.control_rate,
                            lambda t, bus: bus.__setitem__("usv.psi_cmd", psi_c if t >= c.step_time_s - 1e-9 else 0.0),
                            inputs={}, outputs={"usv.psi_cmd": "rad"})
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
        return {"heading.overshoot_pct": 100.0 * max(over, 0.0),
                "heading.predicted_overshoot_pct": 100.0 * predicted_overshoot(cfg.heading.zeta),
                "heading.settling_time_s": ts,
                "heading.final_error_deg": math.degrees(target - psi[-1]),
                "heading.rudder_saturated_frac": sat}

    def plot(self, df, cfg, out_dir: Path) -> list[Path]:
        out_dir = Path(out_dir)
        return [plot_signals(df, [
            ("heading [deg]", [("usv.psi_cmd", "command", RAD2DEG), ("usv.psi", "psi", RAD2DEG)]),
            ("yaw rate [deg/s]", [("usv.r", "r", RAD2DEG)]),
            ("rudder [deg]", [("usv.delta_s", "delta_S", RAD2DEG)]),
        ], out_dir / "heading.png", title="autopilot-heading (000 fig. 17)")]


class SpeedCommand(StrictModel):
    speed_mps: float = Field(5.0, ge=0.5, le=20, description="commanded speed after the step, m/s")
    step_time_s: float = Field(1.0, ge=0, le=1e4, description="time of the speed step, s")
    window_s: float = Field(10.0, gt=0, le=1e4, description="final window for the steady error, s")


class AutopilotSpeedConfig(ClosedLoopConfig):
    command: SpeedCommand = SpeedCommand()


class AutopilotSpeed(Scenario):
    name = "autopilot-speed"
    summary = "Pole-placed speed P on the first-order USV: 0 -> 5 m/s, steady error of P control (000 fig. 18)"
    Config = AutopilotSpeedConfig
    defaults = {"sim": {"duration": 40.0, "dt": 0.01}}

    def build(self, cfg, rng):
        c = cfg.command
        usv = cfg.usv.model_copy(update={"u0": 0.0})

        def cmd(t, bus):
            bus["usv.u_cmd"] = c.speed_mps if t >= c.step_time_s - 1e-9 else 0.0
            bus["usv.psi_cmd"] = 0.0

        blocks = closed_loop_blocks(cfg, [FunctionBlock("command", 1.0 / cfg.control_rate, cmd, inputs={},
                                                        outputs={"usv.u_cmd": "m/s", "usv.psi_cmd": "rad"})])
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
        return {"speed.steady_error_mps": c.speed_mps - fin, "speed.rise_time_s": rise,
                "speed.final_mps": fin, "speed.predicted_steady_error_mps": c.speed_mps / a,
                "speed.rpm_final": float(df["usv.rpm"].iloc[-1])}

    def plot(self, df, cfg, out_dir: Path) -> list[Path]:
        out_dir = Path(out_dir)
        return [plot_signals(df, [
            ("speed [m/s]", [("usv.u_cmd", "command", 1.0), ("usv.u", "u", 1.0)]),
            ("shaft speed [rpm]", [("usv.rpm", "delta_T", 1.0)]),
        ], out_dir / "speed.png", title="autopilot-speed (000 fig. 18)")]


# -- waypoints ------------------------------------------------------------------------------------------------

class GuidanceConfig(StrictModel):
    """LOS / hybrid guidance (000 table 1)."""

    mode: Literal["los", "hybrid"] = "hybrid"
    R: float = Field(25.0, gt=0, le=1e4, description="LOS circle radius R (and band unit of table 1), m")
    R1: float | None = Field(None, gt=0, le=1e4, description="circle radius in 0.5R < d <= R (> R; default 1.25 R), m")
    R2: float | None = Field(None, gt=0, le=1e4, description="circle radius in R < d <= 2R (> 2R; default 2.5 R), m")
    accept_radius: float | None = Field(None, gt=0, le=1e4, description="waypoint acceptance radius (default R), m")
    rate: float = Field(10.0, gt=0, le=100, description="guidance update rate, Hz")

    @model_validator(mode="after")
    def _radii(self):
        if self.R1 is not None and not self.R1 > self.R:
            raise ValueError(f"R1 = {self.R1} must be > R = {self.R} (the circle must reach the leg)")
        if self.R2 is not None and not self.R2 > 2 * self.R:
            raise ValueError(f"R2 = {self.R2} must be > 2R = {2 * self.R}")
        return self


def _guidance(g: GuidanceConfig, waypoints, speed=5.0, speeds=None, stop=True):
    from ..guidance.los import WaypointGuidance

    return WaypointGuidance(waypoints, g.mode, g.R, g.R1, g.R2, g.accept_radius, speed, speeds, 1.0 / g.rate,
                            stop_at_end=stop)


_WP7 = [[150.0, 400.0], [600.0, 400.0], [600.0, 900.0], [250.0, 1250.0], [250.0, 1700.0], [700.0, 2000.0],
        [1000.0, 1700.0]]


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
    name = "usv-waypoints-7"
    summary = "First-order USV through seven waypoints from heading 90 deg, rest; hybrid/LOS guidance (000 fig. 21)"
    Config = Waypoints7Config
    defaults = {"sim": {"duration": 900.0, "dt": 0.01, "log_rate": 5.0}, "usv": {"psi0_deg": 90.0, "u0": 0.0}}

    def build(self, cfg, rng):
        g = _guidance(cfg.guidance, cfg.waypoints, cfg.speed_mps)
        return Simulation([FirstOrderUSV(cfg.usv)], closed_loop_blocks(cfg, [g]), cfg.sim.dt,
                          1.0 / cfg.sim.log_rate, rng)

    def summarize(self, df, cfg) -> dict:
        from ..guidance.los import distance_to_polyline

        wp = np.asarray(cfg.waypoints, float)
        x, y = df["usv.x"].to_numpy(), df["usv.y"].to_numpy()
        # cross-track error once on the route (after first reaching within R of the first leg)
        d = distance_to_polyline(x, y, wp[:, 0], wp[:, 1])
        on = np.nonzero(d < cfg.guidance.R)[0]
        dd = d[on[0]:] if on.size else d
        reached = [float(np.min(np.hypot(x - a, y - b))) for a, b in wp]
        return {"usv.path_error_rms_m": float(np.sqrt(np.mean(dd ** 2))), "usv.path_error_max_m": float(np.max(dd)),
                "usv.join_time_s": float(df["t"].iloc[on[0]]) if on.size else float("nan"),
                "usv.waypoint_miss_max_m": max(reached), "usv.final_leg": float(df["guidance.leg"].iloc[-1])}

    def plot(self, df, cfg, out_dir: Path) -> list[Path]:
        out_dir = Path(out_dir)
        return [plot_track(df, ["usv"], out_dir / "track.png", waypoints=cfg.waypoints,
                           title=f"usv-waypoints-7, {cfg.guidance.mode} (000 fig. 21)"),
                plot_signals(df, [
                    ("speed [m/s]", [("usv.u_cmd", "command", 1.0), ("usv.u", "u", 1.0)]),
                    ("heading [deg]", [("usv.psi_cmd", "command", RAD2DEG), ("usv.psi", "psi", RAD2DEG)]),
                    ("d [m]", [("guidance.d", "perpendicular distance", 1.0)]),
                ], out_dir / "states.png", title="usv-waypoints-7 (000 figs. 19-20)")]


# -- UUV-based planning -----------------------------------------------------------------------------------------

class ProfileConfig(StrictModel):
    """The UUV plan of 000 table 3."""

    speed_mps: float = Field(4.0, gt=0, le=10, description="UUV speed, m/s")
    turn_radius_m: float = Field(40.0, gt=0, le=1e4, description="radius of the half turns, m")
    leg_m: float = Field(200.0, gt=0, le=1e5, description="length of the straight legs, m")
    psi0_deg: float = Field(45.0, ge=-360, le=360, description="heading of the first leg, deg")


class TowConfig(StrictModel):
    cable_length_m: float = Field(30.0, gt=0, le=1e4, description="cable length L, m")
    waypoint_spacing_s: float = Field(5.0, gt=0, le=1e3, description="time between USV waypoints sampled from the plan, s")


class StartPose(StrictModel):
    """Where the USV (and the UUV, aligned a cable length behind it) start, relative to the UUV plan's start."""

    behind_m: float = Field(150.0, ge=-1e4, le=1e4, description="distance behind the plan's start along its first leg, m")
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
        usv = cfg.usv.model_copy(update={"x0": float(x0), "y0": float(y0), "psi0_deg": st.heading_deg,
                                         "u0": st.speed_mps})
        cfg_u = cfg.model_copy(update={"usv": usv})
        g = _guidance(cfg.guidance, wp, speeds=sp)
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
        return {"uuv.join_time_s": tu, "usv.join_time_s": ts,"uuv.path_error_rms_m": float(np.sqrt(np.mean(eu ** 2))), "uuv.path_error_max_m": float(np.max(eu)),
                "usv.path_error_rms_m": float(np.sqrt(np.mean(es ** 2))), "usv.path_error_max_m": float(np.max(es)),
                "plan.waypoints": float(len(wp)), "plan.phi_max_deg": float(np.max(np.abs(plan.phi)) * RAD2DEG),
                "plan.usv_speed_max_mps": float(np.max(plan.u))}

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
        paths.append(plot_track(df, ["usv", "uuv"], out_dir / "paths.png", waypoints=None, extra=extra,
                                title=f"uuv-profile-plan, {mode} guidance (000 figs. 24, {fig_no})"))
        return paths


# -- trials -------------------------------------------------------------------------------------------------------

class TrialsSection(StrictModel):
    """Which trials to run (speeds for usv-first-order in m/s; the 3-DOF USV uses ``*_3dof`` ones)."""

    straight_speeds_mps: list[float] = Field([5.0, 6.4, 7.8, 9.2, 10.6, 12.0, 13.4, 14.8, 16.0], min_length=1,
                                             description="final speeds of the straight runs (from rest), m/s")
    turn_speeds_mps: list[float] = Field([4.2, 5.1, 6.0, 6.9, 7.8, 8.6], min_length=1,
                                         description="approach speeds of the turning trials, m/s")
    steer_deg: float = Field(10.0, gt=0, le=35, description="rudder step of the turning trials, deg")
    zigzag_deg: list[float] = Field([10.0, 20.0], description="ITTC zig-zag amplitudes (10 -> 10/10), deg")
    zigzag_speed_mps: float = Field(6.0, gt=0, le=20, description="approach speed of the zig-zags, m/s")
    straight_duration_s: float = Field(200.0, gt=5, le=1e4, description="length of a straight run, s")
    turn_duration_s: float = Field(40.0, gt=5, le=1e4, description="length of a turning trial, s")
    zigzag_duration_s: float = Field(120.0, gt=5, le=1e4, description="length of a zig-zag, s")
    step_time_s: float = Field(5.0, ge=0.5, le=100, description="time of the input step in each trial, s")
    straight_speeds_3dof_mps: list[float] = Field([0.3, 0.45, 0.6, 0.75, 0.9], min_length=1,
                                                  description="straight-run speeds of the 3-DOF USV, m/s")
    turn_speeds_3dof_mps: list[float] = Field([0.4, 0.6, 0.8], min_length=1,
                                              description="turning-trial speeds of the 3-DOF USV, m/s")
    steer_3dof_kgf: float = Field(2.0, gt=0, le=15, description="differential thrust step (port +, starboard -) of the 3-DOF USV, kgf")


class TrialsConfig(ScenarioConfig):
    vehicle: Literal["usv-first-order", "usv-3dof"] = "usv-first-order"
    usv: FirstOrderConfig = FirstOrderConfig()
    usv3dof: USVConfig = USVConfig()
    trials: TrialsSection = TrialsSection()
    noise: TrialNoise = TrialNoise()
    control_rate: float = Field(20.0, gt=0, le=1000, description="command rate, Hz")


class _OffsetLog:
    """Forwards rows to the run's log with a time offset and the trial's constant columns."""

    def __init__(self, log, t0, extra):
        self.log, self.t0, self.extra = log, t0, extra

    def append(self, t, row):
        r = dict(row)
        r.update(self.extra)
        self.log.append(self.t0 + t, r)


def _nomoto_3dof(c, U):
    """First-order Nomoto (K, T = T1 + T2 - T3) of the linearised 3-DOF USV at speed U, steer in N."""
    A = np.array([[-c.d22 / c.m22, -c.m11 * U / c.m22], [-(c.m22 - c.m11) * U / c.m33, -c.d33 / c.m33]])
    b = c.thruster_spacing / c.m33  # N = (Tp - Ts) B / 2 = steer * B
    lam = np.linalg.eigvals(A)
    T1, T2 = -1.0 / lam.real
    T3 = c.m22 / c.d22
    K = float(np.linalg.solve(-A, np.array([0.0, b]))[1])
    return K, float(T1 + T2 - T3)


class Trials(Scenario):
    name = "trials"
    summary = "Straight/turning/zig-zag trials from a model, logged for 'oceangnc identify first-order' (000 sec. 2.2)"
    Config = TrialsConfig
    defaults = {"sim": {"dt": 0.05, "log_rate": 20.0}, "usv": {"schedule": "operating"}}

    def _trial_list(self, cfg):
        tr = cfg.trials
        out = []
        if cfg.vehicle == "usv-first-order":
            out += [("straight", u) for u in tr.straight_speeds_mps]
            out += [("turn", u) for u in tr.turn_speeds_mps]
            out += [("zigzag", a) for a in tr.zigzag_deg]
        else:
            out += [("straight", u) for u in tr.straight_speeds_3dof_mps]
            out += [("turn", u) for u in tr.turn_speeds_3dof_mps]
            out += [("zigzag", a) for a in tr.zigzag_deg]
        return out

    def _build_one(self, cfg, kind, val, rng):
        tr = cfg.trials
        h = 1.0 / cfg.control_rate
        ts = tr.step_time_s
        if cfg.vehicle == "usv-first-order":
            m = cfg.usv
            U = val if kind != "zigzag" else tr.zigzag_speed_mps
            n = m.trim_rpm(U)
            if n > m.rpm_max:
                raise ConfigError(f"trials: {U:g} m/s needs {n:.0f} rpm, above usv.rpm_max = {m.rpm_max:g} rpm")
            co = m.coefficients(U)
            usv = m.model_copy(update={"u0": 0.0 if kind == "straight" else U, "psi0_deg": 0.0})
            plant = FirstOrderUSV(usv)
            d = math.radians(tr.steer_deg)
            blocks = [FunctionBlock("operating_speed", h, lambda t, bus: bus.__setitem__("usv.u_op", U),
                                    inputs={}, outputs={"usv.u_op": "m/s"})]
            rudder_engine = {"usv.rpm_cmd": "rpm", "usv.delta_s_cmd": "rad"}
            if kind == "straight":
                def cmd(t, bus):
                    bus["usv.rpm_cmd"] = n if t >= ts - 1e-9 else 0.0
                    bus["usv.delta_s_cmd"] = 0.0
                blocks.append(FunctionBlock("command", h, cmd, inputs={}, outputs=rudder_engine))
                truth = (co["K_v"], co["T_v"])
            elif kind == "turn":
                def cmd(t, bus):
                    bus["usv.rpm_cmd"] = n
                    bus["usv.delta_s_cmd"] = d if t >= ts - 1e-9 else 0.0
                blocks.append(FunctionBlock("command", h, cmd, inputs={}, outputs=rudder_engine))
                truth = (co["K_r"], co["T_r"])
            else:
                a = math.radians(val)
                blocks += [FunctionBlock("command", h, lambda t, bus: bus.__setitem__("usv.rpm_cmd", n),
                                         inputs={}, outputs={"usv.rpm_cmd": "rpm"}),
                           ZigZag(a, a, ts, h, "usv.delta_s_cmd", unit="rad")]
                truth = (co["K_r"], co["T_r"])
            blocks.append(RudderEngineBlock(usv, h))
            blocks.append(TrialSensors(cfg.noise, h, lambda bus: bus["usv.delta_s"], lambda bus: bus["usv.rpm"],
                                        inputs={"usv.delta_s": "rad", "usv.rpm": "rpm"}))
        else:
            from ..models.usv import USVPlant

            c = cfg.usv3dof
            U = val if kind != "zigzag" else tr.turn_speeds_3dof_mps[len(tr.turn_speeds_3dof_mps) // 2]
            T0 = c.d11 * U / 2.0
            s = tr.steer_3dof_kgf * KGF
            c0 = c.model_copy(update={"u0": 0.0 if kind == "straight" else U})
            plant = USVPlant(c0)

            def put(bus, thrust, steer):
                bus["usv.thrust_port_cmd"] = thrust + steer
                bus["usv.thrust_stbd_cmd"] = thrust - steer

            thrusts = {"usv.thrust_port_cmd": "N", "usv.thrust_stbd_cmd": "N"}
            if kind == "straight":
                blocks = [FunctionBlock("command", h, lambda t, bus: put(bus, T0 if t >= ts - 1e-9 else 0.0, 0.0),
                                        inputs={}, outputs=thrusts)]
                truth = (2.0 / c.d11, c.m11 / c.d11)
            elif kind == "turn":
                blocks = [FunctionBlock("command", h, lambda t, bus: put(bus, T0, s if t >= ts - 1e-9 else 0.0),
                                        inputs={}, outputs=thrusts)]
                truth = _nomoto_3dof(c, U)
            else:
                zz = ZigZag(s, math.radians(val), ts, h, "_steer", unit="N")
                blocks = [zz, FunctionBlock("command", h, lambda t, bus: put(bus, T0, bus.get("_steer", 0.0)),
                                            inputs={"_steer": "N"}, outputs=thrusts)]
                truth = _nomoto_3dof(c, U)
            blocks.append(USVThrusterBlock(c0, h))
            blocks.append(TrialSensors(cfg.noise, h,
                                        lambda bus: 0.5 * (bus["usv.thrust_port"] - bus["usv.thrust_stbd"]),
                                        lambda bus: 0.5 * (bus["usv.thrust_port"] + bus["usv.thrust_stbd"]),
                                        inputs={"usv.thrust_port": "N", "usv.thrust_stbd": "N"}))
        sim = Simulation([plant], blocks, cfg.sim.dt, 1.0 / cfg.sim.log_rate, rng)
        dur = {"straight": tr.straight_duration_s, "turn": tr.turn_duration_s, "zigzag": tr.zigzag_duration_s}[kind]
        return sim, dur, truth

    def run(self, cfg, ctx) -> dict:
        import warnings

        t0 = 0.0
        codes = {"straight": 0.0, "turn": 1.0, "zigzag": 2.0}
        rngs = ctx.rng.spawn(len(self._trial_list(cfg)))
        with warnings.catch_warnings():
            warnings.simplefilter("ignore", RuntimeWarning)  # trials from rest leave the table-2 range on purpose
            for i, ((kind, val), g) in enumerate(zip(self._trial_list(cfg), rngs)):
                sim, dur, truth = self._build_one(cfg, kind, val, g)
                log = _OffsetLog(ctx.log, t0, {"trial.id": float(i), "trial.kind": codes[kind],
                                               "trial.true_k": truth[0], "trial.true_t": truth[1]})
                sim.run(dur, log=log)
                t0 += dur + 10.0
        ctx.info["t_end"] = t0
        return {"trials.count": float(len(self._trial_list(cfg)))}

    def summarize(self, df, cfg) -> dict:
        from ..errors import InputError
        from ..identification.first_order import Columns, identify_log

        try:
            rep = identify_log(df, Columns(), n_mc=50, seed=cfg.sim.seed)
        except InputError as e:  # the log is still good; say why it cannot be identified as it is
            return {"ident.error": str(e)}
        out: dict = {}
        truth = df.groupby("trial.id")[["trial.true_k", "trial.true_t"]].first()
        for kind, names in (("straight", ("K_v", "T_v")), ("turn", ("K_r", "T_r"))):
            st = [s for s in rep.steps if s.kind == kind]
            if not st:
                continue
            ek = [abs(s.K / truth.loc[s.trial, "trial.true_k"] - 1) * 100 for s in st]
            et = [abs(s.T / truth.loc[s.trial, "trial.true_t"] - 1) * 100 for s in st]
            out[f"ident.{names[0]}_max_err_pct"] = max(ek)
            out[f"ident.{names[1]}_max_err_pct"] = max(et)
            out[f"ident.{names[0]}_max_rel_std_pct"] = max(100 * s.K_std / abs(s.K) for s in st)
            out[f"ident.{names[1]}_max_rel_std_pct"] = max(100 * s.T_std / abs(s.T) for s in st)
        for k, f in rep.fits.items():
            out[f"fit.{k}_slope"] = f.slope
            out[f"fit.{k}_intercept"] = f.intercept
            out[f"fit.{k}_residual_rms"] = f.residual_rms
        zz = [a for k, a in self._trial_list(cfg) if k == "zigzag"]
        for z, amp in zip(rep.zigzags, zz):
            tk = truth.loc[z.trial]
            tag = f"{amp:.0f}_{amp:.0f}"
            out[f"zigzag.{tag}.K_r_err_pct"] = abs(z.K / tk["trial.true_k"] - 1) * 100
            out[f"zigzag.{tag}.T_r_err_pct"] = abs(z.T / tk["trial.true_t"] - 1) * 100
        return out

    def plot(self, df, cfg, out_dir: Path) -> list[Path]:
        import matplotlib.pyplot as plt

        from ..identification.first_order import Columns, identify_log
        from ..io.plots import _save

        from ..errors import InputError

        try:
            rep = identify_log(df, Columns(), n_mc=20)
        except InputError:
            return []
        truth = df.groupby("trial.id")[["trial.true_k", "trial.true_t"]].first()
        fig, axes = plt.subplots(2, 2, figsize=(9, 6))
        for col, (kind, names) in enumerate((("straight", ("K_v", "T_v")), ("turn", ("K_r", "T_r")))):
            st = [s for s in rep.steps if s.kind == kind]
            if not st:
                continue
            u = np.array([s.speed for s in st])
            for row, attr in enumerate(("K", "T")):
                ax = axes[row, col]
                v = np.array([getattr(s, attr) for s in st])
                e = np.array([getattr(s, attr + "_std") for s in st])
                tv = np.array([truth.loc[s.trial, "trial.true_k" if attr == "K" else "trial.true_t"] for s in st])
                ax.errorbar(u, v, yerr=e, fmt="o", label="identified (eq. 12-21)")
                ax.plot(u, tv, "kx", label="model truth")
                f = rep.fits.get(names[row])
                if f is not None:
                    uu = np.linspace(u.min(), u.max(), 10)
                    ax.plot(uu, f.slope * uu + f.intercept, "r-", label=f"fit {f.slope:.4g} u + {f.intercept:.4g}")
                ax.set_xlabel("speed u [m/s]")
                ax.set_ylabel(names[row])
                ax.grid(True, alpha=0.3)
                ax.legend(fontsize=7)
        axes[0, 0].set_title("coefficients vs speed (000 figs. 11-14, table 2)")
        return [_save(fig, Path(out_dir) / "coefficients.png")]


SCENARIOS = [Trials(), AutopilotHeading(), AutopilotSpeed(), USVWaypoints7(), UUVProfilePlan()]
