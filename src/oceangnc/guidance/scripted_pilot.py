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
from collections import deque
from typing import Literal

import numpy as np
from pydantic import Field

from ..core.blocks import Block
from ..core.registry import register_block
from ..core.rotations import wrap
from ..io.config import StrictModel
from ..sensors.filters import gauss_markov
from ..units import KNOT


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


class Route:
    """A polyline route (N, E) with projection and look-ahead along it."""

    def __init__(self, points):
        self.p = np.asarray(points, dtype=float)
        d = np.diff(self.p, axis=0)
        self.seg_len = np.hypot(d[:, 0], d[:, 1])
        self.seg_dir = d / self.seg_len[:, None]
        self.s0 = np.concatenate([[0.0], np.cumsum(self.seg_len)])
        self.length = float(self.s0[-1])

    def project(self, n: float, e: float):
        """(s along the route, signed cross-track offset (starboard of the route positive), segment)."""
        rel = np.array([n, e]) - self.p[:-1]
        t = np.einsum("ij,ij->i", rel, self.seg_dir)
        tc = np.clip(t, 0.0, self.seg_len)
        # extend the last segment beyond its end, the first before its start
        tc[-1] = max(0.0, t[-1]) if len(tc) > 1 else t[-1]
        if len(tc) > 1:
            tc[0] = min(t[0], self.seg_len[0])
        foot = self.p[:-1] + tc[:, None] * self.seg_dir
        dist = np.hypot(n - foot[:, 0], e - foot[:, 1])
        i = int(np.argmin(dist))
        cross = self.seg_dir[i, 0] * (e - foot[i, 1]) - self.seg_dir[i, 1] * (n - foot[i, 0])
        return float(self.s0[i] + tc[i]), float(cross), i

    def point_at(self, s: float):
        """Point at arc length s (extrapolated along the end segments)."""
        if s >= self.length:
            return self.p[-1] + (s - self.length) * self.seg_dir[-1]
        if s <= 0:
            return self.p[0] + s * self.seg_dir[0]
        i = int(np.searchsorted(self.s0, s, side="right") - 1)
        return self.p[i] + (s - self.s0[i]) * self.seg_dir[i]

    def centre_east(self, north):
        """East coordinate of the route at the given north coordinates (route monotonic in north)."""
        return np.interp(north, self.p[:, 0], self.p[:, 1])


@register_block("ship.scripted_pilot")
class ScriptedPilot(Block):
    """Scripted joystick pilot; see the module docstring.

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

    def __init__(self, cfg: PilotConfig, route: Route, mode: str, joy, speed_per_rps: float, n_open_rps: float):
        self.cfg = cfg
        self.route = route
        self.mode = mode
        self.joy = joy
        self.period = float(cfg.period)
        self.speed_per_rps = speed_per_rps
        self.n_open = n_open_rps
        self.inputs = {
            "ship.x": "m",
            "ship.y": "m",
            "ship.psi": "rad",
            "ship.u": "m/s",
            "ship.v": "m/s",
            "ship.r": "rad/s",
        }
        self.outputs = {
            "joystick.surge": "1",
            "joystick.yaw": "1",
            "pilot.u_target": "m/s",
            "pilot.psi_des": "rad",
            "pilot.cross_track": "m",
            "pilot.s_remaining": "m",
            "pilot.done": "bool",
        }

    def reset(self, rng: np.random.Generator) -> None:
        self.rng = rng
        c = self.cfg
        self.delay = max(0.0, c.reaction_s + c.reaction_jitter_s * (2.0 * rng.random() - 1.0))
        self.memory: deque = deque()
        self.stick_u = 0.0
        self.stick_r = 0.0
        self.done = False
        self.err = np.zeros(3)  # perception errors: heading (rad), speed (m/s), yaw rate (rad/s)
        self.sig = np.array([math.radians(c.noise_heading_deg), c.noise_speed, math.radians(c.noise_yaw_rate_degps)])
        self.err[:] = self.sig * rng.standard_normal(3)

    def _decide(self, obs):
        c = self.cfg
        n, e, psi, u, r, v = obs
        s, cross, _ = self.route.project(n, e)
        look = c.lookahead_m
        if c.stop_at_end:  # closing the berth, the eye comes nearer: 50 m + half the remaining distance
            look = min(look, max(c.lookahead_min_m, 50.0 + 0.5 * (self.route.length - s)))
        aim = self.route.point_at(s + look)
        psi_des = math.atan2(aim[1] - e, aim[0] - n)
        # steer the track, not the bow: course over ground (the crab in current / wind comes free)
        course = psi + math.atan2(v, u) if c.steer_course and math.hypot(u, v) > 0.1 else psi
        e_psi = wrap(psi_des - course)
        s_rem = self.route.length - s
        u_cruise = c.cruise_kn * KNOT
        if c.stop_at_end:
            if s_rem > 0:
                u_t = min(u_cruise, math.sqrt(2 * c.brake_decel * s_rem), c.k_stop * s_rem)
            else:
                u_t = max(-0.2, c.k_stop * s_rem)
        else:
            u_t = u_cruise
        u_max = self.joy.u_max_kn * KNOT
        r_max = math.radians(self.joy.r_max_degps)
        if self.mode == "open":
            want_u = u_t / (self.speed_per_rps * self.n_open) + c.k_speed_open * (u_t - u)
            want_r = c.k_rate_open * (c.k_psi * e_psi - r)
        else:
            astern = max(self.joy.u_astern_kn * KNOT, 1e-6)
            db = self.joy.dead_band
            want_u = (u_t / u_max if u_t >= 0 else u_t / astern) + c.k_speed * (u_t - u)
            want_u = math.copysign(db + (1 - db) * abs(want_u), want_u) if abs(want_u) > 1e-3 else 0.0
            want_r = c.k_psi * e_psi / r_max
        return want_u, want_r, u_t, psi_des, cross, s_rem

    def _move(self, cur: float, want: float) -> float:
        c = self.cfg
        want = max(-1.0, min(1.0, want))
        if c.stick_quantum > 0:
            want = round(want / c.stick_quantum) * c.stick_quantum
        step = max(-c.stick_step, min(c.stick_step, want - cur))
        return max(-1.0, min(1.0, cur + step))

    def compiled(self):
        """Compiled form for the fused loop (:func:`oceangnc.control._compiled_berthing.pilot_step`)."""
        from ..control._compiled_berthing import _PP, pilot_step
        from ..core.fused import CompiledBlock

        c, j, rt = self.cfg, self.joy, self.route
        cap = int(self.delay / self.period) + 3
        if len(self.memory) > cap:
            return None
        ring = np.zeros(7 * cap)
        for k, (tk, obs) in enumerate(self.memory):
            ring[7 * k] = tk
            ring[7 * k + 1 : 7 * k + 7] = obs
        st = np.concatenate(
            [[self.stick_u, self.stick_r, 1.0 if self.done else 0.0, *self.err, len(self.memory), 0.0, cap], ring]
        )
        head = [
            self.period,
            c.noise_time_s,
            *self.sig,
            self.delay,
            c.lookahead_m,
            float(c.stop_at_end),
            c.lookahead_min_m,
            float(c.steer_course),
            c.cruise_kn * KNOT,
            c.brake_decel,
            c.k_stop,
            0.0 if self.mode == "open" else 1.0,
            self.speed_per_rps,
            self.n_open,
            c.k_speed_open,
            c.k_rate_open,
            c.k_psi,
            j.dead_band,
            c.stick_quantum,
            c.stick_step,
            j.u_max_kn * KNOT,
            max(j.u_astern_kn * KNOT, 1e-6),
            c.k_speed,
            math.radians(j.r_max_degps),
            float(c.stop_when_done),
        ]
        head += [0.0] * (_PP - 2 - len(head)) + [rt.length, len(rt.p)]
        pa = np.concatenate([head, rt.p.ravel(), rt.seg_len, rt.seg_dir.ravel(), rt.s0])
        sig = [
            "ship.x",
            "ship.y",
            "ship.psi",
            "ship.u",
            "ship.r",
            "ship.v",
            "joystick.surge",
            "joystick.yaw",
            "pilot.u_target",
            "pilot.psi_des",
            "pilot.cross_track",
            "pilot.s_remaining",
            "pilot.done",
            "_stop",
        ]
        return CompiledBlock(pilot_step, sig, st, pa, rng=self.rng)

    def step(self, t: float, bus: dict) -> None:
        c = self.cfg
        a = math.exp(-self.period / c.noise_time_s)
        self.err = gauss_markov(self.err, a, self.sig, self.rng.standard_normal(3))
        obs = (
            bus["ship.x"],
            bus["ship.y"],
            bus["ship.psi"] + self.err[0],
            bus["ship.u"] + self.err[1],
            bus["ship.r"] + self.err[2],
            bus["ship.v"],
        )
        self.memory.append((t, obs))
        while len(self.memory) > 1 and self.memory[1][0] <= t - self.delay + 1e-9:
            self.memory.popleft()
        seen = self.memory[0][1]
        want_u, want_r, u_t, psi_des, cross, s_rem = self._decide(seen)
        self.stick_u = self._move(self.stick_u, want_u)
        self.stick_r = self._move(self.stick_r, want_r)
        # done: stopped at the end of a berthing route, or past the end of a transit
        true_s, true_cross, _ = self.route.project(bus["ship.x"], bus["ship.y"])
        rem = self.route.length - true_s
        if c.stop_at_end:
            if abs(rem) < 3.0 and abs(bus["ship.u"]) < 0.03 and abs(bus["ship.v"]) < 0.05:
                self.done = True
                self.stick_u = 0.0
                self.stick_r = 0.0
        elif rem <= 0.0:
            self.done = True
        bus["joystick.surge"] = self.stick_u
        bus["joystick.yaw"] = self.stick_r
        bus["pilot.u_target"] = u_t
        bus["pilot.psi_des"] = psi_des
        bus["pilot.cross_track"] = true_cross
        bus["pilot.s_remaining"] = rem
        bus["pilot.done"] = float(self.done)
        if self.done and c.stop_when_done:
            bus["_stop"] = True
