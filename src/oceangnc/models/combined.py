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
from ..errors import ConfigError
from ..units import G
from .cable import CableConfig, axial_stability_limit, cable_loads, solve_sym3
from .usv import STATE_NAMES as USV_STATES
from .usv import USVConfig, usv_rhs
from .uuv import NP as UUV_NP
from .uuv import P_MA, P_MRB, P_RC
from .uuv import STATE_NAMES as UUV_STATES
from .uuv import UUVConfig, uuv_deriv, uuv_energy

INPUT_NAMES = ("usv.thrust_port", "usv.thrust_stbd", "env.current_n", "env.current_e", "env.wind_n",
               "env.wind_e", "uuv.thrust_port", "uuv.thrust_stbd", "uuv.thrust_bow")

# parameter layout: header, USV params, UUV params, scratch
H_N, H_TOP, H_FIX, H_ATT, H_L0, H_EA, H_CV, H_MC, H_MA, H_WSEG, H_KDRAG = 0, 1, 2, 5, 8, 9, 10, 11, 12, 13, 14
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
    cf = math.cos(phi)
    sf = math.sin(phi)
    ct = math.cos(th)
    st = math.sin(th)
    cp = math.cos(psi)
    sp = math.sin(psi)
    r00 = cp * ct
    r01 = -sp * cf + cp * st * sf
    r02 = sp * sf + cp * cf * st
    r10 = sp * ct
    r11 = cp * cf + sf * st * sp
    r12 = -cp * sf + st * sp * cf
    r20 = -st
    r21 = ct * sf
    r22 = ct * cf
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
    cable_loads(pos, vel, F, Mn, n, p[H_L0], p[H_EA], p[H_CV], p[H_MC], p[H_MA], p[H_WSEG], p[H_KDRAG],
                u[2], u[3])
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
    cable_loads(pos, vel, F, Mn, n, p[H_L0], p[H_EA], p[H_CV], p[H_MC], p[H_MA], p[H_WSEG], p[H_KDRAG],
                ends[6], ends[7])
    for k in range(3 * (n + 1)):
        nodes[k] = pos[k]
    b = 3 * n
    for k in range(3):
        ends[k] = F[k]
        ends[3 + k] = F[b + k]


def _check(cable: CableConfig, uuv: UUVConfig) -> None:
    if cable.segments < 1:
        raise ConfigError(f"cable.segments = {cable.segments}: allowed range 1 <= value")
    for key, v in (("cable.length", cable.length), ("cable.diameter", cable.diameter), ("cable.E", cable.E),
                   ("cable.density", cable.density), ("uuv.mass", uuv.mass)):
        if not (v > 0 and math.isfinite(v)):
            raise ConfigError(f"{key} = {v}: must be > 0")


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
                 name: str = "combined"):
        if top not in ("usv", "fixed"):
            raise ConfigError(f"CombinedPlant top = {top!r}: allowed values 'usv', 'fixed'")
        _check(cable_cfg, uuv_cfg)
        self.usv_cfg = usv_cfg
        self.uuv_cfg = uuv_cfg
        self.cable_cfg = cable_cfg
        self.top = top
        n = cable_cfg.segments
        self.n = n
        c = cable_cfg
        p = np.zeros(P_SCR + 15 * (n + 1))
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
        self.stability_limit = axial_stability_limit(c, end_mass=end_mass)
        super().__init__(name, combined_rhs, x0, p, names, INPUT_NAMES, state_bound=1e6,
                         max_dt=self.stability_limit)
        self._nodes = np.zeros(3 * (n + 1))
        self._ends = np.zeros(8)
        self.o_uuv = 6 + 6 * (n - 1)

    # -- outputs -----------------------------------------------------------------------------------
    def cable_snapshot(self):
        """(nodes (n+1, 3) NED m, top force (3,) N, bottom force (3,) N) at the current state."""
        self._ends[6] = self.u[2]
        self._ends[7] = self.u[3]
        cable_state(self.x, self.p, self._nodes, self._ends)
        return self._nodes.reshape(-1, 3), self._ends[0:3], self._ends[3:6]

    def publish(self, bus: dict) -> None:
        x = self.x
        for k, s in enumerate(USV_STATES):
            bus[f"usv.{s}"] = float(x[k])
        bus["usv.psi"] = float((x[2] + math.pi) % (2 * math.pi) - math.pi)
        bus["usv.speed"] = float(math.hypot(x[3], x[4]))
        o = self.o_uuv
        for k, s in enumerate(UUV_STATES):
            bus[f"uuv.{s}"] = float(x[o + k])
        bus["uuv.psi"] = float((x[o + 5] + math.pi) % (2 * math.pi) - math.pi)
        bus["uuv.speed"] = float(math.sqrt(x[o + 6] ** 2 + x[o + 7] ** 2 + x[o + 8] ** 2))
        nodes, ftop, fbot = self.cable_snapshot()
        bus["cable.top_tension"] = float(math.sqrt(ftop @ ftop))
        bus["cable.bottom_tension"] = float(math.sqrt(fbot @ fbot))
        d = nodes[-1] - nodes[0]
        bus["cable.angle_deg"] = float(math.degrees(math.atan2(math.hypot(d[0], d[1]), d[2])))
        for i in range(self.n + 1):
            bus[f"cable.x{i}"] = float(nodes[i, 0])
            bus[f"cable.y{i}"] = float(nodes[i, 1])
            bus[f"cable.z{i}"] = float(nodes[i, 2])

    # -- diagnostics -------------------------------------------------------------------------------
    def energy(self) -> float:
        """Mechanical energy (J) in still water: UUV (kinetic + potential), cable interior nodes'
        kinetic energy (with their current mass matrices), cable potential (submerged weight at the
        segment centres) and strain energy 1/2 EA l0 eps^2 of stretched segments. The USV is not
        included (the cable does not act on it). Conserved when drag, damping and added mass are off.
        """
        n = self.n
        nodes, _, _ = self.cable_snapshot()
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
