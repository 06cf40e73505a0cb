"""A scripted pilot that flies the berthing joystick the way a person would (for document 001's trials).

001 evaluates the controllers with a person at the joystick watching the ship and the route on a
screen (sec. 3.1, 4). To repeat the five-trial comparison unattended, this block imitates that
person:

* **looks ahead** along the route's centre line: the aim point lies ``lookahead_m`` ahead of the
  ship's projection on the polyline (extended beyond its end), the wanted heading points at it;
  when berthing the look-ahead shrinks to 50 m + half the remaining distance (not below
  ``lookahead_min_m``), as the eye comes to the berth;
* **steers the track**: like a person watching the ship's track vector on the screen, the pilot
  aims the course over ground chi = psi + atan2(v, u) at the aim point, so the ship crabs into a
  cross current or wind by itself;
* **perceives with errors and reacts with a delay**: heading, speed and yaw rate are read with
  slowly varying Gaussian errors (first-order Gauss-Markov, correlation time ``noise_time_s``) and
  acted on ``reaction_s`` later (per-run jitter), all drawn from the block's own generator;
* **moves the stick in limited steps**: every ``period`` the stick moves at most ``stick_step``
  toward the wanted position, quantised to ``stick_quantum``;
* **knows the mode** of the joystick, like a trained operator: in the closed loops the yaw stick asks
  for a yaw rate proportional to the heading error (r_want = k_psi e_psi, stick = r_want / r_max) and
  the surge stick asks for the wanted speed; in the open loop the stick is a throttle and a rudder/
  thruster lever, so the pilot closes the yaw-rate loop himself, moving the stick in proportion to the
  shortfall of the perceived yaw rate from the same wanted rate (stick = k_rate_open (r_want - r_seen)),
  and flies speed with the throttle that would hold the wanted speed plus a correction on the
  perceived speed error. The closed loops measure r and u with sensors; the person only sees the ship
  swing on the screen, hence the perception errors. In the closed loops the pilot allows for the
  surge stick's dead band (not the yaw stick's: small heading errors are left alone).

The wanted speed is the cruise speed, reduced toward the end of the route when ``stop_at_end``
(berthing): u_t = min(u_cruise, sqrt(2 a s), k_s s) for the remaining distance s, a gentle backing
command if the ship overshoots. Writes ``joystick.surge``, ``joystick.yaw`` (stick, [-1, 1]) and
``pilot.u_target`` (m/s), ``pilot.psi_des`` (rad), ``pilot.cross_track`` (m, starboard of the route
positive), ``pilot.s_remaining`` (m); sets ``pilot.done`` (and ``_stop`` if asked) once stopped at
the end of the route.
"""

from __future__ import annotations

import math
from typing import Literal

import numpy as np
from numba import njit
from pydantic import Field

from ..core.law import In, LawBlock, Layout, Out, Signals, param
from ..core.registry import register_block
from ..core.rotations import wrap
from ..io.config import StrictModel
from ..sensors.filters import gauss_markov
from ..units import KNOT
from .views import entry


class PilotConfig(StrictModel):
    """The (scripted or external) pilot."""

    kind: Literal["scripted", "external"] = Field(
        "scripted", description="'scripted' (this block) or 'external' (joystick.* written by the console)"
    )
    period: float = Field(0.5, gt=0, le=10, description="pilot update period, s")
    reaction_s: float = Field(1.0, ge=0, le=10, description="mean reaction delay, s")
    reaction_jitter_s: float = Field(0.3, ge=0, le=5, description="per-run reaction delay spread (uniform +-), s")
    lookahead_m: float = Field(250.0, gt=1, le=5000, description="look-ahead distance along the route, m")
    lookahead_min_m: float = Field(80.0, gt=1, le=5000, description="berthing: shortest look-ahead near the berth, m")
    cruise_kn: float = Field(1.3, gt=0, le=10, description="wanted cruise speed (001: mean 1.3 kn), kn")
    stick_step: float = Field(0.1, gt=0, le=2, description="largest stick move per update, stick units")
    stick_quantum: float = Field(0.02, ge=0, le=0.5, description="stick resolution, stick units")
    noise_heading_deg: float = Field(0.5, ge=0, le=20, description="heading perception error (std), deg")
    noise_speed: float = Field(0.02, ge=0, le=1, description="speed perception error (std), m/s")
    noise_yaw_rate_degps: float = Field(0.1, ge=0, le=5, description="yaw-rate perception error (std), deg/s")
    k_psi: float = Field(0.03, ge=0, le=10, description="closed loop: wanted yaw rate per heading error, 1/s")
    k_speed: float = Field(0.3, ge=0, le=10, description="closed loop: extra surge stick per speed error, s/m")
    noise_time_s: float = Field(20.0, gt=0, le=1e4, description="correlation time of the perception errors, s")
    k_rate_open: float = Field(300.0, ge=0, le=1e5, description="open loop: yaw stick per yaw-rate shortfall, s/rad")
    k_speed_open: float = Field(3.0, ge=0, le=100, description="open loop: surge stick per speed error, s/m")
    brake_decel: float = Field(0.0015, gt=0, le=1, description="planned deceleration toward the end, m/s2")
    k_stop: float = Field(0.01, gt=0, le=1, description="speed per remaining distance near the end, 1/s")
    steer_course: bool = Field(True, description="aim the course over ground (track vector), not the heading")
    stop_at_end: bool = Field(False, description="slow down and stop at the end of the route")
    stop_when_done: bool = Field(True, description="end the run once stopped at the end (or past it, without stop)")


@njit(cache=True)
def route_project(pts, seg_len, seg_dir, s0, n, e):
    """``(s, cross)`` of the point (n, e) (m) on the polyline through ``pts`` (flat north, east, ...):
    the arc length s (m) of its projection on the nearest segment, the first segment extended before
    its start and the last beyond its end, and the signed cross-track offset (m, starboard of the route
    positive). ``seg_len``, ``seg_dir`` (flat unit vectors) and ``s0`` (arc length at each point)
    describe the segments (:class:`Route`)."""
    nseg = seg_len.size
    best = -1
    bd = 0.0
    bt = 0.0
    bf0 = 0.0
    bf1 = 0.0
    for i in range(nseg):
        r0 = n - pts[2 * i]
        r1 = e - pts[2 * i + 1]
        d0 = seg_dir[2 * i]
        d1 = seg_dir[2 * i + 1]
        t = r0 * d0 + r1 * d1
        L = seg_len[i]
        tc = min(max(t, 0.0), L)
        if i == nseg - 1:
            tc = max(0.0, t) if nseg > 1 else t
        if i == 0 and nseg > 1:
            tc = min(t, L)
        f0 = pts[2 * i] + tc * d0
        f1 = pts[2 * i + 1] + tc * d1
        dist = math.hypot(n - f0, e - f1)
        if best < 0 or dist < bd:
            best = i
            bd = dist
            bt = tc
            bf0 = f0
            bf1 = f1
    i = best
    cross = seg_dir[2 * i] * (e - bf1) - seg_dir[2 * i + 1] * (n - bf0)
    return s0[i] + bt, cross


@njit(cache=True)
def route_point_at(pts, seg_dir, s0, length, s):
    """``(north, east)`` (m) of the point at arc length ``s`` (m) along the polyline (:func:`route_project`'s
    arrays), extrapolated along the end segments."""
    npt = s0.size
    nseg = npt - 1
    if s >= length:
        j = nseg - 1
        return pts[2 * (npt - 1)] + (s - length) * seg_dir[2 * j], pts[2 * (npt - 1) + 1] + (s - length) * seg_dir[
            2 * j + 1
        ]
    if s <= 0:
        return pts[0] + s * seg_dir[0], pts[1] + s * seg_dir[1]
    i = -1
    for k in range(npt):
        if s0[k] <= s:
            i = k
    return pts[2 * i] + (s - s0[i]) * seg_dir[2 * i], pts[2 * i + 1] + (s - s0[i]) * seg_dir[2 * i + 1]


class Route:
    """A polyline route (N, E) with projection and look-ahead along it (:func:`route_project`,
    :func:`route_point_at`)."""

    def __init__(self, points):
        self.p = np.asarray(points, dtype=float)
        d = np.diff(self.p, axis=0)
        self.seg_len = np.hypot(d[:, 0], d[:, 1])
        self.seg_dir = d / self.seg_len[:, None]
        self.s0 = np.concatenate([[0.0], np.cumsum(self.seg_len)])
        self.length = float(self.s0[-1])

    def project(self, n: float, e: float):
        """(s along the route, signed cross-track offset (starboard of the route positive)), m."""
        s, cross = route_project(self.p.ravel(), self.seg_len, self.seg_dir.ravel(), self.s0, float(n), float(e))
        return float(s), float(cross)

    def point_at(self, s: float):
        """Point at arc length s (extrapolated along the end segments), (north, east) m."""
        return np.array(route_point_at(self.p.ravel(), self.seg_dir.ravel(), self.s0, self.length, float(s)))

    def centre_east(self, north):
        """East coordinate of the route at the given north coordinates (route monotonic in north)."""
        return np.interp(north, self.p[:, 0], self.p[:, 1])


@njit(cache=True)
def ring_slot(count, head, cap):
    """Slot for a new entry of a ring buffer of ``cap`` entries holding ``count`` from ``head`` (the
    oldest); returns (slot, new count, new head): a full buffer overwrites its oldest entry."""
    if count < cap:
        return (head + count) % cap, count + 1, head
    return head, count, (head + 1) % cap


@njit(cache=True)
def move_stick(cur, want, quantum, step):
    """The stick moved from ``cur`` toward ``want`` (both clipped to [-1, 1], ``want`` quantised to
    ``quantum`` when > 0) by at most ``step`` (stick units)."""
    want = max(-1.0, min(1.0, want))
    if quantum > 0:
        want = np.rint(want / quantum) * quantum
    d = max(-step, min(step, want - cur))
    return max(-1.0, min(1.0, cur + d))


SIGNALS = Signals(x=In("m"), y=In("m"), psi=In("rad"), u=In("m/s"), r=In("rad/s"), v=In("m/s"), surge=Out("1"),
                  yaw=Out("1"), u_target=Out("m/s"), psi_des=Out("rad"), cross_track=Out("m"),
                  s_remaining=Out("m"), done=Out("bool"), stop=Out("bool"))  # fmt: skip
PARAMS = Layout("period", "noise_time", ("sigma", 3), "delay", "lookahead", "stop_at_end", "lookahead_min",
                "steer_course", "u_cruise", "brake_decel", "k_stop", "closed", "speed_per_rps", "n_open",
                "k_speed_open", "k_rate_open", "k_psi", "dead_band", "stick_quantum", "stick_step", "u_max",
                "u_astern", "k_speed", "r_max", "stop_when_done", "length", "npt")  # fmt: skip
STATE = Layout("stick_u", "stick_r", "done", ("err", 3), "count", "head", "cap")
#: one remembered observation: time (s), position (m), perceived heading (rad), speed (m/s), yaw rate
#: (rad/s) and sway speed (m/s)
MEMORY = Layout("t", "x", "y", "psi", "u", "r", "v")
S, P, X, M = SIGNALS.at, PARAMS.at, STATE.at, MEMORY.at
#: the route follows the parameters from this offset of ``pa``: the npt points (north, east), the npt - 1
#: segment lengths, the segment directions (north, east) and the npt arc lengths s0 (:class:`Route`)
ROUTE = P.npt + 1
#: the memory follows the state from this offset of ``st``: ``cap`` :data:`MEMORY` entries of ``ENTRY``
#: floats, a ring
RING = X.cap + 1
ENTRY = MEMORY.size


@njit(cache=True)
def pilot_law(t, sig, sl, st, pa, rng):
    """One period of the scripted pilot (module docstring): the perception errors (first-order
    Gauss-Markov, correlation time ``noise_time``) drawn from the block's generator, the observation
    remembered and the one ``delay`` s old acted on; the aim point ahead on the route
    (:func:`route_point_at`), the wanted speed and yaw (closed loops: stick for the wanted speed
    and for r_want = k_psi e_psi; open loop: throttle and the pilot's own yaw-rate loop), the sticks
    moved (:func:`move_stick`); done once stopped at the end of a berthing route (or past the end of a
    transit), which ends the run if asked."""
    npt = int(pa[P.npt])
    nseg = npt - 1
    pts = pa[ROUTE : ROUTE + 2 * npt]
    seg_len = pa[ROUTE + 2 * npt : ROUTE + 2 * npt + nseg]
    seg_dir = pa[ROUTE + 2 * npt + nseg : ROUTE + 2 * npt + 3 * nseg]
    s0 = pa[ROUTE + 2 * npt + 3 * nseg : ROUTE + 3 * npt + 3 * nseg]
    length = pa[P.length]
    a = math.exp(-pa[P.period] / pa[P.noise_time])
    for i in range(3):
        st[X.err + i] = gauss_markov(st[X.err + i], a, pa[P.sigma + i], rng.standard_normal())
    x = sig[sl[S.x]]
    y = sig[sl[S.y]]
    # remember this observation; act on the one ``delay`` old
    cnt = int(st[X.count])
    head = int(st[X.head])
    cap = int(st[X.cap])
    j, cnt, head = ring_slot(cnt, head, cap)
    o = RING + ENTRY * j
    st[o + M.t] = t
    st[o + M.x] = x
    st[o + M.y] = y
    st[o + M.psi] = sig[sl[S.psi]] + st[X.err]
    st[o + M.u] = sig[sl[S.u]] + st[X.err + 1]
    st[o + M.r] = sig[sl[S.r]] + st[X.err + 2]
    st[o + M.v] = sig[sl[S.v]]
    while cnt > 1 and st[RING + ENTRY * ((head + 1) % cap) + M.t] <= t - pa[P.delay] + 1e-9:
        head = (head + 1) % cap
        cnt -= 1
    st[X.count] = cnt
    st[X.head] = head
    b = RING + ENTRY * head
    n, e, psi, u, r, v = st[b + M.x], st[b + M.y], st[b + M.psi], st[b + M.u], st[b + M.r], st[b + M.v]
    # decide: the aim point, the wanted course and speed
    stop_at_end = pa[P.stop_at_end] != 0.0
    s, _ = route_project(pts, seg_len, seg_dir, s0, n, e)
    look = pa[P.lookahead]
    if stop_at_end:  # closing the berth, the eye comes nearer: 50 m + half the remaining distance
        look = min(look, max(pa[P.lookahead_min], 50.0 + 0.5 * (length - s)))
    aim0, aim1 = route_point_at(pts, seg_dir, s0, length, s + look)
    psi_des = math.atan2(aim1 - e, aim0 - n)
    # steer the track, not the bow: course over ground (the crab in current / wind comes free)
    course = psi + math.atan2(v, u) if pa[P.steer_course] != 0.0 and math.hypot(u, v) > 0.1 else psi
    e_psi = wrap(psi_des - course)
    s_rem = length - s
    u_cruise = pa[P.u_cruise]
    if stop_at_end:
        if s_rem > 0:
            u_t = min(u_cruise, math.sqrt(2 * pa[P.brake_decel] * s_rem), pa[P.k_stop] * s_rem)
        else:
            u_t = max(-0.2, pa[P.k_stop] * s_rem)
    else:
        u_t = u_cruise
    if pa[P.closed] == 0.0:  # open loop: throttle, and the pilot closes the yaw-rate loop himself
        want_u = u_t / (pa[P.speed_per_rps] * pa[P.n_open]) + pa[P.k_speed_open] * (u_t - u)
        want_r = pa[P.k_rate_open] * (pa[P.k_psi] * e_psi - r)
    else:
        db = pa[P.dead_band]
        want_u = (u_t / pa[P.u_max] if u_t >= 0 else u_t / pa[P.u_astern]) + pa[P.k_speed] * (u_t - u)
        want_u = math.copysign(db + (1 - db) * abs(want_u), want_u) if abs(want_u) > 1e-3 else 0.0
        want_r = pa[P.k_psi] * e_psi / pa[P.r_max]
    st[X.stick_u] = move_stick(st[X.stick_u], want_u, pa[P.stick_quantum], pa[P.stick_step])
    st[X.stick_r] = move_stick(st[X.stick_r], want_r, pa[P.stick_quantum], pa[P.stick_step])
    # done: stopped at the end of a berthing route, or past the end of a transit
    true_s, true_cross = route_project(pts, seg_len, seg_dir, s0, x, y)
    rem = length - true_s
    if stop_at_end:
        if abs(rem) < 3.0 and abs(sig[sl[S.u]]) < 0.03 and abs(sig[sl[S.v]]) < 0.05:
            st[X.done] = 1.0
            st[X.stick_u] = 0.0
            st[X.stick_r] = 0.0
    elif rem <= 0.0:
        st[X.done] = 1.0
    sig[sl[S.surge]] = st[X.stick_u]
    sig[sl[S.yaw]] = st[X.stick_r]
    sig[sl[S.u_target]] = u_t
    sig[sl[S.psi_des]] = psi_des
    sig[sl[S.cross_track]] = true_cross
    sig[sl[S.s_remaining]] = rem
    sig[sl[S.done]] = st[X.done]
    if st[X.done] != 0.0 and pa[P.stop_when_done] != 0.0:
        sig[sl[S.stop]] = 1.0


@register_block("ship.scripted_pilot")
class ScriptedPilot(LawBlock):
    """Scripted joystick pilot; see the module docstring; law :func:`pilot_law`.

    Parameters
    ----------
    cfg : PilotConfig
    route : Route
    mode : "open" | "pid" | "nonlinear"
        The joystick's mode (the pilot's technique depends on it).
    joy : JoystickConfig
        Stick scaling (u_max, r_max), which the pilot knows.
    speed_per_rps : float
        Steady speed per propeller rev/s (m/s per rev/s), the open-loop throttle map the pilot knows.
    n_open_rps : float
        Propeller speed at full surge stick in the open loop, rev/s.
    """

    role = "guidance"
    name = "pilot"
    law = staticmethod(pilot_law)
    signals = SIGNALS
    draws = True

    delay = param(P.delay, "this run's reaction delay, s (drawn at reset)")
    stick_u = entry("st", X.stick_u, float, "surge stick, [-1, 1]")
    stick_r = entry("st", X.stick_r, float, "yaw stick, [-1, 1]")
    done = entry("st", X.done, bool, "stopped at the end of the route (or past the end of a transit)")

    def __init__(self, cfg: PilotConfig, route: Route, mode: str, joy, speed_per_rps: float, n_open_rps: float):
        self.cfg = cfg
        self.route = route
        self.mode = mode
        self.joy = joy
        self.period = float(cfg.period)
        self.speed_per_rps = speed_per_rps
        self.n_open = n_open_rps
        self.bind(x="ship.x", y="ship.y", psi="ship.psi", u="ship.u", r="ship.r", v="ship.v",
                  surge="joystick.surge", yaw="joystick.yaw", u_target="pilot.u_target", psi_des="pilot.psi_des",
                  cross_track="pilot.cross_track", s_remaining="pilot.s_remaining", done="pilot.done",
                  stop="_stop")  # fmt: skip
        c = cfg
        head = PARAMS.pack(
            period=self.period,
            noise_time=c.noise_time_s,
            sigma=[math.radians(c.noise_heading_deg), c.noise_speed, math.radians(c.noise_yaw_rate_degps)],
            delay=0.0,
            lookahead=c.lookahead_m,
            stop_at_end=float(c.stop_at_end),
            lookahead_min=c.lookahead_min_m,
            steer_course=float(c.steer_course),
            u_cruise=c.cruise_kn * KNOT,
            brake_decel=c.brake_decel,
            k_stop=c.k_stop,
            closed=0.0 if mode == "open" else 1.0,
            speed_per_rps=speed_per_rps,
            n_open=n_open_rps,
            k_speed_open=c.k_speed_open,
            k_rate_open=c.k_rate_open,
            k_psi=c.k_psi,
            dead_band=joy.dead_band,
            stick_quantum=c.stick_quantum,
            stick_step=c.stick_step,
            u_max=joy.u_max_kn * KNOT,
            u_astern=max(joy.u_astern_kn * KNOT, 1e-6),
            k_speed=c.k_speed,
            r_max=math.radians(joy.r_max_degps),
            stop_when_done=float(c.stop_when_done),
            length=route.length,
            npt=len(route.p),
        )
        self.pa = np.concatenate([head, route.p.ravel(), route.seg_len, route.seg_dir.ravel(), route.s0])
        self.st = STATE.pack(dict.fromkeys(STATE.names, 0.0))

    @property
    def err(self) -> np.ndarray:
        """The perception errors: heading (rad), speed (m/s), yaw rate (rad/s); a view of the state."""
        return self.st[X.err : X.err + 3]

    @property
    def sig(self) -> np.ndarray:
        """Their stationary standard deviations (same units); a view of the parameters."""
        return self.pa[P.sigma : P.sigma + 3]

    def reset(self, rng: np.random.Generator) -> None:
        """Draw this run's reaction delay and the first perception errors; sticks centred, memory empty
        (a ring of ``delay / period + 3`` observations, more than the delay ever holds)."""
        self.rng = rng
        c = self.cfg
        self.delay = max(0.0, c.reaction_s + c.reaction_jitter_s * (2.0 * rng.random() - 1.0))
        cap = int(self.delay / self.period) + 3
        self.st = np.zeros(RING + ENTRY * cap)
        self.st[X.cap] = cap
        self.err[:] = self.sig * rng.standard_normal(3)
