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

INTEGRATORS = ("rk4", "rk4-split", "imex")
VAR_KEYS = [
    "cable.length",
    "cable.nodes",
    "cable.mass",
    "winch.speed",
    "winch.speed_cmd_sat",
    "winch.cmd_saturated",
    "winch.rendering",
    "winch.at_capacity",
    "winch.tension",
    "winch.power",
    "uuv.altitude",
    "cable.nodes_on_bed",
]
INPUT_NAMES = (
    "usv.thrust_port",
    "usv.thrust_stbd",
    "env.current_n",
    "env.current_e",
    "env.wind_n",
    "env.wind_e",
    "uuv.thrust_port",
    "uuv.thrust_stbd",
    "uuv.thrust_bow",
)

# parameter layout: header, USV params, UUV params, scratch
H_N, H_TOP, H_FIX, H_ATT, H_L0, H_EA, H_CV, H_MC, H_MA, H_WSEG, H_KDRAG = 0, 1, 2, 5, 8, 9, 10, 11, 12, 13, 14
H_CVE = 15  # axial damping inside the RHS (C_v for "rk4"; 0 for "rk4-split", except the last segment)
H_LAW, H_KDT = 16, 17  # drag law (0 loading functions, 1 normal-tangential), tangential drag factor
# seabed: flag, depth at the origin, gradient dz/dx, dz/dy, friction coefficient, contact frequency (rad/s),
# UUV contact radius (m)
H_BED, H_BED_D, H_BED_GX, H_BED_GY, H_BED_MU, H_BED_W, H_BED_R = 18, 19, 20, 21, 22, 23, 24
# state offsets (node positions, node velocities, UUV), so that a winch plant can reorder its state
H_PO, H_VO, H_UO = 25, 26, 27
# winch: flag, state offset (paid-out length, drum speed), max node count, speed/accel/tension limits,
# capacity, minimum length, speed-loop time constant, nominal segment length of the re-meshing
H_WIN, H_WO, H_NMAX, H_WV, H_WA, H_WT, H_WCAP, H_WMIN, H_WTAU = 28, 29, 30, 31, 32, 33, 34, 35, 36
H_BED_Z = 37  # damping ratio of the seabed contact
P_USV = 40
N_USV = 15
P_UUV = 60
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
    o = int(p[H_UO])
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
    pos = p[P_SCR : P_SCR + m]
    vel = p[P_SCR + m : P_SCR + 2 * m]
    F = p[P_SCR + 2 * m : P_SCR + 3 * m]
    Mn = p[P_SCR + 3 * m : P_SCR + 5 * m]
    _ends(x, p, n, pos, vel)
    po = int(p[H_PO])
    vo = int(p[H_VO])
    for k in range(3 * (n - 1)):
        pos[3 + k] = x[po + k]
        vel[3 + k] = x[vo + k]
    return pos, vel, F, Mn


@njit(cache=True)
def top_l0(x, p, n):
    """Unstretched length of the top segment (m): the winch's paid-out length minus the n - 1 nominal
    segments below it, or l0 without a winch."""
    if p[H_WIN] > 0.5:
        return x[int(p[H_WO])] - (n - 1) * p[H_L0]
    return p[H_L0]


@njit(cache=True)
def seabed_depth(p, xn, ye):
    """Depth (m, +down) of the plane seabed at (north, east): D + g_x x + g_y y."""
    return p[H_BED_D] + p[H_BED_GX] * xn + p[H_BED_GY] * ye


@njit(cache=True)
def _contact(p, x, y, z, vx, vy, vz, radius, mass):
    """Seabed penalty force (N, NED) on a point of contact radius ``radius`` and mass ``mass``.

    Plane z_b = D + g . (x, y); unit normal into the water nu = (g_x, g_y, -1) / |.|; penetration
    d = (z - z_b) / |(g_x, g_y, -1)| + radius. For d > 0: normal force N = m (w^2 d + 2 zeta w v_in),
    clipped >= 0 (a spring-damper of natural frequency w and damping ratio zeta per unit mass, so the
    static penetration is g' / w^2 whatever the mass), and a regularised Coulomb friction
    -mu N v_t / sqrt(|v_t|^2 + 0.01^2) against the velocity v_t along the bed.
    """
    gx = p[H_BED_GX]
    gy = p[H_BED_GY]
    nn = math.sqrt(gx * gx + gy * gy + 1.0)
    nx = gx / nn
    ny = gy / nn
    nz = -1.0 / nn
    d = (z - seabed_depth(p, x, y)) / nn + radius
    if d <= 0.0:
        return 0.0, 0.0, 0.0
    vn = vx * nx + vy * ny + vz * nz  # > 0: leaving the bed
    w = p[H_BED_W]
    fn = mass * (w * w * d - 2.0 * p[H_BED_Z] * w * vn)
    if fn <= 0.0:
        return 0.0, 0.0, 0.0
    tx = vx - vn * nx
    ty = vy - vn * ny
    tz = vz - vn * nz
    f = p[H_BED_MU] * fn / math.sqrt(tx * tx + ty * ty + tz * tz + 1e-4)
    return fn * nx - f * tx, fn * ny - f * ty, fn * nz - f * tz


@njit(cache=True)
def combined_rhs(t, x, u, p, out):
    """dx/dt of the combined USV + cable + UUV (layout in the module docstring); allocates nothing."""
    n = int(p[H_N])
    usv_rhs(t, x[0:6], u[0:6], p[P_USV : P_USV + N_USV], out[0:6])
    if p[H_TOP] > 0.5:
        for k in range(6):
            out[k] = 0.0
    pos, vel, F, Mn = _gather(x, p, n)
    lt = top_l0(x, p, n)
    ldot = x[int(p[H_WO]) + 1] if p[H_WIN] > 0.5 else 0.0
    cable_loads(
        pos,
        vel,
        F,
        Mn,
        n,
        p[H_L0],
        p[H_EA],
        p[H_CVE],
        p[H_MC],
        p[H_MA],
        p[H_WSEG],
        p[H_KDRAG],
        u[2],
        u[3],
        p[H_CV],
        int(p[H_LAW]),
        p[H_KDT],
        lt,
        ldot,
    )
    po = int(p[H_PO])
    vo = int(p[H_VO])
    bed = p[H_BED] > 0.5
    mnode = p[H_MC] + p[H_MA]
    for i in range(1, n):
        k = 3 * i
        if bed:
            fx, fy, fz = _contact(p, pos[k], pos[k + 1], pos[k + 2], vel[k], vel[k + 1], vel[k + 2], 0.0, mnode)
            F[k] += fx
            F[k + 1] += fy
            F[k + 2] += fz
        ax, ay, az = solve_sym3(Mn, 6 * i, F[k], F[k + 1], F[k + 2])
        j = 3 * (i - 1)
        out[po + j] = vel[k]
        out[po + j + 1] = vel[k + 1]
        out[po + j + 2] = vel[k + 2]
        out[vo + j] = ax
        out[vo + j + 1] = ay
        out[vo + j + 2] = az
    o = int(p[H_UO])
    b = 3 * n
    fbx = F[b]
    fby = F[b + 1]
    fbz = F[b + 2]
    if bed:  # UUV: a sphere of radius H_BED_R around the CB, force applied at the tow point
        cx, cy, cz = _contact(p, x[o], x[o + 1], x[o + 2], vel[b], vel[b + 1], vel[b + 2], p[H_BED_R], p[P_UUV + P_MRB])
        fbx += cx
        fby += cy
        fbz += cz
    uuv_deriv(x[o : o + 12], out[o : o + 12], p[P_UUV : P_UUV + UUV_NP], u[6], u[7], u[8], u[2], u[3], fbx, fby, fbz)
    if p[H_WIN] > 0.5:
        nmax = int(p[H_NMAX])
        for k in range(3 * (n - 1), 3 * (nmax - 1)):  # inactive node slots stay put
            out[po + k] = 0.0
            out[vo + k] = 0.0
        wo = int(p[H_WO])
        _winch_rhs(x, u, p, wo, F, out)


@njit(cache=True)
def winch_command(x, u, p, ttop):
    """Drum speed the winch tracks (m/s, + paying out): the command ``u[9]`` saturated to +-v_max;
    paying out at v_max while the top tension exceeds the limit (the winch renders rather than exceed
    it); zero at the drum's capacity (payout) or at the minimum length (haul-in)."""
    vmax = p[H_WV]
    sc = min(max(u[9], -vmax), vmax)
    if ttop > p[H_WT]:
        sc = vmax
    L = x[int(p[H_WO])]
    if L >= p[H_WCAP] and sc > 0.0:
        sc = 0.0
    if L <= p[H_WMIN] and sc < 0.0:
        sc = 0.0
    return sc


@njit(cache=True)
def _winch_rhs(x, u, p, wo, F, out):
    """Winch states: dL/dt = s (paid-out unstretched length), ds/dt = (s_c - s) / tau clipped to
    +-a_max (first-order speed loop with an acceleration limit)."""
    ttop = math.sqrt(F[0] ** 2 + F[1] ** 2 + F[2] ** 2)
    sc = winch_command(x, u, p, ttop)
    s = x[wo + 1]
    acc = (sc - s) / p[H_WTAU]
    amax = p[H_WA]
    out[wo] = s
    out[wo + 1] = min(max(acc, -amax), amax)


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
    lt = top_l0(x, p, n)
    law = int(p[H_LAW])
    ldot = x[int(p[H_WO]) + 1] if p[H_WIN] > 0.5 else 0.0
    cable_loads(
        pos[0:6],
        vel[0:6],
        F[0:6],
        Mn[0:12],
        1,
        p[H_L0],
        p[H_EA],
        p[H_CV],
        p[H_MC],
        p[H_MA],
        p[H_WSEG],
        p[H_KDRAG],
        ends[6],
        ends[7],
        -1.0,
        law,
        p[H_KDT],
        lt,
        ldot,
    )
    for k in range(3):
        ends[k] = F[k]
    b = 3 * (n - 1)
    lb = lt if n == 1 else -1.0
    lbd = ldot if n == 1 else 0.0
    cable_loads(
        pos[b : b + 6],
        vel[b : b + 6],
        F[0:6],
        Mn[0:12],
        1,
        p[H_L0],
        p[H_EA],
        p[H_CV],
        p[H_MC],
        p[H_MA],
        p[H_WSEG],
        p[H_KDRAG],
        ends[6],
        ends[7],
        -1.0,
        law,
        p[H_KDT],
        lb,
        lbd,
    )
    for k in range(3):
        ends[3 + k] = F[3 + k]


@njit(cache=True)
def _inv3(a, o, out, q):
    """Inverse of the general 3x3 matrix a[o:o+9] (row-major) into out[q:q+9]."""
    a0, a1, a2, a3, a4, a5, a6, a7, a8 = (
        a[o],
        a[o + 1],
        a[o + 2],
        a[o + 3],
        a[o + 4],
        a[o + 5],
        a[o + 6],
        a[o + 7],
        a[o + 8],
    )
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
    T = p[base : base + m3]  # tangents of segments 1..n at T[3 i - 3 ...], taut flag folded in (0 vector)
    D = p[base + m3 : base + m3 + 9 * (n + 1)]  # inverted modified diagonal blocks
    R = p[base + m3 + 9 * (n + 1) : base + m3 + 12 * (n + 1)]  # modified right-hand sides
    W = p[base + m3 + 12 * (n + 1) : base + m3 + 21 * (n + 1)]  # work 3x3 blocks
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
        # (slack segments and the last one use a zero tangent here, so their added mass counts
        # isotropically: a small inconsistency with the RHS's mass matrix, see docs/uuv-and-cable.md)
        A = W
        ta = (tax, tay, taz)
        tb = (tbx, tby, tbz)
        ma = ta
        mb = tb
        for r in range(3):
            for c in range(3):
                mm = (2.0 * mt if r == c else 0.0) - ha * (ma[r] * ma[c] + mb[r] * mb[c])
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
                acc += ((2.0 * mt if r == c else 0.0) - ha * (ma[r] * ma[c] + mb[r] * mb[c])) * vv[c]
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


# --- IMEX (linearly implicit) integrator: ROS2 W-method with the cable's axial stiffness implicit ------
ROS2_GAMMA = 1.0 + 1.0 / math.sqrt(2.0)


@njit(cache=True)
def _imex_base(n):
    return P_SCR + 40 * (n + 1)


@njit(cache=True)
def _imex_factor(x, p, n, gh):
    """Assemble and factor (M + gh C + gh^2 K) for the interior nodes 1..n-1 (block Thomas, O(n)).

    Uses the node positions and mass matrices left in the scratch by the last :func:`combined_rhs` call
    (at x_n). Per taut segment s (nodes s-1, s): tangent stiffness K_s = EA/l0 t t^T + T/l (I - t t^T)
    (axial spring plus the geometric stiffness of the tension T = EA (l - l0) / l0, the latter for taut
    segments only), damping C_s = C_v t t^T. Stores K_s (6), S_s = gh C_s + gh^2 K_s (6) per
    segment, the node mass matrices M_i (6) and the inverted modified diagonal blocks D_i^-1 (9).
    The top node and the UUV's tow point are not unknowns: the segments that join them add their S to
    the diagonal of nodes 1 and n-1 only.
    """
    m = 3 * (n + 1)
    pos = p[P_SCR : P_SCR + m]
    Mn = p[P_SCR + 3 * m : P_SCR + 5 * m]
    base = _imex_base(n)
    K = p[base : base + 6 * (n + 1)]
    S = p[base + 6 * (n + 1) : base + 12 * (n + 1)]
    Ms = p[base + 12 * (n + 1) : base + 18 * (n + 1)]
    Di = p[base + 18 * (n + 1) : base + 27 * (n + 1)]
    lt = top_l0(x, p, n)
    cv = p[H_CV]
    gh2 = gh * gh
    for s in range(1, n + 1):
        l0 = lt if s == 1 else p[H_L0]
        ea_l0 = p[H_EA] / l0
        a = 3 * (s - 1)
        b = 3 * s
        dx = pos[b] - pos[a]
        dy = pos[b + 1] - pos[a + 1]
        dz = pos[b + 2] - pos[a + 2]
        ln = math.sqrt(dx * dx + dy * dy + dz * dz)
        c = 6 * s
        if s == 1:  # winch: dF_1/dL and dF_1/ds (top segment taut), known-stage terms of the solve
            G = p[base + 30 * (n + 1) + 30 : base + 30 * (n + 1) + 36]
            for k in range(6):
                G[k] = 0.0
            if p[H_WIN] > 0.5 and ln > l0:
                gl = p[H_EA] * ln / (l0 * l0)
                gs = cv * ln / l0
                G[0] = gl * dx / ln
                G[1] = gl * dy / ln
                G[2] = gl * dz / ln
                G[3] = gs * dx / ln
                G[4] = gs * dy / ln
                G[5] = gs * dz / ln
        if ln > 0.0:
            # the axial stiffness and damping are kept in J while the segment is slack too: a segment that
            # becomes taut within the step must not meet an explicit stiff spring (W-method: any J keeps the
            # order; for a slack segment this only filters the relative axial velocity increments)
            tx = dx / ln
            ty = dy / ln
            tz = dz / ln
            g = ea_l0 * (ln - l0) / ln if ln > l0 else 0.0  # T / l (geometric stiffness, taut only)
            ka = ea_l0 - g
            K[c] = ka * tx * tx + g
            K[c + 1] = ka * tx * ty
            K[c + 2] = ka * tx * tz
            K[c + 3] = ka * ty * ty + g
            K[c + 4] = ka * ty * tz
            K[c + 5] = ka * tz * tz + g
            ghc = gh * cv
            S[c] = gh2 * K[c] + ghc * tx * tx
            S[c + 1] = gh2 * K[c + 1] + ghc * tx * ty
            S[c + 2] = gh2 * K[c + 2] + ghc * tx * tz
            S[c + 3] = gh2 * K[c + 3] + ghc * ty * ty
            S[c + 4] = gh2 * K[c + 4] + ghc * ty * tz
            S[c + 5] = gh2 * K[c + 5] + ghc * tz * tz
        else:
            for k in range(6):
                K[c + k] = 0.0
                S[c + k] = 0.0
    for k in range(6 * (n + 1)):
        Ms[k] = Mn[k]
    # forward elimination: D_1 = A_11; D_i = A_ii - S_i D_{i-1}^-1 S_i
    for i in range(1, n):
        cm = 6 * i
        ca = 6 * i  # segment i (above node i)
        cb = 6 * (i + 1)  # segment i+1 (below)
        a00 = Ms[cm] + S[ca] + S[cb]
        a01 = Ms[cm + 1] + S[ca + 1] + S[cb + 1]
        a02 = Ms[cm + 2] + S[ca + 2] + S[cb + 2]
        a11 = Ms[cm + 3] + S[ca + 3] + S[cb + 3]
        a12 = Ms[cm + 4] + S[ca + 4] + S[cb + 4]
        a22 = Ms[cm + 5] + S[ca + 5] + S[cb + 5]
        A = (a00, a01, a02, a01, a11, a12, a02, a12, a22)
        if i > 1:
            q = 9 * (i - 1)
            s00, s01, s02, s11, s12, s22 = S[ca], S[ca + 1], S[ca + 2], S[ca + 3], S[ca + 4], S[ca + 5]
            # W = D^-1 S (3x3), then S W
            w = p[base + 30 * (n + 1) + 12 : base + 30 * (n + 1) + 21]
            for r in range(3):
                d0 = Di[q + 3 * r]
                d1 = Di[q + 3 * r + 1]
                d2 = Di[q + 3 * r + 2]
                w[3 * r] = d0 * s00 + d1 * s01 + d2 * s02
                w[3 * r + 1] = d0 * s01 + d1 * s11 + d2 * s12
                w[3 * r + 2] = d0 * s02 + d1 * s12 + d2 * s22
            srow = (s00, s01, s02, s01, s11, s12, s02, s12, s22)
            A2 = p[base + 30 * (n + 1) + 21 : base + 30 * (n + 1) + 30]
            for r in range(3):
                for cc in range(3):
                    A2[3 * r + cc] = A[3 * r + cc] - (
                        srow[3 * r] * w[cc] + srow[3 * r + 1] * w[3 + cc] + srow[3 * r + 2] * w[6 + cc]
                    )
            _inv3(A2, 0, Di, 9 * i)
        else:
            A2 = p[base + 30 * (n + 1) + 21 : base + 30 * (n + 1) + 30]
            for k in range(9):
                A2[k] = A[k]
            _inv3(A2, 0, Di, 9 * i)


@njit(cache=True)
def _imex_end_increments(x, k, p, n, e):
    """Stage increments of the two end nodes (not unknowns of the implicit solve) into ``e`` (12):
    position part a_0, velocity part b_0 of the top node, then a_n, b_n of the UUV's tow point.

    They are the end nodes' positions/velocities linearised in the vehicles' states times the vehicles'
    stage vectors (which the implicit solve does not change): the J columns of the vehicles' states
    enter the cable rows as known terms, so the nodes next to the ends follow the vehicles' motion
    within the step instead of lagging by ~ gamma h v (which would be a first-order error).
    """
    if p[H_TOP] > 0.5:
        for j in range(6):
            e[j] = 0.0
    else:
        c = math.cos(x[2])
        s = math.sin(x[2])
        ax = p[H_ATT]
        ay = p[H_ATT + 1]
        kp = k[2]
        e[0] = k[0] + (-s * ax - c * ay) * kp
        e[1] = k[1] + (c * ax - s * ay) * kp
        e[2] = 0.0
        ub = x[3] - x[5] * ay
        vb = x[4] + x[5] * ax
        kub = k[3] - k[5] * ay
        kvb = k[4] + k[5] * ax
        e[3] = c * kub - s * kvb + (-s * ub - c * vb) * kp
        e[4] = s * kub + c * kvb + (c * ub - s * vb) * kp
        e[5] = 0.0
    o = int(p[H_UO])
    r00, r01, r02, r10, r11, r12, r20, r21, r22 = rzyx_entries(x[o + 3], x[o + 4], x[o + 5])
    cx = p[P_UUV + P_RC]
    cy = p[P_UUV + P_RC + 1]
    cz = p[P_UUV + P_RC + 2]
    # a_n = k_eta1 + R (Omega x r_c), Omega ~ the Euler-angle increments (small-angle rate map)
    wx = k[o + 3]
    wy = k[o + 4]
    wz = k[o + 5]
    bx = wy * cz - wz * cy
    by = wz * cx - wx * cz
    bz = wx * cy - wy * cx
    e[6] = k[o] + r00 * bx + r01 * by + r02 * bz
    e[7] = k[o + 1] + r10 * bx + r11 * by + r12 * bz
    e[8] = k[o + 2] + r20 * bx + r21 * by + r22 * bz
    # b_n = R (k_v + k_omega x r_c)
    pq = k[o + 9]
    q = k[o + 10]
    r = k[o + 11]
    bu = k[o + 6] + q * cz - r * cy
    bv = k[o + 7] + r * cx - pq * cz
    bw = k[o + 8] + pq * cy - q * cx
    e[9] = r00 * bu + r01 * bv + r02 * bw
    e[10] = r10 * bu + r11 * bv + r12 * bw
    e[11] = r20 * bu + r21 * bv + r22 * bw


@njit(cache=True)
def _imex_solve(x, p, n, k, gh):
    """Replace the cable part of the stage vector ``k`` by (I - gh J)^-1 k (J: cable axial Jacobian).

    With k = (a, q) (node velocities a, node accelerations q) the block system is
    (M + gh C + gh^2 K) b = M q - gh K a, then a' = a + gh b (see :func:`_imex_factor`).
    """
    if n < 2:
        return
    base = _imex_base(n)
    K = p[base : base + 6 * (n + 1)]
    S = p[base + 6 * (n + 1) : base + 12 * (n + 1)]
    Ms = p[base + 12 * (n + 1) : base + 18 * (n + 1)]
    Di = p[base + 18 * (n + 1) : base + 27 * (n + 1)]
    R = p[base + 27 * (n + 1) : base + 30 * (n + 1)]
    e = p[base + 30 * (n + 1) : base + 30 * (n + 1) + 12]
    _imex_end_increments(x, k, p, n, e)
    gh2 = gh * gh
    po = int(p[H_PO])
    vo = int(p[H_VO])
    # right-hand side and forward sweep
    for i in range(1, n):
        j = 3 * (i - 1)
        ax = k[po + j]
        ay = k[po + j + 1]
        az = k[po + j + 2]
        qx = k[vo + j]
        qy = k[vo + j + 1]
        qz = k[vo + j + 2]
        cm = 6 * i
        r0 = Ms[cm] * qx + Ms[cm + 1] * qy + Ms[cm + 2] * qz
        r1 = Ms[cm + 1] * qx + Ms[cm + 3] * qy + Ms[cm + 4] * qz
        r2 = Ms[cm + 2] * qx + Ms[cm + 4] * qy + Ms[cm + 5] * qz
        # (K a)_i = K_i (a_i - a_{i-1}) + K_{i+1} (a_i - a_{i+1}), a_0 = a_n = 0
        dx = ax
        dy = ay
        dz = az
        if i > 1:
            dx -= k[po + j - 3]
            dy -= k[po + j - 2]
            dz -= k[po + j - 1]
        c = 6 * i
        r0 -= gh * (K[c] * dx + K[c + 1] * dy + K[c + 2] * dz)
        r1 -= gh * (K[c + 1] * dx + K[c + 3] * dy + K[c + 4] * dz)
        r2 -= gh * (K[c + 2] * dx + K[c + 4] * dy + K[c + 5] * dz)
        dx = ax
        dy = ay
        dz = az
        if i < n - 1:
            dx -= k[po + j + 3]
            dy -= k[po + j + 4]
            dz -= k[po + j + 5]
        c = 6 * (i + 1)
        r0 -= gh * (K[c] * dx + K[c + 1] * dy + K[c + 2] * dz)
        r1 -= gh * (K[c + 1] * dx + K[c + 3] * dy + K[c + 4] * dz)
        r2 -= gh * (K[c + 2] * dx + K[c + 4] * dy + K[c + 5] * dz)
        # known end nodes j (top for i = 1, tow point for i = n - 1):
        # + gh K_s a_j + gh C_s b_j = K_s (gh a_j - gh^2 b_j) + S_s b_j
        for end in range(2):
            if (end == 0 and i != 1) or (end == 1 and i != n - 1):
                continue
            c = 6 if end == 0 else 6 * n
            eo = 6 * end
            ax_ = gh * e[eo] - gh2 * e[eo + 3]
            ay_ = gh * e[eo + 1] - gh2 * e[eo + 4]
            az_ = gh * e[eo + 2] - gh2 * e[eo + 5]
            bx_ = e[eo + 3]
            by_ = e[eo + 4]
            bz_ = e[eo + 5]
            r0 += K[c] * ax_ + K[c + 1] * ay_ + K[c + 2] * az_ + S[c] * bx_ + S[c + 1] * by_ + S[c + 2] * bz_
            r1 += K[c + 1] * ax_ + K[c + 3] * ay_ + K[c + 4] * az_ + S[c + 1] * bx_ + S[c + 3] * by_ + S[c + 4] * bz_
            r2 += K[c + 2] * ax_ + K[c + 4] * ay_ + K[c + 5] * az_ + S[c + 2] * bx_ + S[c + 4] * by_ + S[c + 5] * bz_
        if i == 1 and p[H_WIN] > 0.5:  # + gh (dF_1/dL k_L + dF_1/ds k_s), the winch's stage known
            G = p[base + 30 * (n + 1) + 30 : base + 30 * (n + 1) + 36]
            wo = int(p[H_WO])
            kl = gh * k[wo]
            ks = gh * k[wo + 1]
            r0 += G[0] * kl + G[3] * ks
            r1 += G[1] * kl + G[4] * ks
            r2 += G[2] * kl + G[5] * ks
        if i > 1:  # r_i += S_i D_{i-1}^-1 r_{i-1}
            q = 9 * (i - 1)
            ro = 3 * (i - 1)
            y0 = Di[q] * R[ro] + Di[q + 1] * R[ro + 1] + Di[q + 2] * R[ro + 2]
            y1 = Di[q + 3] * R[ro] + Di[q + 4] * R[ro + 1] + Di[q + 5] * R[ro + 2]
            y2 = Di[q + 6] * R[ro] + Di[q + 7] * R[ro + 1] + Di[q + 8] * R[ro + 2]
            c = 6 * i
            r0 += S[c] * y0 + S[c + 1] * y1 + S[c + 2] * y2
            r1 += S[c + 1] * y0 + S[c + 3] * y1 + S[c + 4] * y2
            r2 += S[c + 2] * y0 + S[c + 4] * y1 + S[c + 5] * y2
        R[3 * i] = r0
        R[3 * i + 1] = r1
        R[3 * i + 2] = r2
    # back substitution: b_i = D_i^-1 (r_i + S_{i+1} b_{i+1})
    b0 = 0.0
    b1 = 0.0
    b2 = 0.0
    for i in range(n - 1, 0, -1):
        r0 = R[3 * i]
        r1 = R[3 * i + 1]
        r2 = R[3 * i + 2]
        if i < n - 1:
            c = 6 * (i + 1)
            r0 += S[c] * b0 + S[c + 1] * b1 + S[c + 2] * b2
            r1 += S[c + 1] * b0 + S[c + 3] * b1 + S[c + 4] * b2
            r2 += S[c + 2] * b0 + S[c + 4] * b1 + S[c + 5] * b2
        q = 9 * i
        b0 = Di[q] * r0 + Di[q + 1] * r1 + Di[q + 2] * r2
        b1 = Di[q + 3] * r0 + Di[q + 4] * r1 + Di[q + 5] * r2
        b2 = Di[q + 6] * r0 + Di[q + 7] * r1 + Di[q + 8] * r2
        j = 3 * (i - 1)
        k[vo + j] = b0
        k[vo + j + 1] = b1
        k[vo + j + 2] = b2
        k[po + j] += gh * b0
        k[po + j + 1] += gh * b1
        k[po + j + 2] += gh * b2


@njit(cache=True)
def imex_advance(t, x, u, p, dt, nsteps, work, bound):
    """ROS2 steps (Verwer et al. 1999, a second-order L-stable Rosenbrock W-method, gamma = 1 + 1/sqrt 2)
    with the cable's axial stiffness and damping as the implicit part:

        (I - gamma h J) k1 = f(x_n)
        (I - gamma h J) k2 = f(x_n + h k1) - 2 k1
        x_{n+1} = x_n + 3/2 h k1 + 1/2 h k2

    f is the full right-hand side (:func:`combined_rhs`: drag, weight, added mass, both vehicles, all
    explicit); J is the Jacobian of the interior nodes' axial forces only (tangent stiffness and C_v,
    block tridiagonal, :func:`_imex_factor`), so each step costs two RHS evaluations, one block-Thomas
    factorisation and two O(n) solves. Second order for any J (W-method); with J = 0 it is Heun's
    method. Equilibria f(x) = 0 are fixed points for every h. Returns the new time, or -1 - k if the
    state became non-finite or exceeded ``bound`` at step k.
    """
    k1 = work[0]
    k2 = work[1]
    xt = work[4]
    m = x.size
    winch = p[H_WIN] > 0.5
    for s in range(nsteps):
        n = int(p[H_N])
        gh = ROS2_GAMMA * dt
        combined_rhs(t, x, u, p, k1)
        if n >= 2:
            _imex_factor(x, p, n, gh)
            _imex_solve(x, p, n, k1, gh)
        for i in range(m):
            xt[i] = x[i] + dt * k1[i]
        combined_rhs(t + dt, xt, u, p, k2)
        for i in range(m):
            k2[i] -= 2.0 * k1[i]
        if n >= 2:
            _imex_solve(x, p, n, k2, gh)
        ok = True
        for i in range(m):
            x[i] += dt * (1.5 * k1[i] + 0.5 * k2[i])
            if not (abs(x[i]) <= bound):
                ok = False
        if not ok:
            return -1.0 - s
        if winch:
            remesh(x, p)
        t += dt
    return t


@njit(cache=True)
def remesh(x, p):
    """Winch limits and node insertion/removal after a step (see :mod:`oceangnc.models.winch`).

    Clamps the paid-out length to [min_length, capacity] (stopping the drum there), then inserts a node
    when the top segment is longer than 1.5 l0 or removes node 1 when it is shorter than 0.5 l0. Node
    slots are shifted in place (O(n), a few times per metre of payout); returns +1 (inserted), -1
    (removed) or 0.
    """
    wo = int(p[H_WO])
    if x[wo] >= p[H_WCAP]:
        x[wo] = p[H_WCAP]
        x[wo + 1] = min(x[wo + 1], 0.0)
    if x[wo] <= p[H_WMIN]:
        x[wo] = p[H_WMIN]
        x[wo + 1] = max(x[wo + 1], 0.0)
    n = int(p[H_N])
    l0 = p[H_L0]
    lt = x[wo] - (n - 1) * l0
    po = int(p[H_PO])
    vo = int(p[H_VO])
    if lt > 1.5 * l0 and n < int(p[H_NMAX]):
        m = 3 * (n + 1)
        pos = p[P_SCR : P_SCR + m]
        vel = p[P_SCR + m : P_SCR + 2 * m]
        _ends(x, p, n, pos, vel)  # the ends only (node 0 and the tow point)
        for k in range(3 * (n - 1) - 1, -1, -1):  # node i -> i + 1
            x[po + 3 + k] = x[po + k]
            x[vo + 3 + k] = x[vo + k]
        if n >= 2:
            r1x, r1y, r1z = x[po + 3], x[po + 4], x[po + 5]
            v1x, v1y, v1z = x[vo + 3], x[vo + 4], x[vo + 5]
        else:
            b = 3 * n
            r1x, r1y, r1z = pos[b], pos[b + 1], pos[b + 2]
            v1x, v1y, v1z = vel[b], vel[b + 1], vel[b + 2]
        f = (lt - l0) / lt  # the new node's fraction of the way from the sheave
        x[po] = pos[0] + f * (r1x - pos[0])
        x[po + 1] = pos[1] + f * (r1y - pos[1])
        x[po + 2] = pos[2] + f * (r1z - pos[2])
        x[vo] = vel[0] + f * (v1x - vel[0])
        x[vo + 1] = vel[1] + f * (v1y - vel[1])
        x[vo + 2] = vel[2] + f * (v1z - vel[2])
        p[H_N] = n + 1
        return 1
    if lt < 0.5 * l0 and n > 1:
        if n >= 3:  # node 2 takes half of the top segment's mass and its momentum
            m2 = 1.0  # (in units of l0's node mass; all node masses scale with length alike)
            mt = 0.5 * lt / l0
            w = 1.0 / (m2 + mt)
            for a in range(3):
                x[vo + 3 + a] = (m2 * x[vo + 3 + a] + mt * x[vo + a]) * w
        for k in range(3 * (n - 2)):  # node i + 1 -> i
            x[po + k] = x[po + 3 + k]
            x[vo + k] = x[vo + 3 + k]
        for a in range(3):
            x[po + 3 * (n - 2) + a] = 0.0
            x[vo + 3 * (n - 2) + a] = 0.0
        p[H_N] = n - 1
        return -1
    return 0


def _check(cable: CableConfig, uuv: UUVConfig) -> None:
    if cable.segments < 1:
        raise ConfigError(f"cable.segments = {cable.segments}: allowed range 1 <= value")
    for key, v in (
        ("cable.length", cable.length),
        ("cable.diameter", cable.diameter),
        ("cable.E", cable.E),
        ("cable.density", cable.density),
        ("uuv.mass", uuv.mass),
    ):
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


@njit(cache=True)
def _fill_outputs_var(x, p, o_uuv, nodes, ends, out, u, nmax):
    """As :func:`_fill_outputs` for a winch and/or seabed plant: node columns for ``nmax`` + 1 nodes (the
    inactive ones at the tow point; ``cable.nodes`` tells how many are active), then cable.length, cable.nodes, cable.mass, winch.{speed, speed_cmd_sat,
    cmd_saturated, rendering, at_capacity, tension, power}, uuv.altitude, cable.nodes_on_bed."""
    n = int(p[H_N])
    m = 3 * (n + 1)
    _fill_outputs(x, p, o_uuv, nodes[0:m], ends, out)
    for i in range(m, 3 * (nmax + 1)):  # inactive node slots: collapsed onto the tow point
        out[23 + i] = nodes[m - 3 + i % 3]
    k = 23 + 3 * (nmax + 1)
    l0 = p[H_L0]
    lt = top_l0(x, p, n)
    ttop = out[20]
    if p[H_WIN] > 0.5:
        wo = int(p[H_WO])
        L = x[wo]
        sd = x[wo + 1]
        vmax = p[H_WV]
        out[k] = L
        out[k + 3] = sd
        out[k + 4] = winch_command(x, u, p, ttop)
        out[k + 5] = 1.0 if abs(u[9]) > vmax else 0.0
        out[k + 6] = 1.0 if ttop > p[H_WT] else 0.0
        out[k + 7] = 1.0 if (L >= p[H_WCAP] and u[9] > 0.0) else 0.0
        out[k + 8] = ttop
        out[k + 9] = -ttop * sd
    else:
        out[k] = (n - 1) * l0 + lt
        for j in range(3, 10):
            out[k + j] = 0.0
        out[k + 8] = ttop
    out[k + 1] = n + 1.0
    # mass of cable in the water: the segment masses the dynamics use, summed
    out[k + 2] = p[H_MC] * (n - 1) + p[H_MC] * lt / l0
    if p[H_BED] > 0.5:
        out[k + 10] = seabed_depth(p, x[o_uuv], x[o_uuv + 1]) - x[o_uuv + 2]
        cnt = 0
        for i in range(1, n):
            if nodes[3 * i + 2] > seabed_depth(p, nodes[3 * i], nodes[3 * i + 1]) - 1e-3:
                cnt += 1
        out[k + 11] = cnt
    else:
        out[k + 10] = np.nan
        out[k + 11] = 0.0


_UNITS = {
    "x": "m",
    "y": "m",
    "z": "m",
    "psi": "rad",
    "phi": "rad",
    "theta": "rad",
    "u": "m/s",
    "v": "m/s",
    "w": "m/s",
    "p": "rad/s",
    "q": "rad/s",
    "r": "rad/s",
    "speed": "m/s",
    "top_tension": "N",
    "bottom_tension": "N",
    "angle_deg": "deg",
    "length": "m",
    "nodes": "count",
    "mass": "kg",
    "speed_cmd_sat": "m/s",
    "cmd_saturated": "bool",
    "rendering": "bool",
    "at_capacity": "bool",
    "tension": "N",
    "power": "W",
    "altitude": "m",
    "nodes_on_bed": "count",
}


def _unit_of(key: str) -> str:
    body, _, leaf = key.partition(".")
    if body == "cable" and leaf[:1] in "xyz" and leaf[1:].isdigit():
        return "m"
    return _UNITS[leaf]


class CombinedPlant(Plant):
    """USV + cable + UUV as one plant (see the module docstring for layouts and signals).

    Parameters
    ----------
    usv_cfg, uuv_cfg, cable_cfg : the three configs.
    top : "usv" (top node on the USV's attachment point) or "fixed" (held at the USV's initial
        attachment point; the USV's states are frozen).
    name : plant name (used in divergence messages).
    """

    def __init__(
        self,
        usv_cfg: USVConfig,
        uuv_cfg: UUVConfig,
        cable_cfg: CableConfig,
        top: str = "usv",
        name: str = "combined",
        integrator: str | None = None,
        winch=None,
        seabed=None,
    ):
        if top not in ("usv", "fixed"):
            raise ConfigError(f"CombinedPlant top = {top!r}: allowed values 'usv', 'fixed'")
        integrator = integrator or cable_cfg.integrator
        if integrator not in INTEGRATORS:
            raise ConfigError(
                f"cable.integrator = {integrator!r}: allowed values " + ", ".join(repr(k) for k in INTEGRATORS)
            )
        has_winch = winch is not None and winch.enabled
        has_bed = seabed is not None and seabed.depth is not None
        if has_winch and integrator != "imex":
            raise ConfigError(
                f"cable.integrator = {integrator!r}: the winch (winch.enabled) needs 'imex' "
                "(its top segment may be short and stiff)"
            )
        self.integrator = integrator
        _check(cable_cfg, uuv_cfg)
        self.usv_cfg = usv_cfg
        self.uuv_cfg = uuv_cfg
        self.cable_cfg = cable_cfg
        self.winch_cfg = winch if has_winch else None
        self.seabed_cfg = seabed if has_bed else None
        self.top = top
        c = cable_cfg
        if has_winch:
            l0 = c.segment_length if c.segment_length is not None else c.length / c.segments
            if winch.capacity < c.length:
                raise ConfigError(
                    f"cable.length = {c.length:g}: above the drum's capacity winch.capacity = {winch.capacity:g} m"
                )
            if winch.min_length > c.length:
                raise ConfigError(f"cable.length = {c.length:g}: below winch.min_length = {winch.min_length:g} m")
            n = max(1, int(round(c.length / l0)))
            nmax = max(n, int(math.ceil(winch.capacity / l0 + 0.5)) + 1)
        else:
            l0 = c.l0
            n = c.segments
            nmax = n
        self.n_max = nmax
        psi0 = math.radians(usv_cfg.psi0_deg)
        cps, sps = math.cos(psi0), math.sin(psi0)
        top0 = (usv_cfg.x0 + cps * c.top_x - sps * c.top_y, usv_cfg.y0 + sps * c.top_x + cps * c.top_y, c.top_z)
        p = np.zeros(P_SCR + 40 * (nmax + 1) + 30 * (nmax + 1) + 36)
        p[H_N] = n
        p[H_TOP] = 1.0 if top == "fixed" else 0.0
        p[H_FIX : H_FIX + 3] = top0
        p[H_ATT : H_ATT + 3] = c.top_point
        area = c.area
        p[H_L0] = l0
        p[H_EA] = c.EA
        p[H_CV] = c.damping
        p[H_CVE] = 0.0 if integrator == "rk4-split" else c.damping
        p[H_MC] = c.density * area * l0
        p[H_MA] = c.added_mass_coeff * c.rho_water * area * l0
        p[H_WSEG] = c.weight_per_length * l0
        if c.drag_law == "normal-tangential":
            p[H_LAW] = 1.0
            p[H_KDRAG] = 0.5 * c.rho_water * c.cd_n * c.diameter * l0 if c.drag_on else 0.0
            p[H_KDT] = 0.5 * c.rho_water * c.cd_t * math.pi * c.diameter * l0 if c.drag_on else 0.0
        else:
            p[H_KDRAG] = 0.5 * c.rho_water * c.cd * c.diameter * l0 if c.drag_on else 0.0
        p[P_USV : P_USV + N_USV] = usv_cfg.params()
        p[P_UUV : P_UUV + UUV_NP] = uuv_cfg.params(tow_point=c.tow_point)
        if has_bed:
            sl = math.tan(math.radians(seabed.slope_deg))
            ds = math.radians(seabed.slope_direction_deg)
            p[H_BED] = 1.0
            p[H_BED_D] = seabed.depth
            p[H_BED_GX] = sl * math.cos(ds)
            p[H_BED_GY] = sl * math.sin(ds)
            p[H_BED_MU] = seabed.friction
            p[H_BED_W] = seabed.contact_frequency
            p[H_BED_Z] = seabed.contact_damping_ratio
            p[H_BED_R] = uuv_cfg.diameter / 2.0
            zb = seabed.depth + p[H_BED_GX] * top0[0] + p[H_BED_GY] * top0[1]
            if zb <= top0[2]:
                raise ConfigError(
                    f"environment.seabed.depth = {seabed.depth:g}: the seabed ({zb:.3g} m deep under "
                    f"the USV) is above the cable's attachment point (cable.top_z = {c.top_z:g} m)"
                )
        # state layout
        if has_winch:
            uo, wo, po = 6, 18, 20
            vo = po + 3 * (nmax - 1)
            size = vo + 3 * (nmax - 1)
            p[H_WIN] = 1.0
            p[H_WO] = wo
            p[H_NMAX] = nmax
            p[H_WV] = winch.speed_max
            p[H_WA] = winch.accel_max
            p[H_WT] = winch.tension_max
            p[H_WCAP] = winch.capacity
            p[H_WMIN] = winch.min_length
            p[H_WTAU] = winch.time_constant
        else:
            po = 6
            vo = 6 + 3 * (n - 1)
            uo = 6 + 6 * (n - 1)
            size = uo + 12
        p[H_PO], p[H_VO], p[H_UO] = po, vo, uo
        # initial state: USV, straight cable between the attachment points, UUV
        x0 = np.zeros(size)
        x0[:6] = [usv_cfg.x0, usv_cfg.y0, psi0, usv_cfg.u0, 0.0, 0.0]
        x0[uo : uo + 12] = uuv_cfg.initial_state()
        if has_winch:
            x0[wo] = c.length
        pos = np.zeros(3 * (n + 1))
        vel = np.zeros(3 * (n + 1))
        _ends(x0, p, n, pos, vel)
        pos = pos.reshape(-1, 3)
        vel = vel.reshape(-1, 3)
        lt = c.length - (n - 1) * l0
        for i in range(1, n):
            f = (lt + (i - 1) * l0) / c.length  # unstretched arc-length fraction of node i
            x0[po + 3 * (i - 1) : po + 3 * i] = (1 - f) * pos[0] + f * pos[n]
            x0[vo + 3 * (i - 1) : vo + 3 * i] = (1 - f) * vel[0] + f * vel[n]
        names = [f"usv.{s}" for s in USV_STATES]
        cab = [f"cable.{a}{i}" for i in range(1, nmax) for a in "xyz"]
        cab += [f"cable.v{a}{i}" for i in range(1, nmax) for a in "xyz"]
        if has_winch:
            names += [f"uuv.{s}" for s in UUV_STATES] + ["winch.length", "winch.speed"] + cab
        else:
            names += cab + [f"uuv.{s}" for s in UUV_STATES]
        mrb = p[P_UUV + P_MRB : P_UUV + P_MRB + 36].reshape(6, 6)
        ma = p[P_UUV + P_MA : P_UUV + P_MA + 36].reshape(6, 6)
        end_mass = float(mrb[0, 0] + ma[0, 0])
        if integrator == "imex":
            # no stability limit from the axial modes: the step is set by accuracy (docs/uuv-and-cable.md)
            self.stability_limit = math.inf
        else:
            self.stability_limit = axial_stability_limit(
                c, end_mass=end_mass, last_damper_only=(integrator == "rk4-split")
            )
            if has_bed:  # the explicit contact spring: RK4 limit 2.785 / w on the imaginary axis
                self.stability_limit = min(self.stability_limit, 2.0 / seabed.contact_frequency)
        inputs = INPUT_NAMES + (("winch.speed_cmd",) if has_winch else ())
        units = ("N", "N", "m/s", "m/s", "m/s", "m/s", "N", "N", "N") + (("m/s",) if has_winch else ())
        super().__init__(
            name,
            combined_rhs,
            x0,
            p,
            names,
            inputs,
            state_bound=1e6,
            max_dt=self.stability_limit if math.isfinite(self.stability_limit) else None,
            input_units=units,
            input_defaults=CALM,
        )
        self._var = has_winch or has_bed
        self._nodes = np.zeros(3 * (nmax + 1))
        self._ends = np.zeros(8)
        self.o_uuv = uo
        self._usv_keys = [f"usv.{s}" for s in USV_STATES]
        self._uuv_keys = [f"uuv.{s}" for s in UUV_STATES]
        self._node_keys = [f"cable.{a}{i}" for i in range(nmax + 1) for a in "xyz"]
        base = [
            *self._usv_keys,
            "usv.speed",
            *self._uuv_keys,
            "uuv.speed",
            "cable.top_tension",
            "cable.bottom_tension",
            "cable.angle_deg",
            *self._node_keys,
        ]
        self._out_keys = list(base)
        if self._var:
            extra = [
                k
                for k in VAR_KEYS
                if (has_winch or not k.startswith("winch.") or k == "winch.tension")
                and (has_bed or k not in ("uuv.altitude", "cable.nodes_on_bed"))
            ]
            self._out_keys += extra
            full = base + VAR_KEYS
            self._out_idx = np.array([full.index(k) for k in self._out_keys])
        self._out_full = np.zeros(len(base) + len(VAR_KEYS))
        self.output_units = {k: _unit_of(k) for k in self._out_keys}
        self._out = np.zeros(len(self._out_keys))

    @property
    def n(self) -> int:
        """Active number of segments (changes with a winch)."""
        return int(self.p[H_N])

    def reset(self) -> None:
        """Restore the initial state and node count."""
        super().reset()
        if self.winch_cfg is not None:
            l0 = self.p[H_L0]
            self.p[H_N] = max(1, int(round(self.cable_cfg.length / l0)))

    def advance(self, t: float, dt: float, n: int) -> float:
        """RK4 steps, for ``integrator="rk4-split"`` Strang-split steps (:func:`split_advance`), for
        ``"imex"`` ROS2 steps with the axial cable forces implicit (:func:`imex_advance`)."""
        if self.integrator == "rk4":
            return super().advance(t, dt, n)
        from ..errors import DivergenceError

        if self.integrator == "imex":
            t_new = imex_advance(t, self.x, self.u, self.p, dt, n, self.work, self.state_bound)
        else:
            t_new = split_advance(t, self.x, self.u, self.p, dt, n, self.work, self.state_bound)
        if t_new < 0.0:
            k = int(-t_new - 1.0)
            finite = bool(np.all(np.isfinite(self.x)))
            raise DivergenceError(
                t + (k + 1) * dt,
                self.name,
                self.state_dict(),
                reason="non-finite state" if not finite else f"|state| above {self.state_bound:g}",
            )
        return t_new

    # -- outputs -----------------------------------------------------------------------------------
    def cable_snapshot(self):
        """(nodes (n+1, 3) NED m, top force (3,) N, bottom force (3,) N) at the current state."""
        self._ends[6] = self.u[2]
        self._ends[7] = self.u[3]
        m = 3 * (self.n + 1)
        cable_state(self.x, self.p, self._nodes[:m], self._ends)
        return self._nodes[:m].reshape(-1, 3), self._ends[0:3], self._ends[3:6]

    def publish(self, bus: dict) -> None:
        """Write the vehicles' states (headings wrapped to (-pi, pi]), speeds, end tensions (N), cable
        angle from vertical (deg) and node positions (m, NED): one compiled call, one dict update."""
        self._ends[6] = self.u[2]
        self._ends[7] = self.u[3]
        if self._var:
            _fill_outputs_var(self.x, self.p, self.o_uuv, self._nodes, self._ends, self._out_full, self.u, self.n_max)
            self._out[:] = self._out_full[self._out_idx]
        else:
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
        vel = p[P_SCR + m : P_SCR + 2 * m].reshape(-1, 3)
        Mn = p[P_SCR + 3 * m : P_SCR + 5 * m].reshape(-1, 6)
        ke = 0.0
        for i in range(1, n):
            a = Mn[i]
            M = np.array([[a[0], a[1], a[2]], [a[1], a[3], a[4]], [a[2], a[4], a[5]]])
            ke += 0.5 * vel[i] @ M @ vel[i]
        seg = np.diff(nodes, axis=0)
        ln = np.linalg.norm(seg, axis=1)
        l0s = np.full(n, p[H_L0])
        l0s[0] = top_l0(self.x, p, n)
        eps = np.maximum(ln - l0s, 0.0) / l0s
        strain = 0.5 * p[H_EA] * float(np.sum(l0s * eps**2))
        zc = 0.5 * (nodes[:-1, 2] + nodes[1:, 2])
        pe = -p[H_WSEG] / p[H_L0] * float(np.sum(l0s * zc))
        o = self.o_uuv
        e_uuv = uuv_energy(self.x[o : o + 12], p[P_UUV : P_UUV + UUV_NP])
        return float(ke + strain + pe + e_uuv)

    def submerged_weight(self) -> float:
        """Submerged weight (N) of the whole cable plus the UUV."""
        n = self.n
        length = (n - 1) * self.p[H_L0] + top_l0(self.x, self.p, n)
        return self.cable_cfg.weight_per_length * length + self.uuv_cfg.weight_in_water_kgf * G
