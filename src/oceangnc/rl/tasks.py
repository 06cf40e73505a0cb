"""The learning tasks of :mod:`oceangnc.rl`: spaces, reward, terminations and randomisation (docs/rl.md).

A task is defined over one scenario of a vehicle file (:mod:`oceangnc.scenarios.vehicles`). It keeps the
scenario's plant, guidance and environment blocks, drops its controller and thrust allocation (the agent
replaces them) and its current block (the task draws a constant current per episode), and says

* the action: every thruster command ``vehicle.thrust_<name>_cmd`` (N), a in [-1, 1] mapped to
  ``a max_forward`` for a >= 0 and ``a max_reverse`` for a < 0 (the vehicle file's limits);
* the observation: declared signals, each divided by a stated range and clipped to [-1, 1];
* the reward and the named terminations (:meth:`Task.reward`);
* the randomisation of each episode, all drawn from the environment's generator in a fixed order.

The observations are the plant's true states and the guidance's outputs (these scenarios have no
sensor blocks): no measurement noise yet.
"""

from __future__ import annotations

import math

import gymnasium
import numpy as np
from pydantic import Field

from ..core.config import StrictModel
from ..environment import OceanCurrent
from ..models.vehicle import thruster_state


def _wrap(a: float) -> float:
    """Angle wrapped to [-pi, pi), rad."""
    return (a + math.pi) % (2.0 * math.pi) - math.pi


class TaskParams(StrictModel):
    control_period: float = Field(0.1, gt=0, le=10, description="time between actions, s (10 Hz)")
    time_limit: float = Field(120.0, gt=0, le=1e5, description="the episode is truncated at this time, s")
    end_penalty: float = Field(50.0, ge=0, le=1e6, description="R_end, subtracted at a failure termination")
    c_a: float = Field(0.05, ge=0, le=100, description="weight of the action effort, mean(a^2)")
    c_psi: float = Field(0.5, ge=0, le=100, description="weight of the heading error |psi_err| / pi")
    current_max: float = Field(0.3, ge=0, le=3, description="current speed drawn in [0, current_max], m/s")
    heading_band_deg: float = Field(30.0, ge=0, le=180, description="initial heading drawn within +-band, deg")


class Task:
    """Base of a task (module docstring); subclasses set ``name``, ``scenario``, ``Params`` and the
    observation (``obs_signals`` and ``obs_scales`` or :meth:`observe`), :meth:`start` and :meth:`reward`."""

    name = ""
    scenario = ""
    Params: type[TaskParams] = TaskParams
    stop_reason = "scenario_stop"  #: the termination named when a block ends the run (``_stop``)
    body = "vehicle"

    def __init__(self, params: TaskParams, vf, cfg):
        self.params, self.vf, self.cfg = params, vf, cfg
        b = self.body
        self.cmd = [f"{b}.thrust_{t.name}_cmd" for t in vf.thrusters]
        self.fwd = np.array([t.max_forward for t in vf.thrusters])
        self.rev = np.array([t.max_reverse for t in vf.thrusters])
        self.externals = {k: "N" for k in self.cmd} | {"env.current_n": "m/s", "env.current_e": "m/s"}
        self.action_space = gymnasium.spaces.Box(-1.0, 1.0, shape=(len(self.cmd),), dtype=np.float32)
        # the actuator states with a lag (shaft speed or thrust): without them the state is not Markov
        self.act_obs = [(f"{b}.{thruster_state(t)[0]}", _state_range(t)) for t in vf.thrusters if t.time_constant > 0]
        n = len(self.obs_names()) + len(self.act_obs)
        self.observation_space = gymnasium.spaces.Box(-1.0, 1.0, shape=(n,), dtype=np.float32)

    def keep(self, block) -> bool:
        """Blocks kept from the scenario: not its controller, allocation or current (the task's own)."""
        return getattr(block, "role", None) not in ("controller", "actuator") and not isinstance(block, OceanCurrent)

    def act(self, a: np.ndarray) -> dict:
        """The thruster commands (N) of an action a in [-1, 1]."""
        thrust = np.where(a >= 0.0, a * self.fwd, a * self.rev)
        return dict(zip(self.cmd, thrust.tolist()))

    def obs_names(self) -> list[str]:
        return []

    def raw_obs(self, bus: dict) -> list[float]:
        """The observation before scaling: one value per :meth:`obs_names` item, in its range's units."""
        raise NotImplementedError

    def observe(self, bus: dict) -> np.ndarray:
        """raw / range for every item, then the actuator states / their range, clipped to [-1, 1] (float32)."""
        vals = [v / s for v, s in zip(self.raw_obs(bus), self.obs_ranges())]
        vals += [bus[k] / s for k, s in self.act_obs]
        out = np.array(vals)
        out[~np.isfinite(out)] = 0.0  # a diverged step (terminated): a finite observation all the same
        return np.clip(out, -1.0, 1.0).astype(np.float32)

    def obs_ranges(self) -> list[float]:
        raise NotImplementedError

    def start(self, sim, rng: np.random.Generator) -> None:
        """Write the episode's initial state, current and zero thrust commands onto the plant and bus."""
        raise NotImplementedError

    def reward(self, bus: dict, a: np.ndarray) -> tuple[float, str | None]:
        """The step's reward and the name of the termination, if any."""
        raise NotImplementedError

    def _set_start(self, sim, values: dict, rng: np.random.Generator) -> None:
        """Plant states by name, then a constant current of speed U(0, current_max), direction U(0, 2 pi)."""
        pl = sim.plants[0]
        for k, v in values.items():
            pl.x[pl.state_names.index(k)] = v
        speed = rng.uniform(0.0, self.params.current_max)
        to = rng.uniform(0.0, 2.0 * math.pi)  # the direction the current flows toward, from north
        pl.publish(sim.bus)
        sim.bus.update({k: 0.0 for k in self.cmd})
        sim.bus.update({"env.current_n": speed * math.cos(to), "env.current_e": speed * math.sin(to)})


def _state_range(t) -> float:
    """A thruster state's range: the shaft speed at full forward thrust, sqrt(max_forward / k_forward)
    (rad/s), or the thrust max_forward (N)."""
    if t.shaft is not None:
        return math.sqrt(t.max_forward / t.shaft.k_forward)
    return t.max_forward


class PathParams(TaskParams):
    e_max: float = Field(10.0, gt=0, le=1e4, description="channel half-width: |e| > e_max ends the episode, m")
    c_u: float = Field(0.5, ge=0, le=100, description="weight of the speed error ((u - u_d) / u_d)^2")
    start_cross_max: float = Field(3.0, ge=0, le=1e4, description="initial cross-track offset within +-, m")
    start_along_max: float = Field(5.0, ge=0, le=1e4, description="initial distance along the first leg in [0, ], m")
    u0_max: float = Field(1.0, ge=0, le=20, description="initial surge speed in [0, u0_max], m/s")
    u_range: float = Field(3.0, gt=0, le=50, description="range of the surge speed and speed command, m/s")
    v_range: float = Field(1.0, gt=0, le=50, description="range of the sway speed, m/s")
    r_range: float = Field(1.0, gt=0, le=50, description="range of the yaw rate, rad/s")


class OtterPathFollowing(Task):
    """Path following on the ``otter-waypoints`` route (docs/rl.md, "otter-path").

    Observation: e / e_max, psi_err / pi, u / u_range, u_d / u_range, v / v_range, r / r_range and the
    shaft speeds / n_max, with e = ``guidance.e`` (signed cross-track, m), psi_err = wrap(``vehicle.psi_cmd``
    - ``vehicle.psi``) (the LOS heading error, rad) and u_d = ``vehicle.u_cmd`` (m/s). Reward
    r = 1 - |e| / e_max - c_psi |psi_err| / pi - c_u ((u - u_d) / u_d)^2 - c_a mean(a^2); terminations
    ``off_channel`` (|e| > e_max, with -R_end) and ``route_done`` (the guidance passed the last waypoint).
    """

    name = "otter-path"
    scenario = "otter-waypoints"
    Params = PathParams
    stop_reason = "route_done"

    def obs_names(self) -> list[str]:
        return ["guidance.e", "psi_err", "vehicle.u", "vehicle.u_cmd", "vehicle.v", "vehicle.r"]

    def obs_ranges(self) -> list[float]:
        p = self.params
        return [p.e_max, math.pi, p.u_range, p.u_range, p.v_range, p.r_range]

    def raw_obs(self, bus: dict) -> list[float]:
        psi_err = _wrap(bus["vehicle.psi_cmd"] - bus["vehicle.psi"])
        return [bus["guidance.e"], psi_err, bus["vehicle.u"], bus["vehicle.u_cmd"], bus["vehicle.v"], bus["vehicle.r"]]

    def start(self, sim, rng: np.random.Generator) -> None:
        """Initial position on the first leg: s in [0, start_along_max] along it, c in +-start_cross_max
        across; heading the leg's +- heading_band_deg; surge speed in [0, u0_max]; then the current."""
        p, wp = self.params, np.asarray(self.cfg.route.waypoints, float)
        chi = math.atan2(wp[1, 1] - wp[0, 1], wp[1, 0] - wp[0, 0])
        s = rng.uniform(0.0, p.start_along_max)
        c = rng.uniform(-p.start_cross_max, p.start_cross_max)
        psi = chi + math.radians(rng.uniform(-p.heading_band_deg, p.heading_band_deg))
        u0 = rng.uniform(0.0, p.u0_max)
        x = wp[0, 0] + s * math.cos(chi) - c * math.sin(chi)
        y = wp[0, 1] + s * math.sin(chi) + c * math.cos(chi)
        self._set_start(sim, {"x": x, "y": y, "psi": psi, "u": u0}, rng)

    def reward(self, bus: dict, a: np.ndarray) -> tuple[float, str | None]:
        p = self.params
        e = bus["guidance.e"]
        u_d = max(bus["vehicle.u_cmd"], 1e-3)
        psi_err = _wrap(bus["vehicle.psi_cmd"] - bus["vehicle.psi"])
        r = 1.0 - abs(e) / p.e_max - p.c_psi * abs(psi_err) / math.pi - p.c_u * ((bus["vehicle.u"] - u_d) / u_d) ** 2
        r -= p.c_a * float(np.mean(a**2))
        return r, ("off_channel" if not abs(e) <= p.e_max else None)


class StationParams(TaskParams):
    d_max: float = Field(5.0, gt=0, le=1e4, description="distance from the set point that ends the episode, m")
    start_band: float = Field(2.0, ge=0, le=1e4, description="initial north/east offset within +-, m")
    start_depth_band: float = Field(1.0, ge=0, le=1e4, description="initial depth offset within +- (>= 0 m), m")
    vel_range: float = Field(1.0, gt=0, le=50, description="range of u, v, w (m/s)")
    rate_range: float = Field(1.0, gt=0, le=50, description="range of p, q, r (rad/s)")
    tilt_range_deg: float = Field(45.0, gt=0, le=180, description="range of roll and pitch, deg")


class RovStationKeeping(Task):
    """Station keeping on ``rov-station-keeping`` (docs/rl.md, "rov-station").

    Observation: the position error (set point - position) in the yaw-rotated frame (ahead, starboard)
    and in depth / d_max, psi_err / pi (psi_err = wrap(psi_sp - psi)), roll and pitch / tilt range,
    u, v, w / vel_range, p, q, r / rate_range, the 8 thrusts / max_forward. Reward
    r = 1 - |dp| / d_max - c_psi |psi_err| / pi - c_a mean(a^2); termination ``left_station``
    (|dp| > d_max, with -R_end).
    """

    name = "rov-station"
    scenario = "rov-station-keeping"
    Params = StationParams

    def obs_names(self) -> list[str]:
        return ["e_ahead", "e_starboard", "e_down", "psi_err", "phi", "theta", "u", "v", "w", "p", "q", "r"]

    def obs_ranges(self) -> list[float]:
        p = self.params
        tilt = math.radians(p.tilt_range_deg)
        return [p.d_max] * 3 + [math.pi, tilt, tilt] + [p.vel_range] * 3 + [p.rate_range] * 3

    def _errors(self, bus: dict) -> tuple[float, float, float, float]:
        sp = self.cfg.setpoint
        dn, de, dd = sp.x - bus["vehicle.x"], sp.y - bus["vehicle.y"], sp.z - bus["vehicle.z"]
        return dn, de, dd, _wrap(math.radians(sp.psi_deg) - bus["vehicle.psi"])

    def raw_obs(self, bus: dict) -> list[float]:
        dn, de, dd, psi_err = self._errors(bus)
        c, s = math.cos(bus["vehicle.psi"]), math.sin(bus["vehicle.psi"])
        rest = [bus[f"vehicle.{k}"] for k in ("phi", "theta", "u", "v", "w", "p", "q", "r")]
        return [c * dn + s * de, -s * dn + c * de, dd, psi_err, *rest]

    def start(self, sim, rng: np.random.Generator) -> None:
        """Initial position: the set point +- start_band north and east, +- start_depth_band in depth (not
        above the surface); heading the set point's +- heading_band_deg; at rest; then the current."""
        p, sp = self.params, self.cfg.setpoint
        x = sp.x + rng.uniform(-p.start_band, p.start_band)
        y = sp.y + rng.uniform(-p.start_band, p.start_band)
        z = max(0.0, sp.z + rng.uniform(-p.start_depth_band, p.start_depth_band))
        psi = math.radians(sp.psi_deg + rng.uniform(-p.heading_band_deg, p.heading_band_deg))
        self._set_start(sim, {"x": x, "y": y, "z": z, "psi": psi}, rng)

    def reward(self, bus: dict, a: np.ndarray) -> tuple[float, str | None]:
        p = self.params
        dn, de, dd, psi_err = self._errors(bus)
        d = math.sqrt(dn * dn + de * de + dd * dd)
        r = 1.0 - d / p.d_max - p.c_psi * abs(psi_err) / math.pi - p.c_a * float(np.mean(a**2))
        return r, ("left_station" if not d <= p.d_max else None)


TASKS: dict[str, type[Task]] = {OtterPathFollowing.name: OtterPathFollowing, RovStationKeeping.name: RovStationKeeping}
