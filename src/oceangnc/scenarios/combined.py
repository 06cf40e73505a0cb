"""Combined USV-cable-UUV under guidance and control: document 003 ch. 4 and 6.2.

* ``waypoints-square`` (003 fig. 4-6): waypoints (0,0) (50,0) (50,50) (0,50); the UUV follows the
  relative angle only (``formation.mode = "relative-angle"``, fig. 4-6 (a)) or the relative angle
  plus the heading to the USV outside R (``"relative-angle-plus-heading"``, fig. 4-6 (b)).
* ``combined-survey`` (003 figs. 4-7 to 4-15; the flagship): 3 m cable, waypoints (0,0) (10,10)
  (20,5), surge target 0.6 m/s, UUV starting 3 m deep; ``control.uuv.kind = "pid" | "backstepping"``
  or any registered kind (a user's block loaded with ``--plugin``; ``control.uuv = "pid"`` also works);
  ``control.usv`` is a slot of the same kind (default ``pid``, its gains as keys: ``control.usv.speed_kp``).
* ``field-test`` (003 ch. 6.2, figs. 6-13 to 6-19): waypoints (50,0) (50,-50) (0,-50) (0,0), USV
  target 1.3 m/s, PID, sensors on (GPS, AHRS, USBL, depth sensor), guidance and control on the
  measured signals; the vehicle as built: the UUV on the three-point bridle of 003 fig. 5-6
  (``cable.attachment = "bridle"``, apex 1.25 m above the CB, 1.692 m of cable: the UUV hangs at 3 m), held
  0.4 m astern (``formation.l_d``); both fitted to 003's pitch, depth and distance (docs/validation/bridle_fit.py).

The chain each control period (blocks fire in this order): environment -> sensors (if on) -> USBL
dropout hold and navigation -> pure pursuit (USV) and leader-follower (UUV) guidance -> USV loops
and UUV controller -> thruster blocks (which honour ``_estop``). The run ends when the last
waypoint is reached (``_stop``); a ``guidance.acceptance`` below the USV's minimum turning radius is refused
(:func:`oceangnc.guidance.pure_pursuit.check_acceptance`: the last waypoint could be circled for
ever). With ``console.mode == "remote"`` on the bus the USV follows the
joystick (see :mod:`oceangnc.control.usv_control`); the UUV keeps following the USV.

Summary keys: ``usv.waypoints_reached`` (count, the start point included), ``usv.cross_track_rms_m``
(true position to the active leg), ``uuv.rel_distance_mean_m`` / ``uuv.rel_distance_max_m`` (true
horizontal USV-UUV distance), ``uuv.depth_final_m``, ``uuv.heading_error_rms_deg`` (UUV heading
against the target of its active loop), ``usv.heading_error_rms_deg`` (USV heading against the
pure-pursuit target), plus ``usv.waypoints_total``, ``t_end_s``, ``cable.top_tension_max_n`` and,
with sensors, ``usbl.pings_lost`` and ``ahrs.gps_heading_diff_mean_deg``.
"""

from __future__ import annotations

import math
from pathlib import Path
from typing import ClassVar, Literal

import numpy as np
from pydantic import Field, field_validator

from ..control.actuators import USVThrusterBlock, UUVThrusterBlock
from ..control.ardusub import SubDepth
from ..control.backstepping import BacksteppingConfig
from ..control.uuv_control import UUVPIDConfig
from ..control.winch import WinchControlConfig, WinchDepthController
from ..core.caches import cached, compile_ahead
from ..core.clock import Simulation, ahead_jobs
from ..core.registry import BlockChoice, BlockContext, build_block
from ..core.rotations import wrap_array
from ..environment import SeaEnvironmentConfig
from ..errors import ConfigError
from ..guidance.leader_follower import LeaderFollower
from ..guidance.pure_pursuit import (
    PurePursuit,
    check_acceptance,
    look_ahead_distance,
    usv_min_turning_radius,
    uuv_turning_radius_at,
)
from ..io.config import ScenarioConfig, StrictModel
from ..models.cable import CableConfig
from ..models.combined import CombinedPlant
from ..models.usv import USVConfig
from ..models.uuv import UUVConfig
from ..models.winch import WinchConfig
from ..sensors import (
    AHRS,
    GPS,
    USBL,
    AHRSConfig,
    DepthSensor,
    DepthSensorConfig,
    DropoutHold,
    GPSConfig,
    USBLConfig,
)
from ..sensors.navigation import USBLNavigation
from ..units import KGF
from ._combined_plots import plot_3d, plot_jobs, rel_distance  # noqa: F401  (plot_3d: public before)
from ._common import environment_blocks
from .base import Scenario

DEG = 180.0 / math.pi


class GuidanceConfig(StrictModel):
    """Pure-pursuit guidance of the USV (003 ch. 3.1)."""

    waypoints: list[tuple[float, float]] = Field(
        [(0.0, 0.0), (10.0, 10.0), (20.0, 5.0)], min_length=2, description="waypoints (north, east), m"
    )
    look_ahead: float | None = Field(
        None, gt=0, le=1e3, description="look-ahead l (default: 2 R_min from the models, eq. 3.6), m"
    )
    acceptance: float = Field(2.0, gt=0, le=100, description="waypoint acceptance radius, m")
    rate: float = Field(10.0, gt=0, le=100, description="guidance rate, Hz")

    @field_validator("waypoints")
    @classmethod
    def _distinct(cls, wp):
        for i in range(len(wp) - 1):
            if wp[i] == wp[i + 1]:
                raise ValueError(f"waypoints {i} and {i + 1} coincide at {wp[i]}")
        return wp


class FormationConfig(StrictModel):
    """Leader-follower geometry (003 ch. 3.2)."""

    l_d: float = Field(0.5, ge=0, le=50, description="target horizontal range l^d, m")
    lambda_d_deg: float = Field(180.0, ge=90, le=270, description="target bearing lambda^d from the USV's bow, deg")
    R: float = Field(1.0, gt=0, le=100, description="maximum range R before the UUV heads to the USV, m")
    mode: Literal["relative-angle", "relative-angle-plus-heading"] = "relative-angle-plus-heading"


class UUVControllerChoice(BlockChoice):
    """The UUV controller: a registered kind (``pid``, ``backstepping`` or a user's ``family.name``)
    and its parameters; the built-in kinds start from ``control.uuv_pid`` / ``control.backstepping``."""

    family: ClassVar[str] = "uuv"
    role: ClassVar[str | None] = "controller"
    kind: str = Field("pid", description="registered block kind: a name in the uuv family or family.name")


class USVControllerChoice(BlockChoice):
    """The USV controller: a registered kind (``pid``: speed + heading loops, 003 eq. 3.10-3.11, or a
    user's ``family.name``) and its parameters (for ``pid`` the gains of
    :class:`~oceangnc.control.usv_control.USVControlConfig`, e.g. ``control.usv.speed_kp``)."""

    family: ClassVar[str] = "usv"
    role: ClassVar[str | None] = "controller"
    kind: str = Field("pid", description="registered block kind: a name in the usv family or family.name")


class ControlConfig(StrictModel):
    """Controllers and their rate."""

    uuv: UUVControllerChoice = Field(
        UUVControllerChoice(kind="pid"), description="UUV controller: kind = pid | backstepping | a registered kind"
    )
    surge_speed: float = Field(0.6, gt=0, le=5, description="USV surge speed target, m/s")
    rate: float = Field(20.0, gt=0, le=1000, description="control and thruster rate, Hz")
    usv: USVControllerChoice = Field(
        USVControllerChoice(), description="USV controller: kind = pid | a registered kind, and its gains"
    )
    uuv_pid: UUVPIDConfig = UUVPIDConfig()
    backstepping: BacksteppingConfig = BacksteppingConfig()


class SensorChoice(BlockChoice):
    """A further sensor block by registered kind (``sensor.*`` or a user's ``family.name``) and its parameters."""

    family: ClassVar[str] = "sensor"
    role: ClassVar[str | None] = "sensor"


class SensorsConfig(StrictModel):
    """Sensors (003 ch. 6.1, appendix B); when enabled guidance and control use measured signals."""

    enabled: bool = False
    extra: list[SensorChoice] = Field(
        [],
        max_length=20,
        description="further sensor blocks by kind, fired "
        "after the built-in sensors at the control rate (a user's, from --plugin)",
    )
    gps: GPSConfig = GPSConfig()
    usv_ahrs: AHRSConfig = AHRSConfig()
    uuv_ahrs: AHRSConfig = AHRSConfig()
    usbl: USBLConfig = USBLConfig()
    depth: DepthSensorConfig = DepthSensorConfig()


class CombinedConfig(ScenarioConfig):
    usv: USVConfig = USVConfig()
    uuv: UUVConfig = UUVConfig()
    cable: CableConfig = CableConfig()
    environment: SeaEnvironmentConfig = SeaEnvironmentConfig()
    guidance: GuidanceConfig = GuidanceConfig()
    formation: FormationConfig = FormationConfig()
    control: ControlConfig = ControlConfig()
    sensors: SensorsConfig = SensorsConfig()
    winch: WinchConfig = WinchConfig()
    winch_control: WinchControlConfig = WinchControlConfig(target=3.0)


def look_ahead_for(cfg: CombinedConfig) -> tuple[float, float, float]:
    """(l, R_min_usv, R_min_uuv): the look-ahead l = 2 max(R_min) (003 eq. 3.6), from the models.

    USV: :func:`oceangnc.guidance.pure_pursuit.usv_min_turning_radius`; UUV: its turning radius at
    the speed it must hold, the surge target capped at the USV's top speed
    (:func:`oceangnc.guidance.pure_pursuit.uuv_turning_radius_at`).
    """
    top = 2.0 * cfg.usv.max_thrust_kgf * KGF / cfg.usv.d11
    speed = min(cfg.control.surge_speed, top)
    # trimming the models once per machine and inputs (oceangnc.core.caches.cached: no model code loaded at start-up)
    key = [cfg.usv.model_dump(mode="json"), cfg.uuv.model_dump(mode="json"), speed]
    # Newton with a finite-difference Jacobian over the models' Python bodies: the same roots to the last
    # digit or two (1e-16 relative) without compiling the models (~6 s of a first run: ~0.3 s interpreted)
    r_usv, r_uuv = cached(
        "turning-radii",
        key,
        lambda: [
            usv_min_turning_radius(cfg.usv, jacobian="finite-difference", interpreted=True),
            uuv_turning_radius_at(cfg.uuv, speed, jacobian="finite-difference", interpreted=True),
        ],
    )
    if cfg.guidance.look_ahead is not None:
        return cfg.guidance.look_ahead, r_usv, r_uuv
    return look_ahead_distance(r_usv, r_uuv), r_usv, r_uuv


def build_simulation(cfg: CombinedConfig, rng) -> Simulation:
    """Plant, environment, sensors, navigation, guidance, control and thrusters (module docstring)."""
    check_acceptance(cfg.guidance.acceptance, look_ahead_for(cfg)[1])  # the trims are cached: cheap again below
    h = 1.0 / cfg.control.rate
    sens = cfg.sensors.enabled
    winch = cfg.winch if cfg.winch.enabled else None
    blocks = [*environment_blocks(cfg.environment)]
    if sens:
        s = cfg.sensors
        blocks += [
            GPS(s.gps, "usv"),
            AHRS(s.usv_ahrs, "usv"),
            AHRS(s.uuv_ahrs, "uuv"),
            USBL(s.usbl),
            DepthSensor(s.depth),
        ]
        blocks.append(
            DropoutHold(
                "usbl_hold",
                h,
                "usbl.valid",
                {"dn": "usbl.dn", "de": "usbl.de", "dz": "usbl.dz"},
                "nav.usbl",
                units={"dn": "m", "de": "m", "dz": "m"},
            )
        )

        blocks.append(USBLNavigation(h))
        usv_pos = ("nav.usv_x", "nav.usv_y")
        usv_psi, usv_r, usv_u = "usv_ahrs.psi", "usv_ahrs.r", "nav.usv_u"
        uuv_pos = ("nav.uuv_x", "nav.uuv_y")
        uuv_psi, uuv_r = "uuv_ahrs.psi", "uuv_ahrs.r"
    else:
        usv_pos, usv_psi, usv_r, usv_u = ("usv.x", "usv.y"), "usv.psi", "usv.r", "usv.u"
        uuv_pos, uuv_psi, uuv_r = ("uuv.x", "uuv.y"), "uuv.psi", "uuv.r"
    for i, choice in enumerate(cfg.sensors.extra):
        blocks.append(build_block(choice, BlockContext(period=h), f"sensors.extra.{i}"))
    g = cfg.guidance
    at_guidance = len(blocks)  # the pure pursuit goes here once its look-ahead is known (below)
    f = cfg.formation
    lam = math.radians(f.lambda_d_deg)
    blocks.append(
        LeaderFollower(
            f.l_d, lam, f.R, 1.0 / g.rate, mode=f.mode, leader=(*usv_pos, usv_psi), follower=(*uuv_pos, uuv_psi)
        )
    )
    c = cfg.control
    signals = {
        "usv.x": usv_pos[0],
        "usv.y": usv_pos[1],
        "usv.psi": usv_psi,
        "usv.u": usv_u,
        "usv.r": usv_r,
        "uuv.x": uuv_pos[0],
        "uuv.y": uuv_pos[1],
        "uuv.psi": uuv_psi,
        "uuv.r": uuv_r,
    }
    if sens:
        signals["usv.v"] = "_zero"  # no sway measurement on the USV: take v_l = 0
    ctx = BlockContext(period=h, signals=signals)
    # what the scenario offers its controllers, by parameter name: each takes those it declares
    given = {"usv": cfg.usv, "uuv": cfg.uuv, "u_d": c.surge_speed, "l_d": f.l_d, "lambda_d": lam, "mode": f.mode}
    blocks.append(build_block(c.usv, ctx, "control.usv", given=given))
    base = {"uuv.pid": c.uuv_pid, "uuv.backstepping": c.backstepping}.get(c.uuv.full_kind)
    dump = base.model_dump() if base is not None else None
    blocks.append(build_block(c.uuv, ctx, "control.uuv", base=dump, given=given))
    if winch is not None:  # the UUV's depth by the winch, in ArduSub's modes when a ground station flies it
        wc = cfg.winch_control
        if wc.mode != "depth" or wc.profile:
            raise ConfigError("winch_control.mode: combined scenarios hold a depth ('depth', no profile)")
        blocks.append(SubDepth(wc.target, 1.0 / wc.rate, "uuv", up=winch.speed_max, dn=winch.speed_max,
                               z_max=winch.capacity))  # fmt: skip
        blocks.append(WinchDepthController(wc, winch.tension_max))
    blocks += [USVThrusterBlock(cfg.usv, h), UUVThrusterBlock(cfg.uuv, h)]
    plant = CombinedPlant(
        cfg.usv, cfg.uuv, cfg.cable, top="usv", winch=winch, **cfg.environment.plant_kwargs(cfg.sim.seed)
    )
    # a first run: the plant's output function and stepper, then the blocks' laws from the last, compile
    # in a second process while this one trims the models and runs the first tick (core.caches.compile_ahead)
    plant.ahead = compile_ahead(ahead_jobs([plant], blocks, publish=True))
    l, _, _ = look_ahead_for(cfg)
    blocks.insert(
        at_guidance, PurePursuit(g.waypoints, l, g.acceptance, 1.0 / g.rate, pos_keys=usv_pos, psi_key=usv_psi)
    )
    return Simulation([plant], blocks, cfg.sim.dt, 1.0 / cfg.sim.log_rate, rng)


def cross_track(df, waypoints) -> np.ndarray:
    """Signed distance (m) of the true USV position to its active leg (``guidance.leg``)."""
    wp = np.asarray(waypoints, float)
    k = np.clip(df["guidance.leg"].to_numpy().astype(int), 0, len(wp) - 2)
    a, b = wp[k], wp[k + 1]
    t = b - a
    t /= np.linalg.norm(t, axis=1)[:, None]
    w = np.column_stack([df["usv.x"], df["usv.y"]]) - a
    return -t[:, 1] * w[:, 0] + t[:, 0] * w[:, 1]


class CombinedScenario(Scenario):
    Config = CombinedConfig
    frame = "columns"  # summary and plots read columns only (oceangnc.io.frame; plots in LIGHT_PLOTS)

    def __init__(self, name: str, summary: str, defaults: dict):
        self.name = name
        self.summary = summary
        self.defaults = defaults

    def build(self, cfg, rng):
        return build_simulation(cfg, rng)

    def summarize(self, df, cfg) -> dict:
        wp = cfg.guidance.waypoints
        xt = cross_track(df, wp)
        rd = rel_distance(df)
        e_usv = wrap_array(df["guidance.psi_d"] - df["usv.psi"])
        # a user's controller may not publish its heading target: the guidance's then
        e_uuv = wrap_array(df["uuv_ctrl.psi_d" if "uuv_ctrl.psi_d" in df else "lf.psi_d"] - df["uuv.psi"])
        out = {
            "usv.waypoints_reached": int(df["guidance.wp_reached"].max()),
            "usv.waypoints_total": len(wp),
            "usv.cross_track_rms_m": float(np.sqrt(np.mean(xt**2))),
            "uuv.rel_distance_mean_m": float(rd.mean()),
            "uuv.rel_distance_max_m": float(rd.max()),
            "uuv.depth_final_m": float(df["uuv.z"].iloc[-1]),
            "uuv.heading_error_rms_deg": float(np.degrees(np.sqrt(np.mean(e_uuv**2)))),
            "usv.heading_error_rms_deg": float(np.degrees(np.sqrt(np.mean(e_usv**2)))),
            "t_end_s": float(df["t"].iloc[-1]),
            "cable.top_tension_max_n": float(df["cable.top_tension"].max()),
        }
        if "usbl.pings_lost" in df:
            out["usbl.pings_lost"] = int(df["usbl.pings_lost"].iloc[-1])
            moving = df["usv.speed"] > 0.3
            d = np.degrees(np.abs(wrap_array(df["usv_ahrs.psi"] - df["gps.cog"])))[moving]
            out["ahrs.gps_heading_diff_mean_deg"] = float(d.mean()) if len(d) else float("nan")
        return out

    def plot_jobs(self, df, cfg, out_dir: Path) -> list:
        return plot_jobs(self.name, df, cfg, out_dir)


#: the implicit cable (``cable.integrator = "imex"``) at the 10 ms control period: the physics step is set by
#: accuracy, not by the cable's highest axial mode (docs/uuv-and-cable.md: 0.4 mm depth and 1.4 % peak-tension
#: error against a fine RK4 reference). ``--set cable.integrator=rk4-split --set sim.dt=0.001`` gives the
#: explicit scheme of the first releases.
_SIM = {"dt": 0.01, "log_rate": 10.0}
_CABLE = {"integrator": "imex"}
#: the vehicle as built (003 ch. 5-6): towed through the three-point bridle of fig. 5-6. Its rig height and the
#: formation target, which 003 does not print, are a least-squares fit to 003's pitch (-2..-4 deg, ch. 6.2), depth
#: (3 -> 2.75 m, fig. 6-17) and formation distance (within 0.8 m, ch. 6.1.2) on a grid of field-test runs
#: (docs/validation/bridle_fit.py, table docs/validation/bridle_fit.csv, residuals in docs/validation.md): apex
#: 1.25 m above the CB, l^d = 0.4 m. The cable is paid out so that the UUV hangs at 003's initial 3 m (fig. 6-17;
#: ch. 5.2: the winch sets the depth): 3 m - 1.25 m less its static stretch under the UUV (bridle_fit.hang_length)
BUILT_APEX_H = 1.25
BUILT_LENGTH = 1.692
BUILT_L_D = 0.4
_BUILT = {**_CABLE, "attachment": "bridle", "length": BUILT_LENGTH, "bridle": {"apex_z": -BUILT_APEX_H}}

SCENARIOS = [
    CombinedScenario(
        "combined-survey",
        "USV-cable-UUV through (0,0) (10,10) (20,5) at 0.6 m/s; UUV by PID or backstepping (003 figs 4-7..4-15)",
        {"sim": {**_SIM, "duration": 150.0}, "cable": _CABLE, "control": {"uuv": {"kind": "backstepping"}}},
    ),
    CombinedScenario(
        "waypoints-square",
        "combined vehicle round a 50 m square; UUV on relative angle (+ heading to USV) (003 fig 4-6)",
        {
            "sim": {**_SIM, "duration": 400.0},
            "cable": _CABLE,
            "guidance": {"waypoints": [(0.0, 0.0), (50.0, 0.0), (50.0, 50.0), (0.0, 50.0)]},
            "control": {"surge_speed": 0.6},
        },
    ),
    CombinedScenario(
        "field-test",
        "sea trial of 003 ch. 6.2: (50,0) (50,-50) (0,-50) (0,0) at 1.3 m/s target, PID, sensors on",
        {
            "sim": {**_SIM, "duration": 500.0},
            "cable": _BUILT,
            "formation": {"l_d": BUILT_L_D},
            "guidance": {"waypoints": [(0.0, 0.0), (50.0, 0.0), (50.0, -50.0), (0.0, -50.0), (0.0, 0.0)]},
            "control": {"surge_speed": 1.3, "uuv": {"kind": "pid"}},
            "sensors": {"enabled": True},
        },
    ),
]
