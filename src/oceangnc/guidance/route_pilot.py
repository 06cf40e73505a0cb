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
from numba import njit
from pydantic import Field

from ..core.fused_strings import ENUMS
from ..core.law import Ext, In, LawBlock, Layout, Opt, Out, Signals, param
from ..core.registry import register_block
from ..core.rotations import wrap
from ..io.config import StrictModel
from .pure_pursuit import leg_offsets, look_ahead_goal, pursuit_turn
from .views import entry


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


SIGNALS = Signals(psi=In("rad"), x=In("m"), y=In("m"), mode=Ext("str"), surge=Ext("1"), yaw=Ext("1"),
                  gps_x=Opt("m"), gps_y=Opt("m"), u_d=Out("m/s"), r_d=Out("rad/s"), psi_d=Out("rad"),
                  cross_track=Out("m"), wp_index=Out("count"))  # fmt: skip
PARAMS = Layout("max_speed", "max_reverse_speed", "r_max", "heading_gain", "cruise_speed", "lookahead",
                "accept", "mode", "n")  # fmt: skip
STATE = Layout("wp", "has_start", "start_n", "start_e")
S, P, X = SIGNALS.at, PARAMS.at, STATE.at
#: the route follows the parameters: n waypoints (north, east; m) from this offset of ``pa``
ROUTE = P.n + 1
#: shortest leg (m): a leg start on its waypoint (the vehicle set the route standing on it) is skipped
MIN_LEG = 1e-9


@njit(cache=True)
def route_pursuit(x, y, st, pa):
    """Pure pursuit along the route (003 table 3-1, eq. 3.5) from the vehicle at (x, y) (m):
    ``(psi_d rad, cross-track m)``, psi_d NaN once the route is done. The route state ``st`` (waypoint
    steered to, the leg's start) is updated in place: the first leg starts where the vehicle is, and
    the next waypoint is taken within the acceptance radius or past the end of the leg (the waypoint
    then starts the next leg)."""
    n = int(pa[P.n])
    while True:
        if st[X.has_start] == 0.0:
            st[X.has_start] = 1.0
            st[X.start_n] = x
            st[X.start_e] = y
        k = int(st[X.wp])
        b0, b1 = pa[ROUTE + 2 * k], pa[ROUTE + 2 * k + 1]
        a0, a1 = st[X.start_n], st[X.start_e]
        leg = math.hypot(b0 - a0, b1 - a1)
        dist = math.hypot(b0 - x, b1 - y)
        along = 0.0
        if leg > MIN_LEG:
            along, _ = leg_offsets(x, y, a0, a1, b0, b1)
        if dist < pa[P.accept] or leg <= MIN_LEG or along > leg:
            st[X.start_n] = b0
            st[X.start_e] = b1
            st[X.wp] = k + 1
            if k + 1 >= n:
                return math.nan, 0.0
            continue
        e, g0, g1 = look_ahead_goal(x, y, a0, a1, b0, b1, pa[P.lookahead], k == n - 1)
        return pursuit_turn(x, y, 0.0, g0, g1)[0], e  # the bearing of G (the heading enters only d and R)


@njit(cache=True)
def route_pilot_law(t, sig, sl, st, pa):
    """One period of the route pilot (module docstring): in the remote mode the stick (each axis clipped
    to [-1, 1]) scaled to u_d = surge u_max (u_reverse astern) and r_d = yaw r_max (001 eq. 26 data
    flow); in the autonomous mode :func:`route_pursuit` and r_d = sat(k_psi wrap(psi_d - psi), r_max),
    u_d = u_cruise max(0, cos(heading error)); zero once the route is done. The mode is
    ``console.mode``'s code (0 remote), the block's own when absent; the position the GPS fix when one
    is written, else the truth."""
    code = sig[sl[S.mode]] if sig[sl[S.mode]] >= 0.0 else pa[P.mode]
    surge = max(-1.0, min(1.0, sig[sl[S.surge]]))
    yaw = max(-1.0, min(1.0, sig[sl[S.yaw]]))
    x = sig[sl[S.gps_x]] if sl[S.gps_x] >= 0 else sig[sl[S.x]]
    y = sig[sl[S.gps_y]] if sl[S.gps_y] >= 0 else sig[sl[S.y]]
    psi = sig[sl[S.psi]]
    n = int(pa[P.n])
    r_max = pa[P.r_max]
    psi_d = math.nan
    xte = 0.0
    if code == 0.0:
        u_d = surge * (pa[P.max_speed] if surge >= 0 else pa[P.max_reverse_speed])
        r_d = yaw * r_max
    elif st[X.wp] >= n:
        u_d, r_d = 0.0, 0.0
    else:
        psi_d, xte = route_pursuit(x, y, st, pa)
        if st[X.wp] >= n:
            u_d, r_d = 0.0, 0.0
        else:
            err = wrap(psi_d - psi)
            r_d = max(-r_max, min(r_max, pa[P.heading_gain] * err))
            u_d = pa[P.cruise_speed] * max(0.0, math.cos(err))
    sig[sl[S.u_d]] = u_d
    sig[sl[S.r_d]] = r_d
    sig[sl[S.psi_d]] = psi_d if math.isfinite(psi_d) else psi
    sig[sl[S.cross_track]] = xte
    sig[sl[S.wp_index]] = st[X.wp]


@register_block("usv.route_pilot")
class RoutePilot(LawBlock):
    """Stick or pure-pursuit route -> ``usv.u_d``, ``usv.r_d`` (module docstring); law
    :func:`route_pilot_law`.

    A route sent while running (``console.waypoints``, the console's map or a MAVLink mission) reaches
    the block through :func:`send_route` (:meth:`set_route`); it keeps the simulation on the Python
    clock (:func:`oceangnc.core.fused_strings.strings_ok`).

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
    law = staticmethod(route_pilot_law)
    signals = SIGNALS

    heading_gain = param(P.heading_gain, "autonomous heading error -> yaw-rate setpoint gain k_psi, 1/s")
    cruise_speed = param(P.cruise_speed, "autonomous cruise speed, m/s")
    lookahead = param(P.lookahead, "pure-pursuit look-ahead distance l, m")
    wp = entry("st", X.wp, int, "index of the waypoint steered to (the number of waypoints once done)")

    def __init__(self, route: RouteConfig, stick: StickConfig, period: float, mode: str = "auto"):
        self.cfg = route
        self.stick = stick
        self.period = float(period)
        self.bind(psi="usv.psi", x="usv.x", y="usv.y", mode="console.mode", surge="joystick.surge",
                  yaw="joystick.yaw", gps_x="gps.x", gps_y="gps.y", u_d="usv.u_d", r_d="usv.r_d",
                  psi_d="guidance.psi_d", cross_track="guidance.cross_track", wp_index="guidance.wp_index")  # fmt: skip
        # a route sent while running: given to set_route by send_route (the law reads it from pa)
        self.optional_inputs = {**(self.optional_inputs or {}), "console.waypoints": "str"}
        self.pa = PARAMS.pack(
            max_speed=stick.max_speed,
            max_reverse_speed=stick.max_reverse_speed,
            r_max=math.radians(stick.max_yaw_rate_degps),
            heading_gain=route.heading_gain,
            cruise_speed=route.speed,
            lookahead=route.lookahead,
            accept=route.accept_radius,
            mode=float(ENUMS["console.mode"].index(mode)),
            n=0.0,
        )
        self.st = STATE.pack(dict.fromkeys(STATE.names, 0.0))
        self._write_route(route.waypoints)

    @property
    def mode(self) -> str:
        """The mode when the console has not written ``console.mode``."""
        return ENUMS["console.mode"][int(self.pa[P.mode])]

    @property
    def route(self) -> tuple[tuple[float, float], ...]:
        """The route flown, ((north, east), ...) in m (read from the parameter array)."""
        n = int(self.pa[P.n])
        r = self.pa[ROUTE : ROUTE + 2 * n].tolist()
        return tuple((r[2 * i], r[2 * i + 1]) for i in range(n))

    @property
    def leg_start(self) -> tuple[float, float] | None:
        """Where the current leg starts (north, east; m), None before the route's first period."""
        st = self.st
        return (float(st[X.start_n]), float(st[X.start_e])) if st[X.has_start] != 0.0 else None

    @property
    def route_done(self) -> bool:
        """Every waypoint of the route is reached."""
        return self.wp >= int(self.pa[P.n])

    def _write_route(self, points) -> None:
        pts = np.array([(float(a), float(b)) for a, b in points], dtype=np.float64).ravel()
        if self.pa.size < ROUTE + pts.size:
            self.pa = np.concatenate([self.pa[:ROUTE], np.zeros(pts.size)])
        self.pa[P.n] = pts.size // 2
        self.pa[ROUTE : ROUTE + pts.size] = pts

    def set_route(self, points) -> None:
        """Fly ``points`` ((north, east) m, at least one) from where the vehicle is: the route is written
        into the parameter array (rebuilt when it does not fit: a fused loop already built keeps the
        old one) and restarted; the route flown already, or none, changes nothing."""
        pts = tuple((float(a), float(b)) for a, b in points)
        if len(pts) == 0 or pts == self.route:
            return
        self._write_route(pts)
        self.st[:] = 0.0

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
        """The configured route, from its first waypoint; the first leg starts where the vehicle is."""
        self._write_route(self.cfg.waypoints)
        self.st[:] = 0.0


def send_route(sim, points) -> None:
    """Fly the route ``points`` ((north, east) m) in the running simulation ``sim``: the console's and
    MAVLink's way. It is written onto the bus as ``console.waypoints`` (what the console shows; a fused
    loop refuses it) and handed to every block that reads that signal (:meth:`RoutePilot.set_route`)."""
    pts = tuple((float(a), float(b)) for a, b in points)
    sim.inject({"console.waypoints": pts})
    for b in sim.blocks:
        if "console.waypoints" in (getattr(b, "optional_inputs", None) or {}) and hasattr(b, "set_route"):
            b.set_route(pts)
