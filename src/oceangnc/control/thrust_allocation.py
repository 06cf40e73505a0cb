"""Control allocation and a 6-DOF PID for a vehicle of a file (:mod:`oceangnc.models.vehicle`).

**Allocation** (``vehicle.allocation``, Fossen 2021 ch. 11.2): the generalised force asked for,
tau = [X, Y, Z, K, M, N] (N, N m, body axes), restricted to the vehicle's controlled DOFs c
(``control.dofs`` of its file), is met by the thrusts of least weighted norm

    f = W^-1 B_c^T (B_c W^-1 B_c^T)^-1 tau_c          (weighted pseudo-inverse, Fossen eq. 11.36)

with B the 6 x n thruster configuration matrix (column i = [d_i; r_i x d_i]) and W = diag(weights).
With more thrusters than DOFs this is the optimum of min f^T W f subject to B_c f = tau_c. Two
saturation handlings, chosen per vehicle file (``control.allocator``):

* ``"pinv"`` (:func:`allocation_law`): when a thrust would pass its limit (forward or reverse), the
  whole vector f is scaled down to fit: the direction of tau_c is kept and its magnitude reduced. With
  ``control.priority`` (tiers of DOFs) the tiers are scaled one after the other into what is left
  (:mod:`oceangnc.control.priority_allocation`): a saturated surge no longer takes pitch authority.
* ``"redistribute"`` (:func:`redistribute_law`, the redistributed pseudo-inverse, Fossen 2021 ch. 11.2;
  Bordignon & Durham 1995): the thrusters past a limit are fixed at it (set S), and the rest F
  re-allocated to what remains, f_F = W_F^-1 B_F^T (B_F W_F^-1 B_F^T)^-1 (tau_c - B_S f_S), repeated
  until no free thrust passes a limit (at most n passes, each fixing one thruster or more). Where this
  ends feasible, B_c f = tau_c exactly although a thruster saturates, which uniform scaling does not
  give; where it does not (the free thrusters no longer reach every controlled DOF: B_F W_F^-1 B_F^T
  singular), it falls back to the uniform scaling of ``"pinv"``. With no thrust past a limit both are
  the same pseudo-inverse. Compiled, fixed pass count, the k x k system (k <= 6) solved by Cholesky in
  the block's own work array: no allocation per step.

A file with fewer independent thrusters than controlled DOFs is refused when read
(:func:`oceangnc.models.vehicle.load_vehicle`).

**PID** (``vehicle.pid``): per DOF, tau_i = k_p e_i + k_i int e_i - k_d nu_i on the errors of a
position, depth, attitude and heading hold (earth-frame position errors rotated into the body axes by
the heading; roll and pitch held at zero) or, in speed mode, of the surge speed. References come from
the block's parameters, or from the bus (``<body>.psi_cmd``, ``<body>.u_cmd``: the LOS guidance block ``usv.los``)
when written. Both zero their outputs on an emergency stop and ramp back (:mod:`oceangnc.core.estop`).
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit

from ..core.estop import RESUME_RAMP_S, resume_weight
from ..core.law import In, LawBlock, Layout, Opt, Out, Signals
from ..core.registry import register_block
from ..core.rotations import wrap
from ..models.vehicle import DOF_NAMES, VehicleFile, load_vehicle, thruster_matrix
from .priority_allocation import priority_scaled, tiers

# -- allocation ----------------------------------------------------------------------------------------

ALLOC_HEAD = Layout("n", "period", "ramp_s", ("tier", 6))
A = ALLOC_HEAD.at
A_PINV = ALLOC_HEAD.size  #: then the n x 6 pseudo-inverse (row-major), forward limits (n), reverse limits (n)
ALLOC_STATE = Layout("w")
AX = ALLOC_STATE.at


def _alloc_signals(n: int) -> Signals:
    return Signals(force=In("N", 3), moment=In("N m", 3), estop=Opt("bool"), thrust=Out("N", n))


AS = _alloc_signals(1).at  #: force, moment and estop slots are the same for every n; thrust starts at AS.thrust


@njit(cache=True)
def pinv_apply(pa, p0, n, tau, f):
    """f = P tau: P the n x 6 weighted pseudo-inverse at ``pa[p0:]``, row-major (then come the n forward
    and n reverse limits)."""
    for i in range(n):
        s = 0.0
        for j in range(6):
            s += pa[p0 + 6 * i + j] * tau[j]
        f[i] = s


@njit(cache=True)
def pinv_scaled(pa, p0, n, tau, f):
    """f = P tau (:func:`pinv_apply`) scaled as one vector into the limits (the ``"pinv"`` saturation
    handling): the direction of tau is kept."""
    pinv_apply(pa, p0, n, tau, f)
    scale = 1.0
    for i in range(n):
        s = f[i]
        hi = pa[p0 + 6 * n + i]
        lo = pa[p0 + 7 * n + i]
        if s > hi and s * scale > hi:
            scale = hi / s
        elif s < -lo and s * scale < -lo:
            scale = -lo / s
    for i in range(n):
        f[i] *= scale


@njit(cache=True)
def _read_tau(sig, sl, tau):
    for j in range(3):
        tau[j] = sig[sl[AS.force + j]]
        tau[3 + j] = sig[sl[AS.moment + j]]


@njit(cache=True)
def allocation_law(t, sig, sl, st, pa):
    """Thrust commands (N) for the asked generalised force (module docstring): weighted
    pseudo-inverse, scaling into the limits (uniform, or by the file's priority tiers), zero on an
    e-stop and the resume ramp after it."""
    n = int(pa[A.n])
    stop = sl[AS.estop] >= 0 and sig[sl[AS.estop]] != 0.0
    st[AX.w] = resume_weight(st[AX.w], stop, pa[A.period], pa[A.ramp_s])
    tau = np.empty(6)
    f = np.empty(n)
    _read_tau(sig, sl, tau)
    priority_scaled(pa, A_PINV, n, tau, f, A.tier)  # one tier: the uniform scaling of pinv_scaled
    for i in range(n):
        sig[sl[AS.thrust + i]] = f[i] * st[AX.w]


#: parameters of :func:`redistribute_law`: this head, then the pseudo-inverse and limits as
#: :func:`allocation_law`'s (8 n), the controlled rows (6 slots), 1 / weights (n), B_c (k x n, row-major)
REDIST_HEAD = Layout("n", "k", "period", "ramp_s")
RA = REDIST_HEAD.at
#: state: the ramp weight, then the work array (tau, residual, solution, the k x k matrix, f, free flags)
REDIST_STATE = Layout("w", ("tau", 6), ("r", 6), ("y", 6), ("A", 36))
RX = REDIST_STATE.at
R_PINV = REDIST_HEAD.size  #: the pseudo-inverse starts here
R_WORK = REDIST_STATE.size  #: f (n) and the free flags (n) start here in the state


@njit(cache=True)
def _solve_free(st, pa, n, k, pb):
    """One pass of the redistribution (module docstring): r = tau_c - B_S f_S, A = B_F W_F^-1 B_F^T,
    A y = r by Cholesky (in place), f_F = W_F^-1 B_F^T y. False when A is singular (the free
    thrusters do not reach every controlled DOF)."""
    f0 = R_WORK
    fr = f0 + n
    rows, winv, bc = pb + 8 * n, pb + 8 * n + 6, pb + 9 * n + 6
    for a in range(k):
        s = st[RX.tau + int(pa[rows + a])]
        for i in range(n):
            if st[fr + i] == 0.0:
                s -= pa[bc + a * n + i] * st[f0 + i]
        st[RX.r + a] = s
        for b in range(k):
            s = 0.0
            for i in range(n):
                if st[fr + i] != 0.0:
                    s += pa[winv + i] * pa[bc + a * n + i] * pa[bc + b * n + i]
            st[RX.A + a * k + b] = s
    trace = 0.0
    for a in range(k):
        trace += st[RX.A + a * k + a]
    for a in range(k):  # Cholesky A = L L^T, L in the lower triangle
        for b in range(a + 1):
            s = st[RX.A + a * k + b]
            for c in range(b):
                s -= st[RX.A + a * k + c] * st[RX.A + b * k + c]
            if a == b:
                if s <= 1e-12 * trace:
                    return False
                st[RX.A + a * k + a] = np.sqrt(s)
            else:
                st[RX.A + a * k + b] = s / st[RX.A + b * k + b]
    for a in range(k):  # L z = r, then L^T y = z
        s = st[RX.r + a]
        for c in range(a):
            s -= st[RX.A + a * k + c] * st[RX.y + c]
        st[RX.y + a] = s / st[RX.A + a * k + a]
    for a in range(k - 1, -1, -1):
        s = st[RX.y + a]
        for c in range(a + 1, k):
            s -= st[RX.A + c * k + a] * st[RX.y + c]
        st[RX.y + a] = s / st[RX.A + a * k + a]
    for i in range(n):
        if st[fr + i] != 0.0:
            s = 0.0
            for a in range(k):
                s += pa[bc + a * n + i] * st[RX.y + a]
            st[f0 + i] = pa[winv + i] * s
    return True


@njit(cache=True)
def redistribute_law(t, sig, sl, st, pa):
    """Thrust commands (N) by the redistributed pseudo-inverse (module docstring): the pseudo-inverse,
    then thrusters past a limit fixed at it and the rest re-allocated, at most n passes; the uniform
    scaling of :func:`pinv_scaled` where that ends infeasible. Zero on an e-stop, ramped after it."""
    n = int(pa[RA.n])
    k = int(pa[RA.k])
    pb = R_PINV
    stop = sl[AS.estop] >= 0 and sig[sl[AS.estop]] != 0.0
    st[RX.w] = resume_weight(st[RX.w], stop, pa[RA.period], pa[RA.ramp_s])
    f0 = R_WORK
    fr = f0 + n
    tau = st[RX.tau : RX.tau + 6]
    _read_tau(sig, sl, tau)
    pinv_apply(pa, pb, n, tau, st[f0 : f0 + n])  # the unconstrained optimum first
    for i in range(n):
        st[fr + i] = 1.0
    ok = True
    for _ in range(n + 1):
        fixed = False
        for i in range(n):
            hi = pa[pb + 6 * n + i]
            lo = -pa[pb + 7 * n + i]
            if st[fr + i] != 0.0 and (st[f0 + i] > hi or st[f0 + i] < lo):
                st[f0 + i] = hi if st[f0 + i] > hi else lo
                st[fr + i] = 0.0
                fixed = True
        if not fixed:
            break
        if not _solve_free(st, pa, n, k, pb):
            ok = False
            break
    if not ok:
        pinv_scaled(pa, pb, n, tau, st[f0 : f0 + n])
    for i in range(n):
        sig[sl[AS.thrust + i]] = st[f0 + i] * st[RX.w]


def allocation_matrix(vf: VehicleFile) -> np.ndarray:
    """The n x 6 weighted pseudo-inverse of the controlled rows (zero columns for the others)."""
    B = thruster_matrix(vf)
    rows = [DOF_NAMES.index(d) for d in vf.control.dofs]
    w = np.asarray(vf.control.weights or [1.0] * B.shape[1], float)
    Bc = B[rows]
    winv = np.diag(1.0 / w)
    pc = winv @ Bc.T @ np.linalg.inv(Bc @ winv @ Bc.T)
    P = np.zeros((B.shape[1], 6))
    P[:, rows] = pc
    return P


@register_block("vehicle.allocation")
class ThrustAllocation(LawBlock):
    """Thrust allocation of a vehicle file (module docstring): reads ``<body>.tau_X/Y/Z`` (N) and
    ``<body>.tau_K/M/N`` (N m), writes ``<body>.thrust_<name>_cmd`` (N); law :func:`allocation_law`."""

    role = "actuator"
    law = staticmethod(allocation_law)

    def __init__(self, vehicle: VehicleFile | str, period: float = 0.05, body: str = "vehicle"):
        vf = vehicle if isinstance(vehicle, VehicleFile) else load_vehicle(vehicle)
        self.vehicle, self.period, self.body, self.name = vf, period, body, f"{body}_allocation"
        n = len(vf.thrusters)
        self.signals = _alloc_signals(n)
        self.bind(
            force=[f"{body}.tau_{a}" for a in "XYZ"],
            moment=[f"{body}.tau_{a}" for a in "KMN"],
            estop="_estop",
            thrust=[f"{body}.thrust_{t.name}_cmd" for t in vf.thrusters],
        )
        head = ALLOC_HEAD.pack(n=n, period=period, ramp_s=RESUME_RAMP_S, tier=tiers(vf.control.priority, DOF_NAMES))
        fwd = [t.max_forward for t in vf.thrusters]
        rev = [t.max_reverse for t in vf.thrusters]
        self.pa = np.concatenate([head, allocation_matrix(vf).ravel(), fwd, rev])
        self.st = ALLOC_STATE.pack(w=1.0)

    def reset(self, rng) -> None:
        self.st[AX.w] = 1.0


@register_block("vehicle.allocation.redistribute")
class RedistributingAllocation(ThrustAllocation):
    """Thrust allocation by the redistributed pseudo-inverse (module docstring; ``control.allocator =
    "redistribute"`` of a vehicle file): the signals of :class:`ThrustAllocation`, law
    :func:`redistribute_law`."""

    law = staticmethod(redistribute_law)

    def __init__(self, vehicle: VehicleFile | str, period: float = 0.05, body: str = "vehicle"):
        super().__init__(vehicle, period, body)
        vf = self.vehicle
        n = len(vf.thrusters)
        rows = [DOF_NAMES.index(d) for d in vf.control.dofs]
        w = np.asarray(vf.control.weights or [1.0] * n, float)
        head = REDIST_HEAD.pack(n=n, k=len(rows), period=period, ramp_s=RESUME_RAMP_S)
        self.pa = np.concatenate(
            [head, self.pa[A_PINV:], np.r_[rows, np.zeros(6 - len(rows))], 1.0 / w, thruster_matrix(vf)[rows].ravel()]
        )
        self.st = np.zeros(REDIST_STATE.size + 2 * n)
        self.st[RX.w] = 1.0

    def reset(self, rng) -> None:
        self.st[RX.w] = 1.0


def allocation_block(vehicle: VehicleFile | str, period: float = 0.05, body: str = "vehicle") -> ThrustAllocation:
    """The allocation block a vehicle file asks for (``control.allocator``)."""
    vf = vehicle if isinstance(vehicle, VehicleFile) else load_vehicle(vehicle)
    cls = RedistributingAllocation if vf.control.allocator == "redistribute" else ThrustAllocation
    return cls(vf, period, body)


# -- 6-DOF PID -----------------------------------------------------------------------------------------

PID_SIGNALS = Signals(
    pos=In("m", 3),
    att=In("rad", 3),
    vel=In("m/s", 3),
    rate=In("rad/s", 3),
    psi_ref=Opt("rad"),
    u_ref=Opt("m/s"),
    estop=Opt("bool"),
    force=Out("N", 3),
    moment=Out("N m", 3),
)
PID_PARAMS = Layout(
    ("kp", 6), ("ki", 6), ("kd", 6), ("on", 6), ("i_max", 6), "speed_mode", "x_d", "y_d", "z_d", "psi_d", "u_d",
    "period", "ramp_s",
)  # fmt: skip
PID_STATE = Layout(("integral", 6), "w")
S, P, X = PID_SIGNALS.at, PID_PARAMS.at, PID_STATE.at


@njit(cache=True)
def vehicle_pid_law(t, sig, sl, st, pa):
    """tau (N, N m, body axes) from the hold errors of each enabled DOF (module docstring); integrals
    clamped to +-i_max and frozen on an e-stop, outputs zero then and ramped back after it."""
    stop = sl[S.estop] >= 0 and sig[sl[S.estop]] != 0.0
    st[X.w] = resume_weight(st[X.w], stop, pa[P.period], pa[P.ramp_s])
    x = sig[sl[S.pos]]
    y = sig[sl[S.pos + 1]]
    z = sig[sl[S.pos + 2]]
    psi = sig[sl[S.att + 2]]
    psi_d = sig[sl[S.psi_ref]] if sl[S.psi_ref] >= 0 else pa[P.psi_d]
    u_d = sig[sl[S.u_ref]] if sl[S.u_ref] >= 0 else pa[P.u_d]
    c = math.cos(psi)
    s = math.sin(psi)
    ex = pa[P.x_d] - x
    ey = pa[P.y_d] - y
    e = np.empty(6)
    e[0] = u_d - sig[sl[S.vel]] if pa[P.speed_mode] != 0.0 else c * ex + s * ey
    e[1] = -s * ex + c * ey
    e[2] = pa[P.z_d] - z
    e[3] = -sig[sl[S.att]]
    e[4] = -sig[sl[S.att + 1]]
    e[5] = wrap(psi_d - psi)
    for i in range(6):
        out = 0.0
        if pa[P.on + i] != 0.0:
            if not stop:
                lim = pa[P.i_max + i]
                st[X.integral + i] = min(lim, max(-lim, st[X.integral + i] + e[i] * pa[P.period]))
            rate = sig[sl[S.vel + i]] if i < 3 else sig[sl[S.rate + i - 3]]
            kd = 0.0 if (i == 0 and pa[P.speed_mode] != 0.0) else pa[P.kd + i]
            out = pa[P.kp + i] * e[i] + pa[P.ki + i] * st[X.integral + i] - kd * rate
        if i < 3:
            sig[sl[S.force + i]] = out * st[X.w]
        else:
            sig[sl[S.moment + i - 3]] = out * st[X.w]


@register_block("vehicle.pid")
class VehiclePID(LawBlock):
    """6-DOF hold/speed PID of a vehicle of a file (module docstring): reads ``<body>.x/y/z`` (m),
    ``<body>.phi/theta/psi`` (rad), ``<body>.u/v/w`` (m/s), ``<body>.p/q/r`` (rad/s), optionally
    ``<body>.psi_cmd`` (rad) and ``<body>.u_cmd`` (m/s); writes ``<body>.tau_X ... tau_N``.

    ``gains`` maps a DOF name to ``(k_p, k_i, k_d)``; DOFs not named output zero. ``setpoint`` holds
    ``x``, ``y``, ``z`` (m), ``psi`` (rad) and ``u`` (m/s); ``speed_mode`` controls the surge speed
    instead of the position."""

    role = "controller"
    law = staticmethod(vehicle_pid_law)
    signals = PID_SIGNALS

    def __init__(
        self, gains: dict, setpoint: dict, period: float = 0.05, body: str = "vehicle", speed_mode: bool = False,
        i_max: float = 1e3,
    ):  # fmt: skip
        self.period, self.body, self.name = period, body, f"{body}_pid"
        b = body
        self.bind(
            pos=[f"{b}.x", f"{b}.y", f"{b}.z"],
            att=[f"{b}.phi", f"{b}.theta", f"{b}.psi"],
            vel=[f"{b}.u", f"{b}.v", f"{b}.w"],
            rate=[f"{b}.p", f"{b}.q", f"{b}.r"],
            psi_ref=f"{b}.psi_cmd",
            u_ref=f"{b}.u_cmd",
            estop="_estop",
            force=[f"{b}.tau_{a}" for a in "XYZ"],
            moment=[f"{b}.tau_{a}" for a in "KMN"],
        )
        k = np.zeros((3, 6))
        on = np.zeros(6)
        for dof, g in gains.items():
            i = DOF_NAMES.index(dof)
            k[:, i] = g
            on[i] = 1.0
        self.pa = PID_PARAMS.pack(
            kp=k[0], ki=k[1], kd=k[2], on=on, i_max=np.full(6, i_max), speed_mode=float(speed_mode),
            x_d=setpoint.get("x", 0.0), y_d=setpoint.get("y", 0.0), z_d=setpoint.get("z", 0.0),
            psi_d=setpoint.get("psi", 0.0), u_d=setpoint.get("u", 0.0), period=period, ramp_s=RESUME_RAMP_S,
        )  # fmt: skip
        self.st = PID_STATE.pack(integral=np.zeros(6), w=1.0)

    def reset(self, rng) -> None:
        self.st[:] = PID_STATE.pack(integral=np.zeros(6), w=1.0)
