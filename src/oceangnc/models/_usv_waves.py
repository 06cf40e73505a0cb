r"""The USV's wave-frequency motions (issue 29 part B): Cummins' equation in the combined plant.

**Two time scales** (Fossen 2021, *Handbook of Marine Craft Hydrodynamics and Motion Control*, 2nd ed.,
the superposition of the manoeuvring (low-frequency) and seakeeping (wave-frequency) models): the
USV's motion is the manoeuvring model's (003 eq. 2.3, :mod:`oceangnc.models.usv`; states x, y, psi, u,
v, r) plus a wave-frequency perturbation xi = (surge, sway, heave, roll, pitch, yaw) about the
reference point (waterline, amidships), in axes that follow the manoeuvring heading. The
perturbation obeys **Cummins' equation** (Cummins 1962) with the radiation memory replaced by a
state-space model fitted to the frequency-domain coefficients (:mod:`oceangnc.hydro.radiation`):

    xi'' = (M + A_inf)^-1 [ tau_exc(t) - C xi - B_v xi' - mu ],   mu_i = sum_j Cr[i, j] . z_j,
    z_j' = Ar z_j + br xi_j'                                         (j = 1..6)

with M the rigid-body mass, A_inf the infinite-frequency added mass, C the hydrostatic stiffness plus a
weak critically damped tie of surge, sway and yaw to the manoeuvring model (60 s period,
:meth:`~oceangnc.hydro.coefficients.HydroCoefficients.horizontal_tie`: those modes have no restoring
force, their slow motion is the manoeuvring model's), B_v a viscous roll damping, the tie's damping and
(``manoeuvring_damping``, default on) the manoeuvring model's linear d11, d22, d33 on surge, sway and yaw
(:func:`manoeuvring_damping`), and tau_exc the first-order wave excitation (Froude-Krylov + diffraction) of every
wave component at the USV's manoeuvring position, heading and track:

    tau_exc,i(t) = sum_j a_j Re( X_i(w_j, mu_j) exp(i phi_j(t)) ),   mu_j = theta_j - psi,

with phi_j = k_j (x cos theta_j + y sin theta_j) - w_j t + eps_j the component's phase at the USV (its
elevation there is a_j cos phi_j). X is interpolated linearly in heading on the file's uniform grid;
the component frequencies are fixed, so X(w_j, .) is interpolated in frequency once, when the plant is
built. As the sea block's kinematics (:mod:`._combined_sea`), tau_exc is expanded to second order in
time about the middle of each update interval along the USV's track (the phases move at the encounter
frequency), so the right-hand side evaluates 6 polynomials. Nothing in the time domain evaluates an
RAO: the regular-wave amplitudes that the test compares with the RAO come out of this integration.

The **mean wave drift force** (option ``environment.usv_motions.drift``): sum_j a_j^2 D(w_j, mu_j) from
the file's far-field (Maruo 1960) drift coefficients D, held per update interval and applied to the
manoeuvring model as an external surge and sway force and yaw moment (divided by the model's m11,
m22, m33, whose mass matrix is diagonal: 003 eq. 2.3). No slow drift (difference-frequency) forces.

The cable does not load the USV (003, as before); the USV's wave-frequency motion moves the cable's
attachment point r (body): Delta = R(psi) (xi_1..3 + xi_4..6 x r) and its rate
(:func:`oceangnc.models._sea_layout.usv_motion_offset`). Published: ``usv.z``, ``usv.phi``,
``usv.theta`` (xi_3, xi_4, xi_5: heave down, roll, pitch); ``usv.x``, ``usv.y``, ``usv.psi`` stay the
manoeuvring model's (what a wave-filtered navigation system gives the controllers).
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit

from ..errors import ConfigError
from ._sea_layout import (
    NXF,
    S_COMP,
    S_NC,
    S_TMID,
    S_WF,
    W_AR,
    W_BV,
    W_C,
    W_DRIFT,
    W_F,
    W_FD,
    W_LEV,
    W_MINV,
    W_NB,
    W_NS,
    W_SCR,
    W_XO,
)

#: wave-frequency outputs: (signal, offset in xi)
WF_OUTPUTS = (("usv.z", 2), ("usv.phi", 3), ("usv.theta", 4))


def wf_block(
    coeffs, rad, waves, lever, state_offset: int, drift: bool, roll_damping_ratio: float, extra_damping=None
) -> np.ndarray:
    """The USV's wave-frequency block (layout :mod:`._sea_layout` W_*): ``coeffs`` a
    :class:`~oceangnc.hydro.coefficients.HydroCoefficients`, ``rad`` its
    :class:`~oceangnc.hydro.radiation.RadiationModel`, ``waves`` the wave field, ``lever`` the attachment
    point (m, body), ``state_offset`` where the block's states start in x, ``extra_damping`` (6, 6) a
    further linear damping (the manoeuvring model's, :func:`manoeuvring_damping`)."""
    nb = coeffs.headings.size
    if not np.allclose(coeffs.headings, np.arange(nb) * 2.0 * math.pi / nb, atol=1e-9):
        raise ConfigError(
            "environment.usv_motions.file: the time-domain model needs headings uniform over 360 deg from 0"
        )
    if drift and coeffs.drift is None:
        raise ConfigError("environment.usv_motions.drift = true: the coefficient file has no mean drift")
    ns = rad.ns
    nc = int(waves.a.size)
    Bv, Ct = coeffs.time_domain_extras(roll_damping_ratio)
    if extra_damping is not None:
        Bv = Bv + extra_damping
    Xc = coeffs.interp_omega("X", waves.omega)  # (nc, nb, 6) at the components' frequencies
    Dc = coeffs.interp_omega("drift", waves.omega) if coeffs.drift is not None else np.zeros((nc, nb, 3))
    head = np.zeros(W_AR)
    head[W_NS] = ns
    head[W_XO] = state_offset
    head[W_NB] = nb
    head[W_DRIFT] = 1.0 if drift else 0.0
    head[W_LEV : W_LEV + 3] = lever
    head[W_MINV : W_MINV + 36] = np.linalg.inv(coeffs.M + coeffs.A_inf).ravel()
    head[W_C : W_C + 36] = (coeffs.C + Ct).ravel()
    head[W_BV : W_BV + 36] = Bv.ravel()
    parts = [
        head,
        rad.Ar.ravel(),
        rad.br,
        rad.Cr.ravel(),
        Xc.real.ravel(),  # [j, h, i]
        Xc.imag.ravel(),
        Dc.ravel(),
    ]
    return np.concatenate(parts)


def wf_state_size(rad) -> int:
    """Number of states of the block: xi, xi' and 6 copies of the radiation states."""
    return NXF + 6 * rad.ns


def wf_system_matrix(block: np.ndarray) -> np.ndarray:
    """The linear system matrix of the block's free motion (states xi, xi', z), for the stability check."""
    ns = int(block[W_NS])
    n = NXF + 6 * ns
    Minv = block[W_MINV : W_MINV + 36].reshape(6, 6)
    C = block[W_C : W_C + 36].reshape(6, 6)
    Bv = block[W_BV : W_BV + 36].reshape(6, 6)
    Ar = block[W_AR : W_AR + ns * ns].reshape(ns, ns)
    br = block[W_AR + ns * ns : W_AR + ns * ns + ns]
    Cr = block[W_AR + ns * ns + ns : W_AR + ns * ns + ns + 36 * ns].reshape(6, 6, ns)
    S = np.zeros((n, n))
    S[0:6, 6:12] = np.eye(6)
    S[6:12, 0:6] = -Minv @ C
    S[6:12, 6:12] = -Minv @ Bv
    for j in range(6):
        S[6:12, NXF + j * ns : NXF + (j + 1) * ns] = -Minv @ Cr[:, j, :]
        S[NXF + j * ns : NXF + (j + 1) * ns, NXF + j * ns : NXF + (j + 1) * ns] = Ar
        S[NXF + j * ns : NXF + (j + 1) * ns, 6 + j] = br
    return S


@njit(cache=True)
def _tables(p, w):
    """Offsets (Ar, br, Cr, X real, X imag, drift) of the block at ``w``."""
    ns = int(p[w + W_NS])
    a = w + W_AR
    b = a + ns * ns
    c = b + ns
    xr = c + 36 * ns
    return a, b, c, xr


@njit(cache=True)
def wf_update(x, p, s, tm, half):
    """Expand the excitation force of every DOF to second order about ``tm`` (s) along the USV's track,
    and the mean drift force (module docstring); called by :func:`._combined_sea.sea_update`."""
    w = int(p[s + S_WF])
    nc = int(p[s + S_NC])
    nb = int(p[w + W_NB])
    a0, b0, c0, xr = _tables(p, w)
    xi = xr + nc * nb * 6
    dr = xi + nc * nb * 6
    for k in range(18):
        p[w + W_F + k] = 0.0
    for k in range(3):
        p[w + W_FD + k] = 0.0
    psi = x[2] + x[5] * half
    cps = math.cos(x[2])
    sps = math.sin(x[2])
    vn = cps * x[3] - sps * x[4]
    ve = sps * x[3] + cps * x[4]
    px = x[0] + vn * half
    py = x[1] + ve * half
    cb = s + S_COMP
    dh = 2.0 * math.pi / nb
    drift = p[w + W_DRIFT] != 0.0
    for j in range(nc):
        a = p[cb + j]
        om = p[cb + nc + j]
        k = p[cb + 2 * nc + j]
        ct = p[cb + 3 * nc + j]
        st = p[cb + 4 * nc + j]
        phi = k * (px * ct + py * st) - om * tm + p[cb + 5 * nc + j]
        r = k * (vn * ct + ve * st) - om
        mu = (math.atan2(st, ct) - psi) % (2.0 * math.pi)
        hf = mu / dh
        h0 = int(hf)
        f = hf - h0
        h0 = h0 % nb
        h1 = (h0 + 1) % nb
        cp = math.cos(phi)
        sp = math.sin(phi)
        # Re(X e^{i phi}) = Xr cos(phi) - Xi sin(phi), each as q0 + q1 tau + q2 tau^2
        e0c, e1c, e2c = cp, -r * sp, -0.5 * r * r * cp
        e0s, e1s, e2s = sp, r * cp, -0.5 * r * r * sp
        for i in range(6):
            q0 = (j * nb + h0) * 6 + i
            q1 = (j * nb + h1) * 6 + i
            re = a * ((1.0 - f) * p[xr + q0] + f * p[xr + q1])
            im = a * ((1.0 - f) * p[xi + q0] + f * p[xi + q1])
            p[w + W_F + 3 * i] += re * e0c - im * e0s
            p[w + W_F + 3 * i + 1] += re * e1c - im * e1s
            p[w + W_F + 3 * i + 2] += re * e2c - im * e2s
        if drift:
            for i in range(3):
                d0 = p[dr + (j * nb + h0) * 3 + i]
                d1 = p[dr + (j * nb + h1) * 3 + i]
                p[w + W_FD + i] += a * a * ((1.0 - f) * d0 + f * d1)


@njit(cache=True)
def wf_rhs(t, x, p, s, out):
    """The law: d/dt of the USV's wave-frequency states (xi, xi', z) into ``out`` (module docstring:
    Cummins' equation with the state-space radiation force), for the sea block at ``s``."""
    w = int(p[s + S_WF])
    o = int(p[w + W_XO])
    ns = int(p[w + W_NS])
    a0, b0, c0, _ = _tables(p, w)
    tau = t - p[s + S_TMID]
    zo = o + NXF
    for i in range(6):
        out[o + i] = x[o + 6 + i]
    # z_j' = Ar z_j + br xi_j'
    for j in range(6):
        v = x[o + 6 + j]
        zj = zo + j * ns
        for m in range(ns):
            acc = p[b0 + m] * v
            for q in range(ns):
                acc += p[a0 + m * ns + q] * x[zj + q]
            out[zj + m] = acc
    # force = tau_exc - C xi - B_v xi' - mu
    for i in range(6):
        c = w + W_F + 3 * i
        f = p[c] + tau * (p[c + 1] + tau * p[c + 2])
        for j in range(6):
            f -= p[w + W_C + 6 * i + j] * x[o + j] + p[w + W_BV + 6 * i + j] * x[o + 6 + j]
            cr = c0 + (6 * i + j) * ns
            zj = zo + j * ns
            for m in range(ns):
                f -= p[cr + m] * x[zj + m]
        out[o + 6 + i] = f  # the generalised force, before the mass matrix
    for i in range(6):
        p[w + W_SCR + i] = out[o + 6 + i]
    for i in range(6):
        acc = 0.0
        for j in range(6):
            acc += p[w + W_MINV + 6 * i + j] * p[w + W_SCR + j]
        out[o + 6 + i] = acc


def manoeuvring_damping(d11: float, d22: float, d33: float) -> np.ndarray:
    """(6, 6) diag(d11, d22, 0, 0, 0, d33): the manoeuvring model's linear damping (003 eq. 2.3) on the
    wave-frequency surge, sway and yaw. A linear damping acting on the total velocity splits exactly over
    the two time scales, D (nu_LF + nu_WF) = D nu_LF + D nu_WF, so the wave-frequency part of the
    manoeuvring model's (viscous, resistance) damping belongs in the wave-frequency model; at zero
    frequency the potential damping B(w) it adds to vanishes, so nothing is counted twice."""
    D = np.zeros((6, 6))
    D[0, 0], D[1, 1], D[5, 5] = d11, d22, d33
    return D


def _heun_stable(lam: np.ndarray, h: float) -> bool:
    z = lam * h
    return bool(np.all(np.abs(1.0 + z + 0.5 * z * z) <= 1.0 + 1e-12))


def attach_usv_motions(p, x0, names, cfg, waves, cable_cfg, top: str):
    """(p, x0, names, step limit (s)) of a combined plant with the USV's wave-frequency block appended:
    the coefficients of ``cfg.file`` (default 003's USV), their radiation fit, the block after the sea
    block and its states after all others. Refuses an unstable fitted system; the step limit keeps the
    explicit part of the integrators (Heun's method inside ROS2, RK4) stable on its eigenvalues."""
    from ..hydro.coefficients import load_coefficients
    from ..hydro.radiation import fit_radiation
    from ._combined_layout import H_SEA, P_USV
    from .usv import _D11, _D22, _D33

    if waves is None:
        raise ConfigError(
            "environment.usv_motions.enabled = true: needs waves (environment.waves.kind other than 'none')"
        )
    if top == "fixed":
        raise ConfigError("environment.usv_motions.enabled = true: needs the cable's top on the USV, not a fixed point")
    coeffs = load_coefficients(cfg.file)
    rad = fit_radiation(coeffs)
    ratio = cfg.roll_damping_ratio
    if ratio is None:
        ratio = float(coeffs.hull.get("roll_damping_ratio", 0.1))
    xo = int(x0.size)
    extra = None
    if cfg.manoeuvring_damping:
        extra = manoeuvring_damping(p[P_USV + _D11], p[P_USV + _D22], p[P_USV + _D33])
    block = wf_block(coeffs, rad, waves, cable_cfg.top_point, xo, cfg.drift, ratio, extra)
    lam = np.linalg.eigvals(wf_system_matrix(block))
    if np.max(lam.real) >= 0.0:
        raise ConfigError(
            f"environment.usv_motions.file: the fitted radiation model leaves an unstable mode "
            f"(eigenvalue {lam[np.argmax(lam.real)]:.3g} 1/s); recompute the coefficients over a wider band"
        )
    lo, hi = 1e-6, 1.0
    if _heun_stable(lam, hi):
        limit = math.inf
    else:
        for _ in range(60):
            mid = math.sqrt(lo * hi)
            lo, hi = (mid, hi) if _heun_stable(lam, mid) else (lo, mid)
        limit = lo
    s = int(p[H_SEA])
    p[s + S_WF] = p.size
    p = np.concatenate([p, block])
    x0 = np.concatenate([x0, np.zeros(wf_state_size(rad))])
    names = [*names, *(f"usv_wf.xi{i + 1}" for i in range(6)), *(f"usv_wf.dxi{i + 1}" for i in range(6))]
    names += [f"usv_wf.z{j + 1}_{m}" for j in range(6) for m in range(rad.ns)]
    return p, x0, names, limit
