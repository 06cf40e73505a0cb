"""The three-point bridle of 003 fig. 5-6 as the combined plant's tow attachment (``cable.attachment =
"bridle"``): three tension-only wires from the cable's end node (the junction J) to a fore, a mid and
an aft hull point h_i of the UUV (body frame, m).

**The law.** Wire i pulls the junction toward its hull point with

    T_i = EA_w (d_i - L_i) / L_i  if d_i = |h_i - r_J| > L_i, else 0        (tension only)

(EA_w the wire's axial stiffness, L_i its unstretched length). The junction is massless and solved
quasi-statically at every right-hand-side evaluation: its body position r_J satisfies

    F_c(r_J) + sum_i T_i (h_i - r_J) / d_i = 0

with F_c the force of the cable's last segment on it (tension, axial damping, half the segment's drag
and submerged weight: :func:`~oceangnc.models.cable.cable_loads`, the same call the single point uses),
and the junction moving with the hull (v_J = R (v + omega x r_J)). Newton on r_J with the tangent
stiffness of the wires and of the last segment, K = EA/L t t^T + T/d (I - t t^T) (taut only), damped:
a step that does not lower the balance's residual is halved (:func:`search`), and the junction
returned is the last accepted point, so never one worse balanced than the rigged apex. A weak anchor
EPS_K (r_A - r_J) toward the apex makes the junction determinate while everything is slack.

Why damped (issue 38): both the wires (0.7 MN/m) and the last segment (EA/l0 = 25 kN/m) are tension
only, and a full Newton step from the apex crosses their kinks. Undamped, the solve cycled when the
cable snatched taut (the field test's start drops the UUV by the bridle's height onto its slack cable)
and ended on its last iterate, with up to 700 N unbalanced (a snatch of ~160 N). The cable's end
jumped with it and the hull, whose roll is restored only by T times the 0.125 m of its top line and by
W z_G, rolled 44-63 deg in the first second (over 700 deg on a 2 m bridle). Damped, the same start
rolls it under 10 deg (``tests/test_bridle.py``).

**Why the UUV needs nothing else.** Each wire force acts along the line through h_i and r_J, so the
moment of the three about the centre of buoyancy is sum h_i x (-T_i u_i) = r_J x F_c: the bridle acts on
the hull as the single point of 003 eq. 2.32-2.33 placed at the junction. The kernel therefore writes
r_J into the UUV's tow point r_c (``P_RC``) before the cable's end nodes are gathered, and the rest of the
plant (end node 003 eq. 2.30-2.31, force and moment eq. 2.32-2.33, the IMEX end increments) is unchanged.
While two or more wires are taut the junction stays near the rigged apex (the wires are ~30x stiffer
than a cable segment), which is what gives the bridle its pitch stiffness: dM/dtheta = -r_J . F_b.

Why quasi-static and not a junction with its own state: the junction's mass (half a cable segment,
0.12 kg for table 2-6) on 3 mm steel wires of 0.5 m (k ~ 1.4 MN/m) has a natural frequency of ~3 kHz,
which would set the explicit step (< 0.3 ms) or need the wires in the implicit solve; and a massless
junction needs no wire damping (there is no junction mode to damp).

The block of ``p`` (offset ``p[H_BRI]``, 0 for the single point): layout :data:`BRIDLE`.
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit

from ..core.model import ParamLayout
from .cable import solve_sym3

_I0 = np.int64(0)  # not a literal: numba would compile solve_sym3 once more for the constant 0

#: the bridle's block of the combined plant's parameter array: hull points (fore, mid, aft; body, m),
#: unstretched lengths (m), wire EA (N), the rigged apex (Newton's start, body, m), the wire tensions (N)
#: of the last solve, the junction of the last solve (body, m), scratch for the last segment's loads,
#: the Newton matrix, and the tow point saved between the IMEX stages
BRIDLE = ParamLayout(
    [
        ("hull", "m", 9),
        ("length", "m", 3),
        ("ea", "N"),
        ("apex", "m", 3),
        ("tension", "N", 3),
        ("junction", "m", 3),
        ("pos", "m", 6),
        ("vel", "m/s", 6),
        ("force", "N", 6),
        ("mass", "kg", 12),
        ("jac", "N/m", 6),
        ("saved", "m", 3),
        ("residual", "N"),
    ]
)
B_HULL, B_LEN, B_EA, B_APEX, B_T, B_RJ, B_POS, B_VEL, B_F, B_MN, B_J, B_SAVE, B_RES = BRIDLE.indices(
    "hull", "length", "ea", "apex", "tension", "junction", "pos", "vel", "force", "mass", "jac", "saved", "residual"
)
#: regularisation of the Newton matrix (N/m): keeps it invertible while every wire and the segment are
#: slack (then there is no force to balance), negligible against the geometric stiffness T/d of a
#: taut wire (~300 N/m at the survey tension)
EPS_K = 1.0
NEWTON_MAX = 60
STEP_MAX = 0.05  # m, per Newton step
STEP_TOL = 1e-12  # m
RES_TOL = 1e-7  # N: an accepted point balanced to this is the junction
LAM_MIN = 1.0 / 1024.0  # smallest step fraction of the backtracking before a point is taken anyway


def bridle_block(bridle) -> np.ndarray:
    """The bridle's block of ``p`` (layout :data:`BRIDLE`) from a :class:`BridleConfig`."""
    apex = (bridle.apex_x, bridle.apex_y, bridle.apex_z)
    zero = {q.name: np.zeros(q.size) for q in BRIDLE.params}
    given = {"hull": np.array(bridle.points(), float).ravel(), "length": bridle.lengths(), "ea": bridle.EA}
    return BRIDLE.pack({**zero, **given, "apex": apex, "junction": apex, "saved": apex})


@njit(cache=True)
def wire_loads(p, ob, rx, ry, rz, J):
    """Sum of the three wires' forces on a junction at body point r (N, body frame); adds their tangent
    stiffness to the symmetric ``J`` (xx xy xz yy yz zz, N/m) and stores the tensions at ``B_T``."""
    fx = 0.0
    fy = 0.0
    fz = 0.0
    ea = p[ob + B_EA]
    for i in range(3):
        h = ob + B_HULL + 3 * i
        dx = p[h] - rx
        dy = p[h + 1] - ry
        dz = p[h + 2] - rz
        d = math.sqrt(dx * dx + dy * dy + dz * dz)
        L = p[ob + B_LEN + i]
        if d > L:
            T = ea * (d - L) / L
            ux = dx / d
            uy = dy / d
            uz = dz / d
            fx += T * ux
            fy += T * uy
            fz += T * uz
            g = T / d
            ka = ea / L - g
            J[0] += ka * ux * ux + g
            J[1] += ka * ux * uy
            J[2] += ka * ux * uz
            J[3] += ka * uy * uy + g
            J[4] += ka * uy * uz
            J[5] += ka * uz * uz + g
            p[ob + B_T + i] = T
        else:
            p[ob + B_T + i] = 0.0
    return fx, fy, fz


@njit(cache=True)
def add_tangent(J, k_axial, tension, length, tx, ty, tz):
    """Add the tangent stiffness EA/l0 t t^T + T/l (I - t t^T) of a taut line (``k_axial`` = EA/l0, N/m)
    of unit direction t to the symmetric ``J``."""
    g = tension / length
    ka = k_axial - g
    J[0] += ka * tx * tx + g
    J[1] += ka * tx * ty
    J[2] += ka * tx * tz
    J[3] += ka * ty * ty + g
    J[4] += ka * ty * tz
    J[5] += ka * tz * tz + g


@njit(cache=True)
def junction_newton(p, ob, rx, ry, rz, fx, fy, fz, J):
    """The junction's residual and Newton step at body point r (m): the residual G (N, body) is the external
    force (fx, fy, fz) plus the wires' pull plus the anchor EPS_K (r_A - r) toward the rigged apex r_A; ``J``
    holds the external force's stiffness on entry (the wires' and the anchor's added here). Returns the
    residual's norm (N) and the step (K + EPS_K I)^-1 G (m), at most ``STEP_MAX`` long."""
    wx, wy, wz = wire_loads(p, ob, rx, ry, rz, J)
    gx = fx + wx + EPS_K * (p[ob + B_APEX] - rx)
    gy = fy + wy + EPS_K * (p[ob + B_APEX + 1] - ry)
    gz = fz + wz + EPS_K * (p[ob + B_APEX + 2] - rz)
    J[0] += EPS_K
    J[3] += EPS_K
    J[5] += EPS_K
    dx, dy, dz = solve_sym3(J, _I0, gx, gy, gz)
    s = math.sqrt(dx * dx + dy * dy + dz * dz)
    if s > STEP_MAX:
        f = STEP_MAX / s
        dx *= f
        dy *= f
        dz *= f
    return math.sqrt(gx * gx + gy * gy + gz * gz), dx, dy, dz


@njit(cache=True)
def search(rx, ry, rz, res, nx, ny, nz, qx, qy, qz, qres, dx, dy, dz, lam):
    """One move of the damped Newton on the junction (backtracking on the residual's norm).

    r was just evaluated (residual norm ``res`` N, Newton step n); q is the last accepted point (residual
    ``qres``), d the step tried from it with factor ``lam``. A point that does not lower the residual by
    the Armijo fraction 1e-4 lam is rejected and the step from q halved (down to ``LAM_MIN``); otherwise it
    is accepted and its full Newton step tried next. Returns the next point to evaluate, the updated
    (q, qres, d, lam) and whether the solve is done (step under ``STEP_TOL`` or residual under ``RES_TOL``
    at an accepted point)."""
    if res > (1.0 - 1e-4 * lam) * qres and lam > LAM_MIN:
        lam *= 0.5
        return qx + lam * dx, qy + lam * dy, qz + lam * dz, qx, qy, qz, qres, dx, dy, dz, lam, False
    done = res < RES_TOL or math.sqrt(nx * nx + ny * ny + nz * nz) < STEP_TOL
    return rx + nx, ry + ny, rz + nz, rx, ry, rz, res, nx, ny, nz, 1.0, done


@njit(cache=True)
def junction_under_force(p, ob, fx, fy, fz):
    """The junction (body, m) under a fixed external force (N, body frame; the pitch stiffness of
    :func:`pitch_stiffness`), by the damped Newton of :func:`search` from the rigged apex."""
    J = p[ob + B_J : ob + B_J + 6]
    rx = p[ob + B_APEX]
    ry = p[ob + B_APEX + 1]
    rz = p[ob + B_APEX + 2]
    qx, qy, qz, qres, dx, dy, dz, lam = rx, ry, rz, math.inf, 0.0, 0.0, 0.0, 1.0
    for _ in range(NEWTON_MAX):
        for k in range(6):
            J[k] = 0.0
        res, nx, ny, nz = junction_newton(p, ob, rx, ry, rz, fx, fy, fz, J)
        rx, ry, rz, qx, qy, qz, qres, dx, dy, dz, lam, done = search(
            rx, ry, rz, res, nx, ny, nz, qx, qy, qz, qres, dx, dy, dz, lam
        )
        if done:
            break
    p[ob + B_RJ] = qx
    p[ob + B_RJ + 1] = qy
    p[ob + B_RJ + 2] = qz
    p[ob + B_RES] = qres
    return qx, qy, qz


def pitch_stiffness(cable_cfg, uuv_cfg, tension: float, lean_deg: float = 0.0, dtheta: float = 1e-4):
    """Pitch stiffness k = -dM/dtheta (N m/rad) of the tow attachment about the UUV's centre of buoyancy,
    computed through the model, and the point the cable's force acts at (body, m) at theta = 0.

    The cable's force is held fixed in the earth frame: magnitude ``tension`` (N), leaning ``lean_deg``
    forward of the vertical (upward, in the UUV's vertical plane). At theta = +-dtheta (central difference)
    the junction is solved under the force (:func:`junction_under_force`; the single point: r_c) and the
    moment is the one the UUV's right-hand side applies (:func:`~oceangnc.models.uuv.uuv_deriv`: the
    difference of its accelerations with and without the force, times the mass matrix M_RB + M_A).
    For a junction fixed in the body (rigid wires) k = r . F_b (the moment r x F_b of 003 eq. 2.33
    differentiated), positive when the point lies on the side the cable pulls toward.
    """
    from ..core.rotations import rzyx_entries
    from .uuv import NP, P_RC, uuv_deriv

    p = uuv_cfg.params(tow_point=cable_cfg.tow_point)
    blk = bridle_block(cable_cfg.bridle) if cable_cfg.attachment == "bridle" else None
    mrb, ma = uuv_cfg.mass_matrices()
    mass = np.asarray(mrb) + np.asarray(ma)
    lean = math.radians(lean_deg)
    fe = np.array([math.sin(lean), 0.0, -math.cos(lean)]) * tension
    moments, points = [], []
    for th in (dtheta, -dtheta, 0.0):
        x = np.zeros(12)
        x[4] = th
        R = np.array(rzyx_entries(0.0, th, 0.0)).reshape(3, 3)
        fb = R.T @ fe
        if blk is not None:
            p[P_RC : P_RC + 3] = junction_under_force(blk, 0, fb[0], fb[1], fb[2])
        points.append(p[P_RC : P_RC + 3].copy())
        a1, a0 = np.zeros(12), np.zeros(12)
        uuv_deriv(x, a1, p[:NP], 0.0, 0.0, 0.0, 0.0, 0.0, fe[0], fe[1], fe[2])
        uuv_deriv(x, a0, p[:NP], 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0)
        moments.append(float((mass @ (a1[6:] - a0[6:]))[4]))
    return -(moments[0] - moments[1]) / (2.0 * dtheta), points[2]
