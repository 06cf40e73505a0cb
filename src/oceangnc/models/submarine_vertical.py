"""Vertical-plane (heave-pitch) submarine model of document 002 (Lee, Choi & Yang, ADD).

Equations (``002_05c842517d8c1175.txt`` eq. 2.1-2.5, as reconstructed in SPEC.md section 002), all
dimensional, constant forward speed ``U``, small angle of attack::

    (m - Z_wdot) w' - (m x_G + Z_qdot) q' = A
    -(m x_G + M_wdot) w' + (I_y - M_qdot) q' = B_m
    A   = m U q + m z_G q^2 + (W - B) cos(theta) + Z_w w + Z_q q + Z_ds ds
    B_m = M_w w + M_q q + M_ds ds - m x_G U q - m z_G w q - W z_G sin(theta) - W x_G cos(theta)
    theta' = q,    z' = -U sin(theta) + w cos(theta)                       (eq. 2.3)

The 2 x 2 system is solved for (w', q') by Cramer's rule (eq. 2.4-2.5). The rigid-body terms are
those of the DTNSRDC standard equations (Feldman 1979, ref. [1] of 002; the same as Fossen's
``m[w' - uq - z_G q^2 - x_G q']`` and ``I_y q' + m[z_G(u' + wq) - x_G(w' - uq)]`` with u' = 0).

Non-dimensional coefficients (primes) are scaled with rho, L and U as in table 2.1 of 002:

    ======== ================    ======== ==================
    Z_w      rho/2 L^2 U         M_w      rho/2 L^3 U
    Z_wdot   rho/2 L^3           M_wdot   rho/2 L^4
    Z_q      rho/2 L^3 U         M_q      rho/2 L^4 U
    Z_qdot   rho/2 L^4           M_qdot   rho/2 L^5
    Z_ds     rho/2 L^2 U^2       M_ds     rho/2 L^3 U^2  (printed "U"; a moment needs U^2)
    ======== ================    ======== ==================

and ``I_y = I_y' rho/2 L^5``.

Choices where 002 is silent or garbled (see ``docs/ekf-identification.md``):

* **Vertical CG-CB offset.** Table 4.1 prints "Z_theta = -0.27414" among the physical constants. We
  read it as the metacentric arm BG = 0.27414 m: the origin is at the centre of buoyancy (x_B = z_B
  = 0, as in the DTNSRDC equations the paper's eq. 2.1-2.2 come from) and the centre of gravity lies
  0.27414 m *below* it, ``z_G = +0.27414`` m (z down). The printed minus sign is that of the CB seen
  from the CG (z_B - z_G). With this sign the restoring moment -W z_G sin(theta) is stabilising and
  the vehicle is stable in open loop (eigenvalues -0.034 +/- 0.022j and -0.0097 1/s); with z_G =
  -0.27414 m it would have a real eigenvalue of +0.0067 1/s (a vehicle that falls over in pitch).
  Keeping the rigid-body terms m z_G q^2 and m z_G w q also matters for identification: with W = B
  they are the only terms of the heave equation with a known coefficient, and without them the ten
  coefficients are not all identifiable from (w, theta, q) (see the docs page).
* **Sign of M_w.** Table 5.3 prints the true M_w' as -0.004059 while table 4.1 and both estimates
  are positive; a positive (destabilising) Munk moment is the physical one, so M_w' = +0.004059.
* x_G = 0 (the paper's eq. 2.1-2.2 carry x_G but table 4.1 gives none), W = B (table 4.1).

Layouts: filter state ``x = [w, theta, q]`` (m/s, rad, rad/s) with input ``u = [ds]`` (rad), plant
state ``[w, theta, q, z]``; parameters :data:`P_NAMES` (the ten primes, then m kg, I_y' (-), W N,
B N, x_G m, z_G m, rho kg/m^3, L m, U m/s).
"""

from __future__ import annotations

import numpy as np
from numba import njit

from ..core.blocks import Plant
from ..core.model import Model
from ._submarine_params import *  # noqa: F403  (re-exported: the old import paths keep working)
from ._submarine_params import COEFF_NAMES, CONST_NAMES, LAYOUT, P_NAMES, SCALE_POWERS, SubmarineVerticalConfig

_C0 = LAYOUT.index("Zw")  # the ten coefficients are consecutive, in COEFF_NAMES order
_M, _IY, _W, _B, _XG, _ZG, _RHO, _L, _U = LAYOUT.indices(*CONST_NAMES)
(_ZW, _ZWD, _ZQ, _ZQD, _ZDS, _MW, _MWD, _MQ, _MQD, _MDS) = LAYOUT.indices(*COEFF_NAMES)
FILTER_STATES = ("w", "theta", "q")
STATE_NAMES = ("w", "theta", "q", "z")
STATE_UNITS = ("m/s", "rad", "rad/s", "m")
INPUT_NAMES = ("ds",)


def default_params() -> np.ndarray:
    """Parameters of 002 (table 4.1 constants, tables 5.2/5.3 coefficients)."""
    return SubmarineVerticalConfig().params()


def dimensional(p) -> dict[str, float]:
    """Dimensional coefficients (SI: N s/m, kg, N s, kg m, N/rad, ...) and I_y (kg m^2) from ``p``."""
    p = np.asarray(p, dtype=np.float64)
    rho, L, U = p[_RHO], p[_L], p[_U]
    out = {}
    for i, k in enumerate(COEFF_NAMES):
        a, b = SCALE_POWERS[k]
        out[k] = float(p[_C0 + i] * 0.5 * rho * L**a * U**b)
    out["Iy"] = float(p[_IY] * 0.5 * rho * L**5)
    return out


@njit(cache=True)
def _accel(w, theta, q, ds, p):
    """(w', q') of eq. 2.4-2.5 and the mass matrix; type-generic (real or complex, for complex step)."""
    h = 0.5 * p[_RHO]
    L = p[_L]
    U = p[_U]
    L2 = L * L
    L3 = L2 * L
    L4 = L3 * L
    L5 = L4 * L
    m = p[_M]
    W = p[_W]
    Bf = p[_B]
    xG = p[_XG]
    zG = p[_ZG]
    Zw = p[_ZW] * h * L2 * U
    Zwd = p[_ZWD] * h * L3
    Zq = p[_ZQ] * h * L3 * U
    Zqd = p[_ZQD] * h * L4
    Zds = p[_ZDS] * h * L2 * U * U
    Mw = p[_MW] * h * L3 * U
    Mwd = p[_MWD] * h * L4
    Mq = p[_MQ] * h * L4 * U
    Mqd = p[_MQD] * h * L5
    Mds = p[_MDS] * h * L3 * U * U
    Iy = p[_IY] * h * L5
    ct = np.cos(theta)
    st = np.sin(theta)
    A = m * U * q + m * zG * q * q + (W - Bf) * ct + Zw * w + Zq * q + Zds * ds
    Bm = Mw * w + Mq * q + Mds * ds - m * xG * U * q - m * zG * w * q - W * zG * st - W * xG * ct
    M11 = m - Zwd
    M12 = -(m * xG + Zqd)
    M21 = -(m * xG + Mwd)
    M22 = Iy - Mqd
    det = M11 * M22 - M12 * M21
    wd = (M22 * A - M12 * Bm) / det
    qd = (M11 * Bm - M21 * A) / det
    return wd, qd


@njit(cache=True)
def sub_f(x, p, u, out):
    """Filter model f(x, p, u): d/dt [w, theta, q] (002 eq. 2.3-2.5); u = [ds] (rad).

    Written with numpy ufuncs only, so it also runs on complex arrays (complex-step Jacobians).
    """
    wd, qd = _accel(x[0], x[1], x[2], u[0], p)
    out[0] = wd
    out[1] = x[2]
    out[2] = qd


@njit(cache=True)
def sub_h(x, p, out):
    """Measurement model: w (m/s), theta (rad) and q (rad/s) are measured directly (002 ch. 4)."""
    out[0] = x[0]
    out[1] = x[1]
    out[2] = x[2]


@njit(cache=True)
def sub_rhs(t, x, u, p, out):
    """Plant right-hand side: d/dt [w, theta, q, z] (002 eq. 2.3-2.5), u = [ds] (rad)."""
    wd, qd = _accel(x[0], x[1], x[2], u[0], p)
    out[0] = wd
    out[1] = x[2]
    out[2] = qd
    out[3] = -p[_U] * np.sin(x[1]) + x[0] * np.cos(x[1])


@njit(cache=True)
def sub_jac(x, p, u, J):
    """Analytic Jacobian of :func:`sub_f`: J[:, :3] = df/dx, J[:, 3 + j] = df/dp[j] (all 19 params).

    With a = (w', q') = M^-1 r, r = (A, B_m): da/dy = M^-1 (dr/dy - (dM/dy) a) for every state or
    parameter y; theta' = q gives the middle row.
    """
    w = x[0]
    th = x[1]
    q = x[2]
    ds = u[0]
    h = 0.5 * p[_RHO]
    L = p[_L]
    U = p[_U]
    m = p[_M]
    W = p[_W]
    Bf = p[_B]
    xG = p[_XG]
    zG = p[_ZG]
    Ls = np.empty(6)
    Ls[0] = 1.0
    for i in range(1, 6):
        Ls[i] = Ls[i - 1] * L
    # scale s_j = h L^a U^b of each coefficient, its L and U powers
    la = (2, 3, 3, 4, 2, 3, 4, 4, 5, 3)
    ub = (1, 0, 1, 0, 2, 1, 0, 1, 0, 2)
    s = np.empty(10)
    D = np.empty(10)
    for j in range(10):
        s[j] = h * Ls[la[j]] * U ** ub[j]
        D[j] = p[_C0 + j] * s[j]
    Iy = p[_IY] * h * Ls[5]
    ct = np.cos(th)
    st = np.sin(th)
    M11 = m - D[1]
    M12 = -(m * xG + D[3])
    M21 = -(m * xG + D[6])
    M22 = Iy - D[8]
    det = M11 * M22 - M12 * M21
    i11 = M22 / det
    i12 = -M12 / det
    i21 = -M21 / det
    i22 = M11 / det
    A = m * U * q + m * zG * q * q + (W - Bf) * ct + D[0] * w + D[2] * q + D[4] * ds
    Bm = D[5] * w + D[7] * q + D[9] * ds - m * xG * U * q - m * zG * w * q - W * zG * st - W * xG * ct
    wd = i11 * A + i12 * Bm
    qd = i21 * A + i22 * Bm
    ny = J.shape[1]
    for k in range(ny):
        J[0, k] = 0.0
        J[1, k] = 0.0
        J[2, k] = 0.0
    J[1, 2] = 1.0
    # derivative list: (dA, dB, dM11, dM12, dM21, dM22) for each y
    d = np.zeros((22, 6))
    d[0, 0] = D[0]  # w
    d[0, 1] = D[5] - m * zG * q
    d[1, 0] = -(W - Bf) * st  # theta
    d[1, 1] = -W * zG * ct + W * xG * st
    d[2, 0] = m * U + 2.0 * m * zG * q + D[2]  # q
    d[2, 1] = D[7] - m * xG * U - m * zG * w
    d[3, 0] = s[0] * w  # Zw
    d[4, 2] = -s[1]  # Zwdot
    d[5, 0] = s[2] * q  # Zq
    d[6, 3] = -s[3]  # Zqdot
    d[7, 0] = s[4] * ds  # Zds
    d[8, 1] = s[5] * w  # Mw
    d[9, 4] = -s[6]  # Mwdot
    d[10, 1] = s[7] * q  # Mq
    d[11, 5] = -s[8]  # Mqdot
    d[12, 1] = s[9] * ds  # Mds
    d[13, 0] = U * q + zG * q * q  # m
    d[13, 1] = -xG * U * q - zG * w * q
    d[13, 2] = 1.0
    d[13, 3] = -xG
    d[13, 4] = -xG
    d[14, 5] = h * Ls[5]  # Iy_nd
    d[15, 0] = ct  # W
    d[15, 1] = -zG * st - xG * ct
    d[16, 0] = -ct  # B
    d[17, 1] = -m * U * q - W * ct  # xG
    d[17, 3] = -m
    d[17, 4] = -m
    d[18, 0] = m * q * q  # zG
    d[18, 1] = -m * w * q - W * st
    # rho: every scaled term is proportional to rho
    d[19, 0] = (D[0] * w + D[2] * q + D[4] * ds) / p[_RHO]
    d[19, 1] = (D[5] * w + D[7] * q + D[9] * ds) / p[_RHO]
    d[19, 2] = -D[1] / p[_RHO]
    d[19, 3] = -D[3] / p[_RHO]
    d[19, 4] = -D[6] / p[_RHO]
    d[19, 5] = (Iy - D[8]) / p[_RHO]
    # L: d(D_j)/dL = a_j D_j / L
    d[20, 0] = (2 * D[0] * w + 3 * D[2] * q + 2 * D[4] * ds) / L
    d[20, 1] = (3 * D[5] * w + 4 * D[7] * q + 3 * D[9] * ds) / L
    d[20, 2] = -3 * D[1] / L
    d[20, 3] = -4 * D[3] / L
    d[20, 4] = -4 * D[6] / L
    d[20, 5] = 5 * (Iy - D[8]) / L
    # U: d(D_j)/dU = b_j D_j / U, plus the rigid-body m U q terms
    d[21, 0] = m * q + (D[0] * w + D[2] * q + 2 * D[4] * ds) / U
    d[21, 1] = (D[5] * w + D[7] * q + 2 * D[9] * ds) / U - m * xG * q
    for k in range(min(22, ny)):  # column k: states 0-2, then parameter k - 3
        ra = d[k, 0] - (d[k, 2] * wd + d[k, 3] * qd)
        rb = d[k, 1] - (d[k, 4] * wd + d[k, 5] * qd)
        J[0, k] = i11 * ra + i12 * rb
        J[2, k] = i21 * ra + i22 * rb


@njit(cache=True)
def sub_filter_f(t, x, u, p, out):
    """:func:`sub_f` in the model contract ``f(t, x, u, p, out)``."""
    sub_f(x, p, u, out)


@njit(cache=True)
def sub_filter_jac(t, x, u, p, J):
    """:func:`sub_jac` in the model contract ``jac(t, x, u, p, J)``."""
    sub_jac(x, p, u, J)


_FILTER_STATES = (("w", "m/s"), ("theta", "rad"), ("q", "rad/s"))


def filter_model(params=None) -> Model:
    """The 3-state (w, theta, q) model the EKF of 002 identifies: outputs = states (w, theta, q
    measured directly, 002 ch. 4), analytic Jacobian, complex-step safe."""
    p = default_params() if params is None else np.asarray(params, dtype=np.float64)
    return Model(
        "submarine-vertical",
        sub_filter_f,
        _FILTER_STATES,
        [("ds", "rad")],
        LAYOUT,
        p,
        jac=sub_filter_jac,
        bound=100.0,  # |w| > 100 m/s, |theta| > 100 rad, |q| > 100 rad/s or |coef'| > 100: diverged
        description="002 heave-pitch submarine: states w, theta, q; input stern plane ds",
    )


def plant_model(params=None) -> Model:
    """The 4-state plant model (w, theta, q, z) of 002 eq. 2.3-2.5."""
    p = default_params() if params is None else np.asarray(params, dtype=np.float64)
    return Model(
        "submarine-vertical-plant",
        sub_rhs,
        [*_FILTER_STATES, ("z", "m")],
        [("ds", "rad")],
        LAYOUT,
        p,
        description="002 heave-pitch submarine with depth",
    )


def eigenvalues(p, ds: float = 0.0) -> np.ndarray:
    """Eigenvalues (1/s) of the (w, theta, q) dynamics linearised at rest: the open-loop modes."""
    J = np.zeros((3, 3 + len(P_NAMES)))
    sub_jac(np.zeros(3), np.asarray(p, dtype=np.float64), np.array([ds]), J)
    return np.linalg.eigvals(J[:, :3])


class SubmarineVerticalPlant(Plant):
    """The heave-pitch submarine as a plant: state ``[w, theta, q, z]``, input ``<name>.ds`` (rad).

    Publishes ``<name>.w`` (m/s), ``<name>.theta`` (rad), ``<name>.q`` (rad/s), ``<name>.z`` (m).
    """

    def __init__(self, cfg: SubmarineVerticalConfig, name: str = "sub"):
        super().__init__(
            **plant_model(cfg.params()).plant_args(name, cfg.x0(), [f"{name}.ds"], declare=True), state_bound=1e6
        )
        self.cfg = cfg
