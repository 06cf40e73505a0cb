"""The combined plant's compiled right-hand side and cable end forces (layout: :mod:`._combined_layout`).

:func:`combined_rhs` is dx/dt of USV + lumped-mass cable + UUV (003 ch. 2.4); :func:`cable_state` the
node positions and the forces the cable exerts at its two ends; :func:`_contact` the seabed penalty
force on a node or on the UUV.
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit

from ._combined_layout import (
    H_N,
    H_TOP,
    H_L0,
    H_EA,
    H_CV,
    H_MC,
    H_MA,
    H_WSEG,
    H_KDRAG,
    H_CVE,
    H_LAW,
    H_KDT,
    H_BED,
    H_BED_GX,
    H_BED_GY,
    H_BED_MU,
    H_BED_W,
    H_BED_R,
    H_PO,
    H_VO,
    H_UO,
    H_WIN,
    H_WO,
    H_NMAX,
    H_BED_Z,
    H_SEA,
    H_T,
    H_BRI,
    P_USV,
    N_USV,
    P_UUV,
    UUV_NP,
    _gather,
    _ends,
    top_l0,
    seabed_depth,
    tow_frame,
    rot_add,
    cross_add,
)
from ._combined_bridle import (
    B_APEX,
    B_F,
    B_J,
    B_MN,
    B_POS,
    B_RES,
    B_RJ,
    B_VEL,
    NEWTON_MAX,
    add_tangent,
    junction_newton,
    search,
)
from ._combined_winch import _winch_rhs
from .cable import cable_loads, segment, solve_sym3
from .usv import _M11, _M22, _M33, usv_rhs
from ._sea_layout import NCOEF, S_FKSEG, S_MDISP, S_NPT, S_TMID, S_WF, W_DRIFT, W_FD, coef_base, point_kinematics
from ._usv_waves import wf_rhs
from .uuv import P_MRB, P_RC, uuv_deriv, uuv_deriv_flow

# constants as numpy scalars, not Python literals: numba compiles a callee once per *literal* argument value
# (``_loads(..., 1, ...)`` and ``_loads(..., n, ...)`` would be two compilations of the whole cable law)
_I0, _I1, _TRUE = np.int64(0), np.int64(1), np.bool_(True)


# feature switches (oceangnc.core.variants): True here, so the functions as written handle every
# configuration (the runtime flags in p decide); ._combined_variants compiles copies with the features
# a plant does not use switched off, whose code numba then never compiles
SEA = BED = WINCH = BRIDLE = True


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
def _loads(p, pos, vel, F, Mn, n, cv, vcn, vce, cv_last, l0_top, ldot_top):
    """:func:`~oceangnc.models.cable.cable_loads` with the cable's parameters from the header of ``p``, in
    calm water: no wave coefficients (an empty array, so that calm water and waves call one compiled
    ``cable_loads``: one compilation fewer in a first run)."""
    cable_loads(
        pos, vel, F, Mn, n, p[H_L0], p[H_EA], cv, p[H_MC], p[H_MA], p[H_WSEG], p[H_KDRAG], vcn, vce, cv_last,
        int(p[H_LAW]), p[H_KDT], l0_top, ldot_top, p[0:0], 0.0, 0.0,
    )  # fmt: skip


@njit(cache=True)
def _loads_sea(p, pos, vel, F, Mn, n, cv, vcn, vce, cv_last, l0_top, ldot_top, first, t):
    """:func:`_loads` in waves: segments ``first`` + 1 .. ``first`` + n of the sea block's expansions,
    evaluated at time ``t`` (s)."""
    s = int(p[H_SEA])
    c = coef_base(p, s) + NCOEF * first
    wv = p[c : c + NCOEF * n]
    cable_loads(
        pos, vel, F, Mn, n, p[H_L0], p[H_EA], cv, p[H_MC], p[H_MA], p[H_WSEG], p[H_KDRAG], vcn, vce, cv_last,
        int(p[H_LAW]), p[H_KDT], l0_top, ldot_top, wv, t - p[s + S_TMID], p[s + S_FKSEG],
    )  # fmt: skip


@njit(cache=True)
def combined_rhs(t, x, u, p, out):
    """dx/dt of the combined USV + cable + UUV (layout in the module docstring); allocates nothing."""
    n = int(p[H_N])
    sea = p[H_SEA] > 0.0
    if SEA and sea:
        p[H_T] = t
    if BRIDLE and p[H_BRI] > 0.0:
        bridle_update(x, p, n, u[2], u[3])
    usv_rhs(t, x[0:6], u[0:6], p[P_USV : P_USV + N_USV], out[0:6])
    if p[H_TOP] > 0.5:
        for k in range(6):
            out[k] = 0.0
    if SEA and sea and p[int(p[H_SEA]) + S_WF] > 0.0:  # the USV's wave-frequency motion (._usv_waves)
        s = int(p[H_SEA])
        wf_rhs(t, x, p, s, out)
        w = int(p[s + S_WF])
        if p[w + W_DRIFT] != 0.0:  # mean drift: external X, Y, N of 003 eq. 2.3 (diagonal mass)
            out[3] += p[w + W_FD] / p[P_USV + _M11]
            out[4] += p[w + W_FD + 1] / p[P_USV + _M22]
            out[5] += p[w + W_FD + 2] / p[P_USV + _M33]
    pos, vel, F, Mn = _gather(x, p, n)
    lt = top_l0(x, p, n)
    ldot = x[int(p[H_WO]) + 1] if WINCH and p[H_WIN] > 0.5 else 0.0
    if SEA and sea:
        _loads_sea(p, pos, vel, F, Mn, n, p[H_CVE], u[2], u[3], p[H_CV], lt, ldot, _I0, t)
    else:
        _loads(p, pos, vel, F, Mn, n, p[H_CVE], u[2], u[3], p[H_CV], lt, ldot)
    po = int(p[H_PO])
    vo = int(p[H_VO])
    bed = p[H_BED] > 0.5
    mnode = p[H_MC] + p[H_MA]
    for i in range(1, n):
        k = 3 * i
        if BED and bed:
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
    if BED and bed:  # UUV: a sphere of radius H_BED_R around the CB, force applied at the tow point
        cx, cy, cz = _contact(p, x[o], x[o + 1], x[o + 2], vel[b], vel[b + 1], vel[b + 2], p[H_BED_R], p[P_UUV + P_MRB])
        fbx += cx
        fby += cy
        fbz += cz
    if SEA and sea:  # the UUV in the waves: flow velocity and acceleration at its centre of buoyancy
        s = int(p[H_SEA])
        c = coef_base(p, s) + NCOEF * (int(p[s + S_NPT]) - 2)
        wn, we, wd, an, ae, ad = point_kinematics(p, c, t - p[s + S_TMID], x[o + 2])
        uuv_deriv_flow(
            x[o : o + 12], out[o : o + 12], p[P_UUV : P_UUV + UUV_NP], u[6], u[7], u[8], u[2] + wn, u[3] + we, wd,
            an, ae, ad, p[s + S_MDISP], fbx, fby, fbz, _TRUE,
        )  # fmt: skip
    else:
        uuv_deriv(
            x[o : o + 12], out[o : o + 12], p[P_UUV : P_UUV + UUV_NP], u[6], u[7], u[8], u[2], u[3], fbx, fby, fbz
        )
    if WINCH and p[H_WIN] > 0.5:
        nmax = int(p[H_NMAX])
        for k in range(3 * (n - 1), 3 * (nmax - 1)):  # inactive node slots stay put
            out[po + k] = 0.0
            out[vo + k] = 0.0
        wo = int(p[H_WO])
        _winch_rhs(x, u, p, wo, F, out)


@njit(cache=True, inline="always")
def cable_state(x, p, nodes, ends):
    """Node positions into ``nodes`` (3(n+1)) and the end forces (top xyz, bottom xyz, N) into ``ends``.

    The top force is the one the cable exerts on the top attachment, the bottom force the one on the
    UUV (both: tension of the end segment plus half its drag and submerged weight). Current is taken
    from ``ends[6:8]`` (NED, m/s) on entry.
    """
    n = int(p[H_N])
    if BRIDLE and p[H_BRI] > 0.0:
        bridle_update(x, p, n, ends[6], ends[7])
    pos, vel, F, Mn = _gather(x, p, n)
    for k in range(3 * (n + 1)):
        nodes[k] = pos[k]
    # only the two end segments matter: run the segment loads on one-segment views
    lt = top_l0(x, p, n)
    ldot = x[int(p[H_WO]) + 1] if WINCH and p[H_WIN] > 0.5 else 0.0
    sea = p[H_SEA] > 0.0
    if SEA and sea:
        _loads_sea(p, pos[0:6], vel[0:6], F[0:6], Mn[0:12], _I1, p[H_CV], ends[6], ends[7], -1.0, lt, ldot, _I0, p[H_T])
    else:
        _loads(p, pos[0:6], vel[0:6], F[0:6], Mn[0:12], _I1, p[H_CV], ends[6], ends[7], -1.0, lt, ldot)
    for k in range(3):
        ends[k] = F[k]
    b = 3 * (n - 1)
    lb = lt if n == 1 else -1.0
    lbd = ldot if n == 1 else 0.0
    if SEA and sea:
        _loads_sea(
            p, pos[b : b + 6], vel[b : b + 6], F[0:6], Mn[0:12], _I1, p[H_CV], ends[6], ends[7], -1.0, lb, lbd, n - 1,
            p[H_T],
        )  # fmt: skip
    else:
        _loads(p, pos[b : b + 6], vel[b : b + 6], F[0:6], Mn[0:12], _I1, p[H_CV], ends[6], ends[7], -1.0, lb, lbd)
    for k in range(3):
        ends[3 + k] = F[3 + k]


@njit(cache=True)
def bridle_update(x, p, n, vcn, vce):
    """The bridle's junction (:mod:`._combined_bridle`) at state ``x``, written into the UUV's tow point
    r_c: the damped Newton of :func:`._combined_bridle.search` from the rigged apex on the balance of the
    last cable segment's force on the junction (:func:`_loads` on a one-segment view, as :func:`cable_state`;
    the junction moving with the hull) and the three wires' pull; its residual (N) at ``B_RES``. Current
    (m/s, NED) ``vcn``, ``vce``."""
    ob = int(p[H_BRI])
    pos = p[ob + B_POS : ob + B_POS + 6]
    vel = p[ob + B_VEL : ob + B_VEL + 6]
    F = p[ob + B_F : ob + B_F + 6]
    Mn = p[ob + B_MN : ob + B_MN + 12]
    J = p[ob + B_J : ob + B_J + 6]
    lt = top_l0(x, p, n)
    if n == 1:  # node n - 1 is the top node
        _ends(x, p, _I1, pos, vel)
        lb = lt
        lbd = x[int(p[H_WO]) + 1] if WINCH and p[H_WIN] > 0.5 else 0.0
        l0 = lt
    else:
        po = int(p[H_PO]) + 3 * (n - 2)
        vo = int(p[H_VO]) + 3 * (n - 2)
        for k in range(3):
            pos[k] = x[po + k]
            vel[k] = x[vo + k]
        lb = -1.0
        lbd = 0.0
        l0 = p[H_L0]
    o, R, rx, ry, rz = tow_frame(x, p)
    rx = p[ob + B_APEX]  # the damped Newton starts from the rigged apex at every call (no history)
    ry = p[ob + B_APEX + 1]
    rz = p[ob + B_APEX + 2]
    qx, qy, qz, qres, sx, sy, sz, lam = rx, ry, rz, math.inf, 0.0, 0.0, 0.0, 1.0
    sea = p[H_SEA] > 0.0
    for _ in range(NEWTON_MAX):
        pos[3], pos[4], pos[5] = rot_add(R, x[o], x[o + 1], x[o + 2], rx, ry, rz)
        bu, bv, bw = cross_add(x[o + 6], x[o + 7], x[o + 8], x[o + 9], x[o + 10], x[o + 11], rx, ry, rz)
        vel[3], vel[4], vel[5] = rot_add(R, 0.0, 0.0, 0.0, bu, bv, bw)
        if SEA and sea:
            _loads_sea(p, pos, vel, F, Mn, _I1, p[H_CV], vcn, vce, -1.0, lb, lbd, n - 1, p[H_T])
        else:
            _loads(p, pos, vel, F, Mn, _I1, p[H_CV], vcn, vce, -1.0, lb, lbd)
        # the segment's force on the junction and its tangent stiffness, in the body frame
        fx = R[0] * F[3] + R[3] * F[4] + R[6] * F[5]
        fy = R[1] * F[3] + R[4] * F[4] + R[7] * F[5]
        fz = R[2] * F[3] + R[5] * F[4] + R[8] * F[5]
        for k in range(6):
            J[k] = 0.0
        dx, dy, dz, ln = segment(pos, _I1)
        if ln > l0:
            tx = R[0] * dx + R[3] * dy + R[6] * dz
            ty = R[1] * dx + R[4] * dy + R[7] * dz
            tz = R[2] * dx + R[5] * dy + R[8] * dz
            add_tangent(J, p[H_EA] / l0, p[H_EA] * (ln - l0) / l0, ln, tx / ln, ty / ln, tz / ln)
        res, nx, ny, nz = junction_newton(p, ob, rx, ry, rz, fx, fy, fz, J)
        rx, ry, rz, qx, qy, qz, qres, sx, sy, sz, lam, done = search(
            rx, ry, rz, res, nx, ny, nz, qx, qy, qz, qres, sx, sy, sz, lam
        )
        if done:
            break
    rx, ry, rz = qx, qy, qz  # the last accepted point
    p[ob + B_RES] = qres
    p[ob + B_RJ] = rx
    p[ob + B_RJ + 1] = ry
    p[ob + B_RJ + 2] = rz
    p[P_UUV + P_RC] = rx
    p[P_UUV + P_RC + 1] = ry
    p[P_UUV + P_RC + 2] = rz
