r"""The combined plant at sea (issue 29): wave loads on the cable and the UUV, a heaving top point.

**What the waves do.** Every cable segment and the UUV see the wave field of
:mod:`oceangnc.environment.waves` (linear Airy components): the drag acts on the velocity relative to
current + wave orbital velocity, and the water's acceleration a_w adds the Morison inertia force
(Morison, O'Brien, Johnson & Schaaf 1950; DNV-RP-C205 (2010) sec. 6.2.1 and eq. 6.2.1/6.2.3):

* cable segment (displaced volume V = A l0): rho V a_w + C_a rho V a_w,n (:func:`~oceangnc.models.cable.
  cable_loads`): Froude-Krylov on the whole volume, added mass on the normal component;
* UUV hull: (rho V [I 0] + M_A) [R^T a_w; 0], with its own 6x6 added-mass matrix, and the relative velocity
  nu_r = nu - [R^T v_f; 0] (v_f = current + wave velocity at the CB, now with a vertical part) in its
  damping, lift and Coriolis terms (:func:`~oceangnc.models.uuv.uuv_deriv_flow`) - the long-wave,
  diffraction-free approximation (hull length 1.79 m against wave lengths of 10 m and more).

The USV is as in calm water (its wave-frequency motions are issue 29 part B); only its attachment
point may heave: ``heave = "surface"`` moves it with the wave elevation at the USV (z = z_top - eta: a
craft much shorter than the waves follows the surface, heave RAO 1), ``"sine"`` prescribes
z = z_top + a sin(omega t) (tests).

**How the kinematics are evaluated (speed).** The full sum over 128 components at 21 points costs about
0.1 ms; evaluated at every right-hand side call it would cap a tow at ~50x real time. Instead
:func:`sea_update` (called by the plant once per tick, before its integrator) expands, every
``update_dt`` (default 0.1 s) and for each point, every quantity q (eta, velocity, acceleration) to
second order in time about the middle t_m of the coming interval, *along the point's track*: the point
is moved to x + V (t_m - t) with its current velocity V, each component's phase
phi = k (x cos theta + y sin theta) - omega t + eps then changes at the rate
r = k (V_N cos theta + V_E sin theta) - omega (the encounter frequency, with the sign of the phase),
and each component contributes c (cos phi, -r sin phi, -r^2 cos phi / 2) (or the sine counterpart) to
the coefficients (q0, q1, q2) of q(t) = q0 + q1 tau + q2 tau^2, tau = t - t_m. The right-hand side then
evaluates three polynomials per point. The error of a component is about (r dt / 2)^3 / 6 of its size
(dt = update_dt): 3e-5 at the peak of a Tp = 6 s sea towed at 1.5 m/s, 1e-2 for the 4 fp components of
head seas (whose amplitude is ~3 % of the peak's). The depth factor F(d) is held at the update's depth
(its change over 0.1 s is k |w| dt, < 1 % at the peak). Components that have decayed below 1e-13 at the
point's depth are skipped, and so is the elevation at points deeper than the sum of the amplitudes.
A point above the instantaneous surface (depth < -eta) gets no wave kinematics.
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit

from ..units import G
from ._combined_layout import H_N, H_SEA, H_T, _gather, tow_frame
from ._usv_waves import wf_update
from ._sea_layout import (
    NCOEF,
    S_COMP,
    S_DEPTH,
    S_DT,
    S_FKSEG,
    S_HAMP,
    S_HEAVE,
    S_HOMG,
    S_MDISP,
    S_NC,
    S_NLAST,
    S_NPT,
    S_SUMA,
    S_T0,
    S_TMID,
    S_TNEXT,
    S_WF,
    S_EV,
    S_WHEEL,
    coef_base,
    sea_size,
)

HEAVE_MODES = {"none": 0.0, "surface": 1.0, "sine": 2.0}
#: decay exp(-k d) below which a component is skipped at a point
SKIP_KD = 30.0


def sea_block(
    waves,
    nmax: int,
    update_dt: float,
    heave: str,
    rho_water: float,
    area: float,
    l0: float,
    uuv_buoyancy: float,
    heave_amplitude: float = 0.0,
    heave_period: float = 0.0,
) -> np.ndarray:
    """The sea block (layout :mod:`._sea_layout`) of a plant with ``nmax`` segment slots, the wave field
    ``waves`` (a :class:`~oceangnc.environment.waves.WaveField`, or None) and the top point's heave."""
    nc = 0 if waves is None else int(waves.a.size)
    npt = nmax + 2
    b = np.zeros(sea_size(nc, npt))
    b[S_NC] = nc
    b[S_DEPTH] = waves.depth if waves is not None else 1000.0
    b[S_WHEEL] = 1.0 if (waves is not None and waves.wheeler) else 0.0
    b[S_DT] = update_dt
    b[S_TNEXT] = -math.inf
    b[S_T0] = math.inf
    b[S_HEAVE] = HEAVE_MODES[heave]
    b[S_HAMP] = heave_amplitude
    b[S_HOMG] = 2.0 * math.pi / heave_period if heave_period > 0 else 0.0
    b[S_MDISP] = uuv_buoyancy / G
    b[S_FKSEG] = rho_water * area * l0
    b[S_NPT] = npt
    b[S_NLAST] = -1.0
    if waves is not None:
        kh = waves.k * waves.depth
        deep = kh > 20.0
        with np.errstate(over="ignore"):
            invd = np.where(deep, 0.0, 1.0 / -np.expm1(-2.0 * np.minimum(kh, 20.0)))
        rows = [waves.a, waves.omega, waves.k, np.cos(waves.theta), np.sin(waves.theta), waves.eps, invd, deep * 1.0]
        b[S_COMP : S_COMP + 8 * nc] = np.concatenate(rows)
        b[S_SUMA] = float(np.sum(np.abs(waves.a)))
    return b


def reset_sea(p) -> None:
    """Forget the expansions (the next :func:`sea_update` recomputes them), e.g. after a reset."""
    s = int(p[H_SEA])
    if s > 0:
        p[s + S_TNEXT] = -math.inf
        p[s + S_T0] = math.inf
        p[s + S_NLAST] = -1.0
        p[H_T] = 0.0
        # the USV's block, then the event block, after the coefficients
        end = int(p[s + S_WF]) if p[s + S_WF] > 0 else (int(p[s + S_EV]) if p[s + S_EV] > 0 else p.size)
        p[coef_base(p, s) : end] = 0.0


@njit(cache=True)
def _expand(p, s, c, x, y, d, vn, ve, tm, kin):
    """Coefficients at p[c : c + NCOEF] of the point at (x, y, d) (NED, m) moving at (vn, ve) (m/s),
    about time tm; ``kin`` False: the elevation only (the top point)."""
    nc = int(p[s + S_NC])
    h = p[s + S_DEPTH]
    cb = s + S_COMP
    for k in range(NCOEF):
        p[c + k] = 0.0
    need_eta = (not kin) or d < p[s + S_SUMA] or p[s + S_WHEEL] != 0.0
    de = max(d, 0.0)
    if kin and p[s + S_WHEEL] != 0.0:  # Wheeler: stretched with the elevation at tm
        eta = 0.0
        for j in range(nc):
            k = p[cb + 2 * nc + j]
            phi = k * (x * p[cb + 3 * nc + j] + y * p[cb + 4 * nc + j]) - p[cb + nc + j] * tm + p[cb + 5 * nc + j]
            eta += p[cb + j] * math.cos(phi)
        de = h * (d + eta) / (h + eta)
        if de < 0.0:
            de = 0.0
    for j in range(nc):
        k = p[cb + 2 * nc + j]
        kde = k * de
        far = kde > SKIP_KD
        if far and not need_eta:
            continue
        a = p[cb + j]
        w = p[cb + nc + j]
        ct = p[cb + 3 * nc + j]
        st = p[cb + 4 * nc + j]
        phi = k * (x * ct + y * st) - w * tm + p[cb + 5 * nc + j]
        cp = math.cos(phi)
        sp = math.sin(phi)
        r = k * (vn * ct + ve * st) - w
        c1 = -r * sp
        c2 = -0.5 * r * r * cp
        s1 = r * cp
        s2 = -0.5 * r * r * sp
        p[c] += a * cp
        p[c + 1] += a * c1
        p[c + 2] += a * c2
        if not kin or far:
            continue
        e1 = math.exp(-kde)
        if p[cb + 7 * nc + j] != 0.0:
            fc = e1
            fs = e1
        else:
            e2 = math.exp(-k * (2.0 * h - de))
            fc = (e1 + e2) * p[cb + 6 * nc + j]
            fs = (e1 - e2) * p[cb + 6 * nc + j]
        uh = a * w * fc  # u_h = uh cos(phi)
        wu = a * w * fs  # w_up = wu sin(phi)
        ah = a * w * w * fc  # du_h/dt = ah sin(phi)
        aw = a * w * w * fs  # dw_D/dt = aw cos(phi)
        # u_N, u_E
        p[c + 3] += ct * uh * cp
        p[c + 4] += ct * uh * c1
        p[c + 5] += ct * uh * c2
        p[c + 6] += st * uh * cp
        p[c + 7] += st * uh * c1
        p[c + 8] += st * uh * c2
        # w_D = -w_up
        p[c + 9] -= wu * sp
        p[c + 10] -= wu * s1
        p[c + 11] -= wu * s2
        # du_N/dt, du_E/dt
        p[c + 12] += ct * ah * sp
        p[c + 13] += ct * ah * s1
        p[c + 14] += ct * ah * s2
        p[c + 15] += st * ah * sp
        p[c + 16] += st * ah * s1
        p[c + 17] += st * ah * s2
        # dw_D/dt
        p[c + 18] += aw * cp
        p[c + 19] += aw * c1
        p[c + 20] += aw * c2


@njit(cache=True)
def sea_update(t, x, p, span):
    """Refresh the expansions (module docstring) if ``t`` (s) left the current interval or the segment
    count changed; ``span`` (s) is the length of the coming integration call (an interval is at least
    that long). Called once per tick before the integrator; nothing to do in calm water."""
    s = int(p[H_SEA])
    if s == 0:
        return
    n = int(p[H_N])
    if p[s + S_T0] <= t < p[s + S_TNEXT] - 0.25 * span and n == int(p[s + S_NLAST]):
        return
    dtu = max(p[s + S_DT], span)
    half = 0.5 * dtu
    tm = t + half
    p[H_T] = t
    pos, vel, F, Mn = _gather(x, p, n)  # (the top point's heave from the previous expansion)
    p[s + S_T0] = t
    p[s + S_TMID] = tm
    p[s + S_TNEXT] = t + dtu
    p[s + S_NLAST] = n
    if int(p[s + S_NC]) == 0:
        return
    c0 = coef_base(p, s)
    for i in range(1, n + 1):  # segment centres, moved to tm along their velocity
        a = 3 * (i - 1)
        b = 3 * i
        vn = 0.5 * (vel[a] + vel[b])
        ve = 0.5 * (vel[a + 1] + vel[b + 1])
        vd = 0.5 * (vel[a + 2] + vel[b + 2])
        px = 0.5 * (pos[a] + pos[b]) + vn * half
        py = 0.5 * (pos[a + 1] + pos[b + 1]) + ve * half
        pz = 0.5 * (pos[a + 2] + pos[b + 2]) + vd * half
        _expand(p, s, c0 + NCOEF * (i - 1), px, py, pz, vn, ve, tm, True)
    npt = int(p[s + S_NPT])
    o, R, cx, cy, cz = tow_frame(x, p)  # the UUV's centre of buoyancy and its NED velocity
    u = x[o + 6]
    v = x[o + 7]
    w = x[o + 8]
    vn = R[0] * u + R[1] * v + R[2] * w
    ve = R[3] * u + R[4] * v + R[5] * w
    vd = R[6] * u + R[7] * v + R[8] * w
    _expand(
        p, s, c0 + NCOEF * (npt - 2), x[o] + vn * half, x[o + 1] + ve * half, x[o + 2] + vd * half, vn, ve, tm, True
    )
    if p[s + S_WF] > 0.0:  # the USV's excitation forces along its track (._usv_waves)
        wf_update(x, p, s, tm, half)
    if p[s + S_HEAVE] == 1.0:  # the top point: elevation along the USV's track
        _expand(
            p, s, c0 + NCOEF * (npt - 1), pos[0] + vel[0] * half, pos[1] + vel[1] * half, 0.0, vel[0], vel[1], tm, False
        )
