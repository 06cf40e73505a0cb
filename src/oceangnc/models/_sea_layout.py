"""Layout of the combined plant's *sea block* (issue 29) and the compiled evaluation of its expansions.

The sea block is appended to the combined plant's flat parameter array when the plant has waves or a
heaving top point; the header word ``H_SEA`` holds its offset (0: calm water, the wave branches are
skipped after that one test). It holds the wave components and, for every kinematics point (the
segment centres, the UUV's centre of buoyancy, the top attachment point), a second-order expansion in
time of the wave elevation, particle velocity and acceleration about the middle of the current update
interval (:func:`oceangnc.models._combined_sea.sea_update` fills them; module docstring there).
"""

from __future__ import annotations

import math

from numba import njit

# scalar words of the sea block
S_NC = 0  # number of wave components
S_DEPTH = 1  # water depth h (m)
S_WHEEL = 2  # Wheeler stretching (1/0)
S_DT = 3  # update interval of the expansions (s)
S_TMID = 4  # expansion time t_m (s): the middle of the current interval
S_TNEXT = 5  # end of the current interval (s)
S_T0 = 6  # start of the current interval (s)
S_HEAVE = 7  # top point heave: 0 none, 1 with the wave surface, 2 prescribed sine
S_HAMP = 8  # prescribed heave amplitude (m, + down)
S_HOMG = 9  # prescribed heave angular frequency (rad/s)
S_MDISP = 10  # UUV displaced mass rho V = B / g (kg)
S_FKSEG = 11  # cable segment displaced mass rho_w A l0 (kg, nominal segment)
S_NPT = 12  # number of point slots (n_max + 2)
S_NLAST = 13  # segment count at the last update (a winch changes it)
S_SUMA = 14  # sum of the amplitudes: a bound on |eta| (m)
S_WF = 15  # offset in p of the USV's wave-frequency block (0: the USV moves as in calm water; part B)
S_EV = 16  # offset in p of the event block (0: no in-step slack/snap tracking; ._combined_events)
S_COMP = 17  # components: 8 rows of nc (a, omega, k, cos theta, sin theta, eps, 1/(1 - exp(-2kh)), deep)
NQ = 7  # quantities per point: eta, u_N, u_E, w_D, du_N/dt, du_E/dt, dw_D/dt
NCOEF = 3 * NQ  # coefficients per point: each quantity as c0 + c1 tau + c2 tau^2


# the USV's wave-frequency block (issue 29 part B; filled by ._usv_waves.wf_block, stepped by its wf_rhs)
W_NS = 0  # radiation states per DOF (ns)
W_XO = 1  # offset in x of the USV's wave-frequency states: xi (6), xi' (6), radiation z (6 ns)
W_NB = 2  # headings of the excitation table (uniform over 2 pi from 0)
W_DRIFT = 3  # mean drift force on the USV's manoeuvring model (1/0)
W_LEV = 4  # 3: the cable's attachment point relative to the reference point (body, m)
W_F = 8  # 18: the excitation force of each DOF as c0 + c1 tau + c2 tau^2 over the current interval
W_FD = 26  # 3: the mean drift force (surge N, sway N, yaw N m) over the current interval
W_SCR = 30  # 6: scratch (the generalised force of the right-hand side)
W_MINV = 36  # 36: (M + A_inf)^-1
W_C = 72  # 36: hydrostatic stiffness C
W_BV = 108  # 36: viscous damping (roll)
W_AR = 144  # ns^2 radiation Ar, then ns br, 36 ns Cr, then the tables (._usv_waves.wf_block)
NXF = 12  # the motion states xi, xi' before the radiation states


def sea_size(nc: int, npt: int) -> int:
    """Length of a sea block with ``nc`` components and ``npt`` point slots."""
    return S_COMP + 8 * nc + NCOEF * npt


@njit(cache=True)
def coef_base(p, s):
    """Offset in ``p`` of the first point's coefficients, for the sea block at ``s``."""
    return s + S_COMP + 8 * int(p[s + S_NC])


@njit(cache=True)
def q_at(p, b, tau):
    """The quantity whose three expansion coefficients start at ``b`` (``c + 3 q`` for quantity ``q`` of the
    point whose coefficients start at ``c``), at tau (s) from the expansion time."""
    return p[b] + tau * (p[b + 1] + tau * p[b + 2])


@njit(cache=True)
def point_kinematics(p, c, tau, depth):
    """(u_N, u_E, w_D, a_N, a_E, a_D) of the point whose coefficients start at ``c`` (m/s, m/s^2, NED), at
    tau (s) from the expansion time; zero when the point (at ``depth``, m) is above the wave surface."""
    # offsets computed here, not literal quantity numbers: one compiled q_at for all seven
    if depth < -q_at(p, c, tau):
        return 0.0, 0.0, 0.0, 0.0, 0.0, 0.0
    return (
        q_at(p, c + 3, tau),
        q_at(p, c + 6, tau),
        q_at(p, c + 9, tau),
        q_at(p, c + 12, tau),
        q_at(p, c + 15, tau),
        q_at(p, c + 18, tau),
    )


@njit(cache=True)
def top_heave(p, s, t):
    """(dz, dz/dt, d2z/dt2) of the top attachment point at time ``t`` (m, NED: + down) for the sea block
    at ``s``: -eta at the USV (heave with the surface, its expansion along the USV's track) or the
    prescribed sine a sin(omega t)."""
    mode = p[s + S_HEAVE]
    if mode == 1.0:
        c = coef_base(p, s) + NCOEF * (int(p[s + S_NPT]) - 1)
        tau = t - p[s + S_TMID]
        return -(p[c] + tau * (p[c + 1] + tau * p[c + 2])), -(p[c + 1] + 2.0 * tau * p[c + 2]), -2.0 * p[c + 2]
    if mode == 2.0:
        a = p[s + S_HAMP]
        w = p[s + S_HOMG]
        sw = math.sin(w * t)
        return a * sw, a * w * math.cos(w * t), -a * w * w * sw
    return 0.0, 0.0, 0.0


@njit(cache=True)
def lever_ned(v, o, w, p, psi):
    """NED vector (m or m/s) of v[o:o+3] + v[o+3:o+6] x r, rotated by the heading ``psi`` (rad): the
    displacement (or velocity) of the cable's attachment point r (W_LEV of the wave-frequency block at
    ``w``) for small rotations, from the USV's wave-frequency motion (or its rates, or a stage increment)."""
    ax = p[w + W_LEV]
    ay = p[w + W_LEV + 1]
    az = p[w + W_LEV + 2]
    dx = v[o] + v[o + 4] * az - v[o + 5] * ay
    dy = v[o + 1] + v[o + 5] * ax - v[o + 3] * az
    dz = v[o + 2] + v[o + 3] * ay - v[o + 4] * ax
    c = math.cos(psi)
    sn = math.sin(psi)
    return c * dx - sn * dy, sn * dx + c * dy, dz


@njit(cache=True)
def usv_motion_offset(x, p, s):
    """(dN, dE, dD, dvN, dvE, dvD): displacement (m) and velocity (m/s) of the cable's attachment point
    due to the USV's wave-frequency motion xi (surge, sway, heave, roll, pitch, yaw about the reference
    point; :func:`lever_ned`); zeros when the USV has no wave-frequency block (sea block at ``s``)."""
    w = int(p[s + S_WF])
    if w == 0:
        return 0.0, 0.0, 0.0, 0.0, 0.0, 0.0
    o = int(p[w + W_XO])
    dn, de, dd = lever_ned(x, o, w, p, x[2])
    vn, ve, vd = lever_ned(x, o + 6, w, p, x[2])
    return dn, de, dd, vn, ve, vd
