"""The combined vehicle of 003 ch. 2.4: USV + lumped-mass cable + 6-DOF UUV as one plant.

One flat state, integrated by one compiled right-hand side :func:`combined_rhs`:

    x = [ USV (6): x, y, psi, u, v, r                       (models/usv.py, unchanged physics)
          cable interior node positions r_1..r_{n-1} (3(n-1), NED, m)
          cable interior node velocities v_1..v_{n-1} (3(n-1), m/s)
          UUV (12): x, y, z, phi, theta, psi, u, v, w, p, q, r  (models/uuv.py) ]

The end nodes are not states: the top node r_0 is the USV's attachment point (``cable.top_x/y/z`` in
the USV's body frame; a fixed point when ``top="fixed"``) and the bottom node r_n is the UUV's tow
point r_c, r_n = eta_1 + J_1 r_c and v_n = J_1 (v_1 + omega x r_c) (003 eq. 2.30-2.31). The force the
cable exerts on node n (tension of the last segment plus half its drag and submerged weight) acts
on the UUV at r_c (003 eq. 2.32-2.33). As in 003 ("the USV is assumed unaffected by the cable"), the
cable does not load the USV; the force it would exert on it is published as ``cable.top_tension``.

The half-segment masses at the two end nodes are carried by the vehicles: their weight and drag are
applied, their inertia (0.1 kg each for table 2-6) is neglected.

Inputs (bus keys): ``usv.thrust_port``, ``usv.thrust_stbd``, ``env.current_n``, ``env.current_e``,
``env.wind_n``, ``env.wind_e``, ``uuv.thrust_port``, ``uuv.thrust_stbd``, ``uuv.thrust_bow``.
Published: ``usv.{x,y,psi,u,v,r,speed}``, ``uuv.{x,y,z,phi,theta,psi,u,v,w,p,q,r,speed}``,
``cable.top_tension``, ``cable.bottom_tension`` (N, magnitudes of the cable's end forces),
``cable.angle_deg`` (angle from vertical of the top-to-bottom line) and ``cable.{x,y,z}{i}``.
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit

from ..core.blocks import Plant
from ..core.rotations import rzyx_entries, wrap
from ..core.signals import CALM
from ..errors import ConfigError
from ..units import G
from .cable import CableConfig, axial_stability_limit, cable_loads, solve_sym3
from .usv import STATE_NAMES as USV_STATES
from .usv import USVConfig, usv_rhs
from .uuv import NP as UUV_NP
from .uuv import P_MA, P_MRB, P_RC
from .uuv import STATE_NAMES as UUV_STATES
from .uuv import UUVConfig, uuv_deriv, uuv_energy

USV_UNITS, UUV_UNITS = ("m", "m", "rad", "m/s", "m/s", "rad/s"), ("m",) * 3 + ("rad",) * 3 + ("m/s",) * 3 + ("rad/s",) * 3
INPUT_NAMES = ("usv.thrust_port", "usv.thrust_stbd", "env.current_n", "env.current_e", "env.wind_n",
               "env.wind_e", "uuv.thrust_port", "uuv.thrust_stbd", "uuv.thrust_bow")

# parameter layout: header, USV params, UUV params, scratch
H_N, H_TOP, H_FIX, H_ATT, H_L0, H_EA, H_CV, H_MC, H_MA, H_WSEG, H_KDRAG = 0, 1, 2, 5, 8, 9, 10, 11, 12, 13, 14
H_CVE = 15  # axial damping inside the RHS (C_v for "rk4"; 0 for "rk4-split", except the last segment)
P_USV = 20
N_USV = 15
P_UUV = 40
P_SCR = P_UUV + UUV_NP


@njit(cache=True)
def _ends(x, p, n, pos, vel):
    """Write the top (node 0) and bottom (node n) positions/velocities into ``pos``/``vel``."""
    # top node
    if p[H_TOP] > 0.5:
        pos[0] = p[H_FIX]
        pos[1] = p[H_FIX + 1]
        pos[2] = p[H_FIX + 2]
        vel[0] = 0.0
        vel[1] = 0.0
        vel[2] = 0.0
    else:
        c = math.cos(x[2])
        s = math.sin(x[2])
        ax = p[H_ATT]
        ay = p[H_ATT + 1]
        pos[0] = x[0] + c * ax - s * ay
        pos[1] = x[1] + s * ax + c * ay
        pos[2] = p[H_ATT + 2]
        ub = x[3] - x[5] * ay
        vb = x[4] + x[5] * ax
        vel[0] = c * ub - s * vb
        vel[1] = s * ub + c * vb
        vel[2] = 0.0
    # bottom node (003 eq. 2.30-2.31)
    o = 6 + 6 * (n - 1)
    phi = x[o + 3]
    th = x[o + 4]
    psi = x[o + 5]
    r00, r01, r02, r10, r11, r12, r20, r21, r22 = rzyx_entries(phi, th, psi)
    cx = p[P_UUV + P_RC]
    cy = p[P_UUV + P_RC + 1]
    cz = p[P_UUV + P_RC + 2]
    b = 3 * n
    pos[b] = x[o] + r00 * cx + r01 * cy + r02 * cz
    pos[b + 1] = x[o + 1] + r10 * cx + r11 * cy + r12 * cz
    pos[b + 2] = x[o + 2] + r20 * cx + r21 * cy + r22 * cz
    pq = x[o + 9]
    q = x[o + 10]
    r = x[o + 11]
    bu = x[o + 6] + q * cz - r * cy
    bv = x[o + 7] + r * cx - pq * cz
    bw = x[o + 8] + pq * cy - q * cx
    vel[b] = r00 * bu + r01 * bv + r02 * bw
    vel[b + 1] = r10 * bu + r11 * bv + r12 * bw
    vel[b + 2] = r20 * bu + r21 * bv + r22 * bw


@njit(cache=True)
def _gather(x, p, n):
    """Node positions/velocities into the scratch part of ``p``; returns the scratch views."""
    m = 3 * (n + 1)
    pos = p[P_SCR:P_SCR + m]
    vel = p[P_SCR + m:P_SCR + 2 * m]
    F = p[P_SCR + 2 * m:P_SCR + 3 * m]
    Mn = p[P_SCR + 3 * m:P_SCR + 5 * m]
    _ends(x, p, n, pos, vel)
    vo = 6 + 3 * (n - 1)
    for k in range(3 * (n - 1)):
        pos[3 + k] = x[6 + k]
        vel[3 + k] = x[vo + k]
    return pos, vel, F, Mn


@njit(cache=True)
def combined_rhs(t, x, u, p, out):
    """dx/dt of the combined USV + cable + UUV (layout in the module docstring); allocates nothing."""
    n = int(p[H_N])
    usv_rhs(t, x[0:6], u[0:6], p[P_USV:P_USV + N_USV], out[0:6])
    if p[H_TOP] > 0.5:
        for k in range(6):
            out[k] = 0.0
    pos, vel, F, Mn = _gather(x, p, n)
    cable_loads(pos, vel, F, Mn, n, p[H_L0], p[H_EA], p[H_CVE], p[H_MC], p[H_MA], p[H_WSEG], p[H_KDRAG],
                u[2], u[3], p[H_CV])
    vo = 6 + 3 * (n - 1)
    for i in range(1, n):
        k = 3 * i
        ax, ay, az = solve_sym3(Mn, 6 * i, F[k], F[k + 1], F[k + 2])
        j = 3 * (i - 1)
        out[6 + j] = vel[k]
        out[6 + j + 1] = vel[k + 1]
        out[6 + j + 2] = vel[k + 2]
        out[vo + j] = ax
        out[vo + j + 1] = ay
        out[vo + j + 2] = az
    o = 6 + 6 * (n - 1)
    b = 3 * n
    uuv_deriv(x[o:o + 12], out[o:o + 12], p[P_UUV:P_UUV + UUV_NP], u[6], u[7], u[8], u[2], u[3],
              F[b], F[b + 1], F[b + 2])


@njit(cache=True)
def cable_state(x, p, nodes, ends):
    """Node positions into ``nodes`` (3(n+1)) and the end forces (top xyz, bottom xyz, N) into ``ends``.

    The top force is the one the cable exerts on the top attachment, the bottom force the one on the
    UUV (both: tension of the end segment plus half its drag and submerged weight). Current is taken
    from ``ends[6:8]`` (NED, m/s) on entry.
    """
    n = int(p[H_N])
    pos, vel, F, Mn = _gather(x, p, n)
    for k in range(3 * (n + 1)):
        nodes[k] = pos[k]
    # only the two end segments matter: run the segment loads on one-segment views
    args = (p[H_L0], p[H_EA], p[H_CV], p[H_MC], p[H_MA], p[H_WSEG], p[H_KDRAG], ends[6], ends[7])
    cable_loads(pos[0:6], vel[0:6], F[0:6], Mn[0:12], 1, *args)
    for k in range(3):
        ends[k] = F[k]
    b = 3 * (n - 1)
    cable_loads(pos[b:b + 6], vel[b:b + 6], F[0:6], Mn[0:12], 1, *args)
    for k in range(3):
        ends[3 + k] = F[3 + k]


@njit(cache=True)
def _inv3(a, o, out, q):
    """Inverse of the general 3x3 matrix a[o:o+9] (row-major) into out[q:q+9]."""
    a0, a1, a2, a3, a4, a5, a6, a7, a8 = a[o], a[o + 1], a[o + 2], a[o + 3], a[o + 4], a[o + 5], a[o + 6], a[o + 7], a[o + 8]
    c0 = a4 * a8 - a5 * a7
    c1 = a5 * a6 - a3 * a8
    c2 = a3 * a7 - a4 * a6
    det = a0 * c0 + a1 * c1 + a2 * c2
    d = 1.0 / det
    out[q] = c0 * d
    out[q + 1] = (a2 * a7 - a1 * a8) * d
    out[q + 2] = (a1 * a5 - a2 * a4) * d
    out[q + 3] = c1 * d
    out[q + 4] = (a0 * a8 - a2 * a6) * d
    out[q + 5] = (a2 * a3 - a0 * a5) * d
    out[q + 6] = c2 * d
    out[q + 7] = (a1 * a6 - a0 * a7) * d
    out[q + 8] = (a0 * a4 - a1 * a3) * d


@njit(cache=True)
def damping_substep(x, p, h):
    """Backward-Euler step of length ``h`` of the axial damping alone on the interior node velocities.

    Solves (M + h C) v+ = M v for the block-tridiagonal damping matrix C of the stretched segments
    (C_v t t^T per segment, 003 eq. 2.23) of segments 1..n-1 by the block Thomas algorithm, the top
    node's velocity held (the USV is not loaded by the cable). The last segment's damper stays in the
    explicit RHS, so its reaction acts on the UUV. Unconditionally stable and dissipative.
    """
    n = int(p[H_N])
    cv = p[H_CV]
    if n < 2 or cv == 0.0:
        return
    pos, vel, F, Mn = _gather(x, p, n)
    m3 = 3 * (n + 1)
    base = P_SCR + 15 * (n + 1)
    T = p[base:base + m3]  # tangents of segments 1..n at T[3 i - 3 ...], taut flag folded in (0 vector)
    D = p[base + m3:base + m3 + 9 * (n + 1)]  # inverted modified diagonal blocks
    R = p[base + m3 + 9 * (n + 1):base + m3 + 12 * (n + 1)]  # modified right-hand sides
    W = p[base + m3 + 12 * (n + 1):base + m3 + 21 * (n + 1)]  # work 3x3 blocks
    l0 = p[H_L0]
    mt = 0.5 * (p[H_MC] + p[H_MA])
    ha = 0.5 * p[H_MA]
    for i in range(1, n + 1):
        a = 3 * (i - 1)
        b = 3 * i
        dx = pos[b] - pos[a]
        dy = pos[b + 1] - pos[a + 1]
        dz = pos[b + 2] - pos[a + 2]
        ln = math.sqrt(dx * dx + dy * dy + dz * dz)
        k = 3 * (i - 1)
        if ln > l0 and i < n:  # the last segment's damper stays explicit (its reaction acts on the UUV)
            T[k] = dx / ln
            T[k + 1] = dy / ln
            T[k + 2] = dz / ln
        else:
            T[k] = 0.0
            T[k + 1] = 0.0
            T[k + 2] = 0.0
    hc = h * cv
    # forward sweep over interior nodes i = 1..n-1; segment i joins nodes i-1, i
    for i in range(1, n):
        ka = 3 * (i - 1)  # segment i (above)
        kb = 3 * i  # segment i+1 (below)
        tax, tay, taz = T[ka], T[ka + 1], T[ka + 2]
        tbx, tby, tbz = T[kb], T[kb + 1], T[kb + 2]
        # node mass matrix (both adjacent segments, eq. 2.28), with the *current* tangents
        # (slack segments use a zero tangent above; their mass still counts isotropically)
        A = W
        ta = (tax, tay, taz)
        tb = (tbx, tby, tbz)
        for r in range(3):
            for c in range(3):
                mm = (2.0 * mt if r == c else 0.0) - ha * (ta[r] * ta[c] + tb[r] * tb[c])
                A[3 * r + c] = mm + hc * (ta[r] * ta[c] + tb[r] * tb[c])
        vi0 = vel[3 * i]
        vi1 = vel[3 * i + 1]
        vi2 = vel[3 * i + 2]
        r0 = 0.0
        r1 = 0.0
        r2 = 0.0
        vv = (vi0, vi1, vi2)
        for r in range(3):
            acc = 0.0
            for c in range(3):
                acc += ((2.0 * mt if r == c else 0.0) - ha * (ta[r] * ta[c] + tb[r] * tb[c])) * vv[c]
            if r == 0:
                r0 = acc
            elif r == 1:
                r1 = acc
            else:
                r2 = acc
        if i == 1:  # top node velocity held: + h c t t^T v_0
            v0 = vel[0] * tax + vel[1] * tay + vel[2] * taz
            r0 += hc * tax * v0
            r1 += hc * tay * v0
            r2 += hc * taz * v0
        if i > 1:
            # L = A_{i,i-1} D_{i-1}^{-1} with A_{i,i-1} = -hc ta ta^T; A' = A - L A_{i-1,i} (= -hc ta ta^T)
            q = 9 * (i - 1)
            # u = D^{-1} ta ; s = ta . D^{-1} ta ; L v = -hc ta (ta^T D^{-1} v)
            u0 = D[q] * tax + D[q + 1] * tay + D[q + 2] * taz
            u1 = D[q + 3] * tax + D[q + 4] * tay + D[q + 5] * taz
            u2 = D[q + 6] * tax + D[q + 7] * tay + D[q + 8] * taz
            w0 = tax * D[q] + tay * D[q + 3] + taz * D[q + 6]
            w1 = tax * D[q + 1] + tay * D[q + 4] + taz * D[q + 7]
            w2 = tax * D[q + 2] + tay * D[q + 5] + taz * D[q + 8]
            sdot = tax * u0 + tay * u1 + taz * u2
            g = hc * hc * sdot
            for r in range(3):
                for c in range(3):
                    A[3 * r + c] -= g * ta[r] * ta[c]
            rp = 3 * (i - 1)
            proj = w0 * R[rp] + w1 * R[rp + 1] + w2 * R[rp + 2]
            r0 += hc * tax * proj
            r1 += hc * tay * proj
            r2 += hc * taz * proj
        _inv3(A, 0, D, 9 * i)
        R[3 * i] = r0
        R[3 * i + 1] = r1
        R[3 * i + 2] = r2
    # back substitution: v_i = D_i^{-1} (R_i - A_{i,i+1} v_{i+1}), A_{i,i+1} = -hc tb tb^T
    vo = 6 + 3 * (n - 1)
    nx0 = 0.0
    nx1 = 0.0
    nx2 = 0.0
    for i in range(n - 1, 0, -1):
        kb = 3 * i
        tbx, tby, tbz = T[kb], T[kb + 1], T[kb + 2]
        b0 = R[3 * i]
        b1 = R[3 * i + 1]
        b2 = R[3 * i + 2]
        if i < n - 1:
            pr = tbx * nx0 + tby * nx1 + tbz * nx2
            b0 += hc * tbx * pr
            b1 += hc * tby * pr
            b2 += hc * tbz * pr
        q = 9 * i
        nx0 = D[q] * b0 + D[q + 1] * b1 + D[q + 2] * b2
        nx1 = D[q + 3] * b0 + D[q + 4] * b1 + D[q + 5] * b2
        nx2 = D[q + 6] * b0 + D[q + 7] * b1 + D[q + 8] * b2
        j = vo + 3 * (i - 1)
        x[j] = nx0
        x[j + 1] = nx1
        x[j + 2] = nx2


@njit(cache=True)
def split_advance(t, x, u, p, dt, nsteps, work, bound):
    """Strang splitting: damping(dt/2, implicit) - RK4(dt, everything else) - damping(dt/2, implicit).

    The closing and opening half steps of consecutive steps are fused into one backward-Euler step of
    dt (exact for the first-order damping flow up to O(dt^2), like the splitting itself). Second order; removes the overdamped axial mode (lambda ~ -C_v 4 / m_c) from the explicit
    part, whose limit is then that of the axial springs alone. Returns the new time, or -1 - k if the
    state became non-finite or exceeded ``bound`` in magnitude at step k.
    """
    k1 = work[0]
    k2 = work[1]
    k3 = work[2]
    k4 = work[3]
    xt = work[4]
    m = x.size
    damping_substep(x, p, 0.5 * dt)
    for s in range(nsteps):
        # RK4 written out (not core.integrators.rk4_step): passing combined_rhs as a value would stop
        # numba from caching this function on disk
        combined_rhs(t, x, u, p, k1)
        for i in range(m):
            xt[i] = x[i] + 0.5 * dt * k1[i]
        combined_rhs(t + 0.5 * dt, xt, u, p, k2)
        for i in range(m):
            xt[i] = x[i] + 0.5 * dt * k2[i]
        combined_rhs(t + 0.5 * dt, xt, u, p, k3)
        for i in range(m):
            xt[i] = x[i] + dt * k3[i]
        combined_rhs(t + dt, xt, u, p, k4)
        ok = True
        for i in range(m):
            x[i] += dt / 6.0 * (k1[i] + 2.0 * k2[i] + 2.0 * k3[i] + k4[i])
            if not (abs(x[i]) <= bound):  # also catches NaN
                ok = False
        if not ok:
            return -1.0 - s
        # the closing half step of this step and the opening half step of the next are fused
        damping_substep(x, p, dt if s < nsteps - 1 else 0.5 * dt)
        t += dt
    return t


def _check(cable: CableConfig, uuv: UUVConfig) -> None:
    if cable.segments < 1:
        raise ConfigError(f"cable.segments = {cable.segments}: allowed range 1 <= value")
    for key, v in (("cable.length", cable.length), ("cable.diameter", cable.diameter), ("cable.E", cable.E),
                   ("cable.density", cable.density), ("uuv.mass", uuv.mass)):
        if not (v > 0 and math.isfinite(v)):
            raise ConfigError(f"{key} = {v}: must be > 0")


@njit(cache=True)
def _fill_outputs(x, p, o_uuv, nodes, ends, out):
    """Published outputs in the order of ``CombinedPlant._out_keys`` (see :meth:`CombinedPlant.publish`)."""
    cable_state(x, p, nodes, ends)
    for i in range(6):
        out[i] = x[i]
    out[2] = wrap(x[2])
    out[6] = math.hypot(x[3], x[4])
    for i in range(12):
        out[7 + i] = x[o_uuv + i]
    out[7 + 5] = wrap(x[o_uuv + 5])
    out[19] = math.sqrt(x[o_uuv + 6] ** 2 + x[o_uuv + 7] ** 2 + x[o_uuv + 8] ** 2)
    out[20] = math.sqrt(ends[0] ** 2 + ends[1] ** 2 + ends[2] ** 2)
    out[21] = math.sqrt(ends[3] ** 2 + ends[4] ** 2 + ends[5] ** 2)
    m = nodes.size
    dx = nodes[m - 3] - nodes[0]
    dy = nodes[m - 2] - nodes[1]
    dz = nodes[m - 1] - nodes[2]
    out[22] = math.degrees(math.atan2(math.hypot(dx, dy), dz))
    for i in range(m):
        out[23 + i] = nodes[i]


class CombinedPlant(Plant):
    """USV + cable + UUV as one plant (see the module docstring for layouts and signals).

    Parameters
    ----------
    usv_cfg, uuv_cfg, cable_cfg : the three configs.
    top : "usv" (top node on the USV's attachment point) or "fixed" (held at the USV's initial
        attachment point; the USV's states are frozen).
    name : plant name (used in divergence messages).
    """

    def __init__(self, usv_cfg: USVConfig, uuv_cfg: UUVConfig, cable_cfg: CableConfig, top: str = "usv",
                 name: str = "combined", integrator: str | None = None):
        if top not in ("usv", "fixed"):
            raise ConfigError(f"CombinedPlant top = {top!r}: allowed values 'usv', 'fixed'")
        integrator = integrator or cable_cfg.integrator
        if integrator not in ("rk4", "rk4-split"):
            raise ConfigError(f"cable.integrator = {integrator!r}: allowed values 'rk4', 'rk4-split'")
        self.integrator = integrator
        _check(cable_cfg, uuv_cfg)
        self.usv_cfg = usv_cfg
        self.uuv_cfg = uuv_cfg
        self.cable_cfg = cable_cfg
        self.top = top
        n = cable_cfg.segments
        self.n = n
        c = cable_cfg
        p = np.zeros(P_SCR + 15 * (n + 1) + 25 * (n + 1))
        p[H_N] = n
        p[H_TOP] = 1.0 if top == "fixed" else 0.0
        psi0 = math.radians(usv_cfg.psi0_deg)
        cps, sps = math.cos(psi0), math.sin(psi0)
        top0 = (usv_cfg.x0 + cps * c.top_x - sps * c.top_y, usv_cfg.y0 + sps * c.top_x + cps * c.top_y, c.top_z)
        p[H_FIX:H_FIX + 3] = top0
        p[H_ATT:H_ATT + 3] = c.top_point
        p[H_L0] = c.l0
        p[H_EA] = c.EA
        p[H_CV] = c.damping
        p[H_CVE] = c.damping if integrator == "rk4" else 0.0
        p[H_MC] = c.segment_mass
        p[H_MA] = c.segment_added_mass
        p[H_WSEG] = c.weight_per_length * c.l0
        p[H_KDRAG] = 0.5 * c.rho_water * c.cd * c.diameter * c.l0 if c.drag_on else 0.0
        p[P_USV:P_USV + N_USV] = usv_cfg.params()
        p[P_UUV:P_UUV + UUV_NP] = uuv_cfg.params(tow_point=c.tow_point)
        # initial state: USV, straight cable between the attachment points, UUV
        xu = np.array([usv_cfg.x0, usv_cfg.y0, psi0, usv_cfg.u0, 0.0, 0.0])
        xv = uuv_cfg.initial_state()
        x0 = np.zeros(6 + 6 * (n - 1) + 12)
        x0[:6] = xu
        x0[6 + 6 * (n - 1):] = xv
        pos = np.zeros(3 * (n + 1))
        vel = np.zeros(3 * (n + 1))
        _ends(x0, p, n, pos, vel)
        pos = pos.reshape(-1, 3)
        vel = vel.reshape(-1, 3)
        for i in range(1, n):
            f = i / n
            x0[6 + 3 * (i - 1):6 + 3 * i] = (1 - f) * pos[0] + f * pos[n]
            x0[6 + 3 * (n - 1) + 3 * (i - 1):6 + 3 * (n - 1) + 3 * i] = (1 - f) * vel[0] + f * vel[n]
        names = [f"usv.{s}" for s in USV_STATES]
        names += [f"cable.{a}{i}" for i in range(1, n) for a in "xyz"]
        names += [f"cable.v{a}{i}" for i in range(1, n) for a in "xyz"]
        names += [f"uuv.{s}" for s in UUV_STATES]
        mrb = p[P_UUV + P_MRB:P_UUV + P_MRB + 36].reshape(6, 6)
        ma = p[P_UUV + P_MA:P_UUV + P_MA + 36].reshape(6, 6)
        end_mass = float(mrb[0, 0] + ma[0, 0])
        self.stability_limit = axial_stability_limit(c, end_mass=end_mass,
                                                     last_damper_only=(integrator == "rk4-split"))
        super().__init__(name, combined_rhs, x0, p, names, INPUT_NAMES, state_bound=1e6,
                         max_dt=self.stability_limit, input_units=("N", "N", "m/s", "m/s", "m/s", "m/s", "N", "N", "N"), input_defaults=CALM)
        self._nodes = np.zeros(3 * (n + 1))
        self._ends = np.zeros(8)
        self.o_uuv = 6 + 6 * (n - 1)
        self._usv_keys = [f"usv.{s}" for s in USV_STATES]
        self._uuv_keys = [f"uuv.{s}" for s in UUV_STATES]
        self._node_keys = [f"cable.{a}{i}" for i in range(n + 1) for a in "xyz"]
        self._out_keys = [*self._usv_keys, "usv.speed", *self._uuv_keys, "uuv.speed", "cable.top_tension",
                          "cable.bottom_tension", "cable.angle_deg", *self._node_keys]
        self._out = np.zeros(len(self._out_keys))
        self.output_units = dict(zip(self._out_keys, [*USV_UNITS, "m/s", *UUV_UNITS, "m/s", "N", "N", "deg", *["m"] * len(self._node_keys)]))

    def advance(self, t: float, dt: float, n: int) -> float:
        """RK4 steps, or for ``integrator="rk4-split"`` Strang-split steps (see :func:`split_advance`)."""
        if self.integrator == "rk4":
            return super().advance(t, dt, n)
        from ..errors import DivergenceError

        t_new = split_advance(t, self.x, self.u, self.p, dt, n, self.work, self.state_bound)
        if t_new < 0.0:
            k = int(-t_new - 1.0)
            finite = bool(np.all(np.isfinite(self.x)))
            raise DivergenceError(t + (k + 1) * dt, self.name, self.state_dict(),
                                  reason="non-finite state" if not finite else f"|state| above {self.state_bound:g}")
        return t_new

    # -- outputs -----------------------------------------------------------------------------------
    def cable_snapshot(self):
        """(nodes (n+1, 3) NED m, top force (3,) N, bottom force (3,) N) at the current state."""
        self._ends[6] = self.u[2]
        self._ends[7] = self.u[3]
        cable_state(self.x, self.p, self._nodes, self._ends)
        return self._nodes.reshape(-1, 3), self._ends[0:3], self._ends[3:6]

    def publish(self, bus: dict) -> None:
        """Write the vehicles' states (headings wrapped to (-pi, pi]), speeds, end tensions (N), cable
        angle from vertical (deg) and node positions (m, NED): one compiled call, one dict update."""
        self._ends[6] = self.u[2]
        self._ends[7] = self.u[3]
        _fill_outputs(self.x, self.p, self.o_uuv, self._nodes, self._ends, self._out)
        bus.update(zip(self._out_keys, self._out.tolist()))

    # -- diagnostics -------------------------------------------------------------------------------
    def energy(self) -> float:
        """Mechanical energy (J) in still water: UUV (kinetic + potential), cable interior nodes'
        kinetic energy (with their current mass matrices), cable potential (submerged weight at the
        segment centres) and strain energy 1/2 EA l0 eps^2 of stretched segments. The USV is not
        included (the cable does not act on it). Conserved when drag, damping and added mass are off.
        """
        n = self.n
        nodes, _, _ = self.cable_snapshot()
        combined_rhs(0.0, self.x, self.u, self.p, np.zeros_like(self.x))  # fills node velocities and masses
        p = self.p
        m = 3 * (n + 1)
        vel = p[P_SCR + m:P_SCR + 2 * m].reshape(-1, 3)
        Mn = p[P_SCR + 3 * m:P_SCR + 5 * m].reshape(-1, 6)
        ke = 0.0
        for i in range(1, n):
            a = Mn[i]
            M = np.array([[a[0], a[1], a[2]], [a[1], a[3], a[4]], [a[2], a[4], a[5]]])
            ke += 0.5 * vel[i] @ M @ vel[i]
        seg = np.diff(nodes, axis=0)
        ln = np.linalg.norm(seg, axis=1)
        eps = np.maximum(ln - p[H_L0], 0.0) / p[H_L0]
        strain = 0.5 * p[H_EA] * p[H_L0] * float(np.sum(eps ** 2))
        zc = 0.5 * (nodes[:-1, 2] + nodes[1:, 2])
        pe = -p[H_WSEG] * float(np.sum(zc))
        o = self.o_uuv
        e_uuv = uuv_energy(self.x[o:o + 12], p[P_UUV:P_UUV + UUV_NP])
        return float(ke + strain + pe + e_uuv)

    def submerged_weight(self) -> float:
        """Submerged weight (N) of the whole cable plus the UUV."""
        return self.cable_cfg.weight_per_length * self.cable_cfg.length + self.uuv_cfg.weight_in_water_kgf * G
