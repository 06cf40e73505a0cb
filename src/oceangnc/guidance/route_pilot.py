"""Route pilot of the console's USV: operator stick or pure pursuit along a route -> speed and yaw-rate setpoints.

Reads the console's bus keys (the shared remote-control protocol, see :mod:`oceangnc.console`):
``console.mode`` (``"remote"`` | ``"auto"``), ``joystick.surge`` / ``joystick.yaw`` (stick in
[-1, 1], surge ahead and yaw to starboard positive) and ``console.waypoints`` (a tuple of (north,
east) points, m, that replaces the route).

* Remote: ``u_d = surge * max_speed`` (``surge * max_reverse_speed`` astern) and ``r_d = yaw * r_max``
  (001 eq. 26 data flow: stick axes -> speed, yaw rate).
* Autonomous: pure pursuit along the legs of the route (003 ch. 3.1, table 3-1, with the geometry of
  :mod:`oceangnc.guidance.pure_pursuit`): the target heading points at the look-ahead point G on the
  current leg at distance ``l`` from the vehicle (turning radius R = l^2 / (2 d), 003 eq. 3.5). The
  next waypoint is taken within the acceptance radius or past the end of the leg; the first leg
  starts where the vehicle is when the route is set. A proportional heading law gives
  ``r_d = sat(k_psi wrap(psi_d - psi), r_max)`` and the speed setpoint is the cruise speed times
  max(0, cos(heading error)), so the boat turns before it speeds off. It steers on the GPS fix
  (``gps.x``/``gps.y``, the truth if no GPS runs).

Writes ``usv.u_d`` (m/s), ``usv.r_d`` (rad/s), ``guidance.psi_d`` (rad), ``guidance.cross_track``
(m) and ``guidance.wp_index`` (index of the waypoint steered to; the number of waypoints once the
route is complete). The inner loops are :class:`oceangnc.control.usv_control.USVRateController`.
"""

from __future__ import annotations

import math

import numpy as np
from pydantic import Field

from ..core.blocks import Block
from ..core.registry import register_block
from ..io.config import StrictModel
from . import _compiled_route as _cr


class RouteConfig(StrictModel):
    """Route and pure-pursuit guidance of the autonomous mode."""

    waypoints: list[tuple[float, float]] = Field(
        [(50.0, 0.0), (50.0, 50.0), (0.0, 50.0), (0.0, 0.0)],
        min_length=1,
        max_length=200,
        description="route, list of (north, east) points, m",
    )
    speed: float = Field(0.7, gt=0, le=5, description="cruise speed, m/s")
    lookahead: float = Field(6.0, gt=0, le=1000, description="pure-pursuit look-ahead distance l (003 eq. 3.5), m")
    accept_radius: float = Field(3.0, gt=0, le=1000, description="waypoint acceptance radius, m")
    heading_gain: float = Field(0.8, gt=0, le=20, description="heading error -> yaw-rate setpoint gain k_psi, 1/s")


class StickConfig(StrictModel):
    """Stick scaling (003 ch. 5.4 remote mode; 001 eq. 26 data flow: stick axes -> speed, yaw rate)."""

    max_speed: float = Field(0.9, gt=0, le=5, description="surge speed at full stick ahead, m/s")
    max_reverse_speed: float = Field(0.3, ge=0, le=5, description="surge speed at full stick astern, m/s")
    max_yaw_rate_degps: float = Field(20.0, gt=0, le=90, description="yaw rate at full stick, deg/s")
    open_loop_thrust_kgf: float = Field(
        36.2, gt=0, le=100, description="open loop: per-thruster thrust at full surge stick, kgf"
    )
    open_loop_reverse_kgf: float = Field(
        13.83, ge=0, le=100, description="open loop: per-thruster astern thrust at full stick, kgf"
    )
    open_loop_diff_kgf: float = Field(
        15.0, ge=0, le=100, description="open loop: differential thrust U_heading at full yaw stick, kgf"
    )


@register_block("usv.route_pilot")
class RoutePilot(Block):
    """Stick or pure-pursuit route -> ``usv.u_d``, ``usv.r_d`` (module docstring).

    Parameters
    ----------
    route : RouteConfig
    stick : StickConfig
    period : float
        Firing period, s.
    mode : str
        Initial mode when the console has not written ``console.mode``.
    """

    role = "guidance"
    name = "usv_route"

    def __init__(self, route: RouteConfig, stick: StickConfig, period: float, mode: str = "auto"):
        self.cfg = route
        self.stick = stick
        self.period = float(period)
        self.mode = mode
        self.heading_gain = route.heading_gain
        self.cruise_speed = route.speed
        self.lookahead = route.lookahead
        self.inputs = {"usv.psi": "rad", "usv.x": "m", "usv.y": "m"}
        self.optional_inputs = {
            "console.mode": "str",
            "console.waypoints": "str",
            "joystick.surge": "1",
            "joystick.yaw": "1",
            "gps.x": "m",
            "gps.y": "m",
        }
        self.outputs = {
            "usv.u_d": "m/s",
            "usv.r_d": "rad/s",
            "guidance.psi_d": "rad",
            "guidance.cross_track": "m",
            "guidance.wp_index": "count",
        }

    # -- console protocol: adjustable gains ---------------------------------------------------------
    def gain_specs(self) -> list[dict]:
        """The gains an operator may change while running: name, value, range, unit, description."""
        return [
            {
                "name": "heading_gain",
                "value": self.heading_gain,
                "min": 0.01,
                "max": 10.0,
                "unit": "1/s",
                "description": "autonomous heading error -> yaw-rate setpoint gain",
            },
            {
                "name": "cruise_speed",
                "value": self.cruise_speed,
                "min": 0.05,
                "max": 1.2,
                "unit": "m/s",
                "description": "autonomous cruise speed",
            },
            {
                "name": "lookahead",
                "value": self.lookahead,
                "min": 0.5,
                "max": 100.0,
                "unit": "m",
                "description": "pure-pursuit look-ahead distance",
            },
        ]

    def set_gain(self, name: str, value: float) -> None:
        """Set one gain listed by :meth:`gain_specs` (the console validates the range first)."""
        if name not in ("heading_gain", "cruise_speed", "lookahead"):
            raise KeyError(name)
        setattr(self, name, float(value))

    # -- block ---------------------------------------------------------------------------------------
    def reset(self, rng) -> None:
        self.route = tuple((float(n), float(e)) for n, e in self.cfg.waypoints)
        self.wp = 0
        self.leg_start: tuple[float, float] | None = None
        self.route_done = False

    def step(self, t: float, bus: dict) -> None:
        psi = bus["usv.psi"]
        mode = bus.get("console.mode", self.mode)
        wps = bus.get("console.waypoints")
        if wps is not None and tuple(wps) != self.route and len(wps) > 0:
            self.route = tuple((float(a), float(b)) for a, b in wps)
            self.wp = 0
            self.leg_start = None
            self.route_done = False
        surge = float(bus.get("joystick.surge", 0.0))
        yaw = float(bus.get("joystick.yaw", 0.0))
        x, y = float(bus.get("gps.x", bus["usv.x"])), float(bus.get("gps.y", bus["usv.y"]))
        rs = self._route_state()
        route = np.array(self.route, dtype=np.float64).ravel()
        u_d, r_d, psi_d, xte = _cr.route_pilot_law(
            mode == "remote", surge, yaw, x, y, float(psi), route, len(self.route), rs, self._law_params()
        )
        self.wp = int(rs[0])
        self.leg_start = (float(rs[2]), float(rs[3])) if rs[1] != 0.0 else None
        self.route_done = self.wp >= len(self.route)
        bus["usv.u_d"] = u_d
        bus["usv.r_d"] = r_d
        bus["guidance.psi_d"] = psi_d
        bus["guidance.cross_track"] = xte
        bus["guidance.wp_index"] = float(self.wp)

    def _route_state(self) -> np.ndarray:
        ls = self.leg_start
        return np.array([self.wp, 0.0 if ls is None else 1.0, *(ls or (0.0, 0.0))], dtype=np.float64)

    def _law_params(self) -> np.ndarray:
        st = self.stick
        r_max = math.radians(st.max_yaw_rate_degps)
        c = self.cfg
        v = [st.max_speed, st.max_reverse_speed, r_max, self.heading_gain, self.cruise_speed, self.lookahead]
        return np.array([*v, c.accept_radius], dtype=np.float64)

    def compiled(self):
        """Compiled form: :func:`oceangnc.guidance._compiled_route.route_pilot_step` (the route as it
        stands; a route sent by the console while running keeps the Python path, see
        :func:`oceangnc.core.fused.build_fused`)."""
        from ..core.fused import CompiledBlock
        from ..core.fused_strings import ENUMS

        route = np.array(self.route, dtype=np.float64).ravel()
        pa = np.concatenate(
            [self._law_params(), [float(ENUMS["console.mode"].index(self.mode))], [len(self.route)], route]
        )
        sigs = ["usv.psi", "usv.x", "usv.y", "console.mode", "joystick.surge", "joystick.yaw", "?gps.x", "?gps.y"]
        sigs += ["usv.u_d", "usv.r_d", "guidance.psi_d", "guidance.cross_track", "guidance.wp_index"]
        return CompiledBlock(_cr.route_pilot_step, sigs, state=self._route_state(), params=pa)
