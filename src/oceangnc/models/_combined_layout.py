"""Layout of the combined plant's flat parameter array (header, USV, UUV, scratch) and the end nodes.

The state layout is documented in :mod:`oceangnc.models.combined`; the offsets of its node positions,
node velocities and UUV states are stored in the header (``H_PO``, ``H_VO``, ``H_UO``) so that a winch
plant can reorder it. :func:`_ends` gives the two end nodes (the USV's attachment point and the UUV's
tow point, 003 eq. 2.30-2.31), :func:`_gather` all node positions/velocities into the scratch.
"""

from __future__ import annotations

import math

from numba import njit

from ..core.rotations import rzyx_entries
from ._sea_layout import top_heave, usv_motion_offset
from .uuv import NP as UUV_NP
from .uuv import P_RC

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
# sea (issue 29): offset of the sea block (0: calm water; layout in ._sea_layout), time of the last
# right-hand-side evaluation (the heaving top point and the published end forces read it)
H_SEA, H_T = 38, 39
# the three-point bridle (003 fig. 5-6): offset of its block (0: the single tow point; layout ._combined_bridle)
H_BRI = 59
P_USV = 40
N_USV = 15
P_UUV = 60
P_SCR = P_UUV + UUV_NP


# feature switches (oceangnc.core.variants): True here, so the functions as written handle every
# configuration (the runtime flags in p decide); ._combined_variants compiles copies with the features
# a plant does not use switched off, whose code numba then never compiles
SEA = WINCH = True


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
        ub, vb = x[3] - x[5] * ay, x[4] + x[5] * ax  # body velocity of the attachment point
        vel[0] = c * ub - s * vb
        vel[1] = s * ub + c * vb
        vel[2] = 0.0
    if SEA and p[H_SEA] > 0.0:  # a heaving top point (with the waves, or prescribed)
        s = int(p[H_SEA])
        dz, wz, _ = top_heave(p, s, p[H_T])
        pos[2] += dz
        vel[2] += wz
        dn, de, dd, vn, ve, vd = usv_motion_offset(x, p, s)  # the USV's wave-frequency motion (part B)
        pos[0] += dn
        pos[1] += de
        pos[2] += dd
        vel[0] += vn
        vel[1] += ve
        vel[2] += vd
    # bottom node (003 eq. 2.30-2.31)
    o, R, cx, cy, cz = tow_frame(x, p)
    b = 3 * n
    pos[b], pos[b + 1], pos[b + 2] = rot_add(R, x[o], x[o + 1], x[o + 2], cx, cy, cz)
    bu, bv, bw = cross_add(x[o + 6], x[o + 7], x[o + 8], x[o + 9], x[o + 10], x[o + 11], cx, cy, cz)
    vel[b], vel[b + 1], vel[b + 2] = rot_add(R, 0.0, 0.0, 0.0, bu, bv, bw)


@njit(cache=True, inline="always")
def tow_frame(x, p):
    """(o, R, c_x, c_y, c_z): the UUV's state offset, the 9 entries of its R_b^n and its tow point r_c (m, body)."""
    o = int(p[H_UO])
    return o, rzyx_entries(x[o + 3], x[o + 4], x[o + 5]), p[P_UUV + P_RC], p[P_UUV + P_RC + 1], p[P_UUV + P_RC + 2]


@njit(cache=True, inline="always")
def rot_add(R, e0, e1, e2, a, b, c):
    """e + R (a, b, c) for ``R`` the 9 row-major entries of a rotation matrix (summed left to right)."""
    return (
        e0 + R[0] * a + R[1] * b + R[2] * c,
        e1 + R[3] * a + R[4] * b + R[5] * c,
        e2 + R[6] * a + R[7] * b + R[8] * c,
    )


@njit(cache=True, inline="always")
def cross_add(u, v, w, p, q, r, cx, cy, cz):
    """(u, v, w) + (p, q, r) x (cx, cy, cz): the body-frame velocity of the body point r_c of a body moving
    at linear velocity (u, v, w) and angular velocity (p, q, r) (003 eq. 2.31)."""
    return u + q * cz - r * cy, v + r * cx - p * cz, w + p * cy - q * cx


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
    if WINCH and p[H_WIN] > 0.5:
        return x[int(p[H_WO])] - (n - 1) * p[H_L0]
    return p[H_L0]


@njit(cache=True)
def seabed_depth(p, xn, ye):
    """Depth (m, +down) of the plane seabed at (north, east): D + g_x x + g_y y."""
    return p[H_BED_D] + p[H_BED_GX] * xn + p[H_BED_GY] * ye


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
