"""Planning the USV's motion from the towed UUV's plan (document 000 eq. 32-34).

Inverting the trailer relations (000 eq. 3-4, see :mod:`oceangnc.models.towed_trailer`): a UUV
profile of speed u_UUV, heading psi_UUV and yaw rate r_UUV is produced by a USV whose offset angle
phi = psi_UUV - psi_USV, heading and speed are::

    tan(phi_d)   = -L r_UUV / u_UUV          (32 and 34 solved together)
    psi_USV      = psi_UUV - phi_d           (33)
    u_USV        = u_UUV / cos(phi_d)        (34)

000 prints (32) as ``phi_d = asin(L r_UUV / u_USV)``, which lacks the minus sign of (4) and uses
u_USV, itself unknown until (34); substituting (34) into (4) gives the tan form (SPEC.md 000
notes). The USV path follows by integrating (1), ``x' = u_USV cos psi_USV, y' = u_USV sin psi_USV``
from ``p_USV(0) = p_UUV(0) + L (cos psi_UUV(0), sin psi_UUV(0))``; it equals the closed form
``p_UUV + L (cos psi_UUV, sin psi_UUV)`` (checked in the tests). Waypoints are samples of that path.

Table 3 of 000 (the demo profile): 4 m/s; 0-50 s heading 45 deg (200 m NE); a clockwise half turn of
radius 40 m to 225 deg (31.4 s); 200 m SW (50 s); an anticlockwise half turn of radius 40 m back to
45 deg; 200 m NE. The table's 225.1 deg, 81.4 s, 162.8 s and misprinted 131.1 s are the roundings of
the exact values pi R / u = 31.416 s used here.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from ..models.towed_trailer import trailer_offset_for


@dataclass
class Profile:
    """A planar motion sampled in time: t (s), x, y (m, NED), psi (rad, unwrapped), u (m/s), r (rad/s).

    Segment boundaries appear twice in ``t`` (end of one segment, start of the next), so that jumps of
    r (and of the USV heading planned from it) are represented exactly.
    """

    t: np.ndarray
    x: np.ndarray
    y: np.ndarray
    psi: np.ndarray
    u: np.ndarray
    r: np.ndarray


@dataclass
class USVPlan(Profile):
    """The USV's planned motion (:class:`Profile`) plus the offset angle ``phi`` (rad) and cable length ``L`` (m)."""

    phi: np.ndarray = None
    L: float = 0.0


def segments_profile(
    segments, speed: float, psi0: float, x0: float = 0.0, y0: float = 0.0, dt: float = 0.05
) -> Profile:
    """Profile made of constant-speed, constant-yaw-rate segments ``[(duration_s, r_rad_s), ...]``.

    Positions are exact arcs (no integration error).
    """
    ts, xs, ys, ps, rs = [], [], [], [], []
    t0, x, y, psi = 0.0, float(x0), float(y0), float(psi0)
    for dur, r in segments:
        n = max(2, int(math.ceil(dur / dt)) + 1)
        tau = np.linspace(0.0, dur, n)
        p = psi + r * tau
        if abs(r) > 1e-12:
            xx = x + speed / r * (np.sin(p) - math.sin(psi))
            yy = y + speed / r * (math.cos(psi) - np.cos(p))
        else:
            xx = x + speed * tau * math.cos(psi)
            yy = y + speed * tau * math.sin(psi)
        ts.append(t0 + tau)
        xs.append(xx)
        ys.append(yy)
        ps.append(p)
        rs.append(np.full(n, float(r)))
        t0, x, y, psi = t0 + dur, float(xx[-1]), float(yy[-1]), float(p[-1])
    t = np.concatenate(ts)
    return Profile(
        t, np.concatenate(xs), np.concatenate(ys), np.concatenate(ps), np.full(t.size, float(speed)), np.concatenate(rs)
    )


def table3_profile(
    speed: float = 4.0,
    radius: float = 40.0,
    leg: float = 200.0,
    psi0_deg: float = 45.0,
    x0: float = 0.0,
    y0: float = 0.0,
    dt: float = 0.05,
) -> Profile:
    """The UUV plan of 000 table 3 (straight, clockwise half turn, straight, anticlockwise half turn, straight)."""
    r = speed / radius
    t_leg = leg / speed
    t_turn = math.pi * radius / speed
    segs = [(t_leg, 0.0), (t_turn, r), (t_leg, 0.0), (t_turn, -r), (t_leg, 0.0)]
    return segments_profile(segs, speed, math.radians(psi0_deg), x0, y0, dt)


def plan_usv(profile: Profile, L: float) -> USVPlan:
    """The USV's offset angle, heading, speed and path for a UUV profile (000 eq. 32-34 and 1)."""
    if not L > 0:
        raise ValueError(f"cable length must be > 0 m, got {L}")
    u = np.asarray(profile.u, float)
    if np.any(u <= 0):
        raise ValueError("the UUV profile speed must be > 0 everywhere (eq. 32 divides by it)")
    phi = trailer_offset_for(u, profile.r, L)  # eq. 32/34: the inverse of the trailer's eq. 3-4
    psi = profile.psi - phi
    us = u / np.cos(phi)
    t = profile.t
    # eq. 1 integrated with the trapezoid rule; duplicated boundary times contribute nothing
    vx = us * np.cos(psi)
    vy = us * np.sin(psi)
    h = np.diff(t)
    x0 = profile.x[0] + L * math.cos(profile.psi[0])
    y0 = profile.y[0] + L * math.sin(profile.psi[0])
    x = x0 + np.concatenate([[0.0], np.cumsum(0.5 * h * (vx[1:] + vx[:-1]))])
    y = y0 + np.concatenate([[0.0], np.cumsum(0.5 * h * (vy[1:] + vy[:-1]))])
    # r_USV = r_UUV - phi_d' (phi_d is constant on constant-yaw-rate segments; its jumps are corners)
    dphi = np.zeros_like(t)
    ok = h > 0
    dphi[:-1][ok] = np.diff(phi)[ok] / h[ok]
    r = profile.r - dphi
    return USVPlan(t, x, y, psi, us, r, phi=phi, L=float(L))


def usv_path_closed_form(profile: Profile, L: float):
    """USV path ``p_UUV + L (cos psi_UUV, sin psi_UUV)`` (m): the trailer geometry, for checking (1)."""
    return profile.x + L * np.cos(profile.psi), profile.y + L * np.sin(profile.psi)


def waypoints_from_plan(plan: Profile, spacing_s: float = 5.0):
    """Waypoints (n, 2) [north, east in m] and speeds (n,) [m/s] sampled from a plan every ``spacing_s`` s.

    The plan's segment boundaries (its corners, where the planned heading jumps) are always kept.
    """
    t = plan.t
    keep = np.zeros(t.size, bool)
    keep[0] = keep[-1] = True
    dup = np.nonzero(np.diff(t) == 0.0)[0]
    keep[dup] = True
    dupset = set(dup.tolist())
    next_t = spacing_s
    for i in range(t.size):
        if t[i] >= next_t - 1e-9 or i in dupset:
            keep[i] = True
            next_t = t[i] + spacing_s
    idx = np.nonzero(keep)[0]
    # drop waypoints closer than 1 m to the previous one (corner duplicates)
    sel = [idx[0]]
    for i in idx[1:]:
        if math.hypot(plan.x[i] - plan.x[sel[-1]], plan.y[i] - plan.y[sel[-1]]) > 1.0:
            sel.append(i)
    sel = np.array(sel)
    # the speed of the leg that starts at a waypoint (the sample just after it, past a corner)
    return np.column_stack([plan.x[sel], plan.y[sel]]), np.asarray(plan.u[np.minimum(sel + 1, t.size - 1)], float)
