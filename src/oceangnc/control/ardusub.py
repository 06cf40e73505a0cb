"""ArduSub's flight modes as compiled laws: the depth reference of every mode, the ROV's 6-DOF pilot
(``SubROV``) and the towed UUV's depth reference (``SubDepth``, flown by the winch).

One law for the modes (issues 28 and 30): a ground station picks an ArduSub mode (numbers of ArduSub's
``mode.h``: STABILIZE 0, ACRO 1, ALT_HOLD 2, AUTO 3, GUIDED 4, SURFACE 9, POSHOLD 16, MANUAL 19) and the
MAVLink front end (:mod:`oceangnc.mavlink.sub`) only writes the operator's inputs on the bus, as external
signals of the body ``b``:

* ``b.sub_mode`` (count): the ArduSub mode number; ``b.sub_pilot`` (bool): 1 while a ground station flies
  the vehicle (0: no pilot, the scenario's own set point is held, so a batch run is unchanged);
* ``b.stick_x``, ``b.stick_y``, ``b.stick_z``, ``b.stick_r`` (1): MANUAL_CONTROL's axes in [-1, 1]
  (x forward, y to starboard, z *up* - ArduSub's throttle, 500 of 0..1000 neutral - and r yaw to starboard);
* ``b.target_n``, ``b.target_e``, ``b.target_z`` (m): the GUIDED / AUTO target, ``b.target_z`` a depth
  (down positive); ``b.target_valid`` (count) says which are set: 1 the horizontal target, 2 the depth
  (3 both; 0 none: hold where the mode was entered).

**Depth reference** (:func:`depth_reference`, the same for the ROV and the towed UUV):

* MANUAL, STABILIZE, ACRO: no depth hold; the reference follows the depth (so that engaging ALT_HOLD is
  bumpless) and the stick's climb rate is passed on;
* ALT_HOLD, POSHOLD (and GUIDED / AUTO without a depth target): the depth at the moment the mode is
  entered is held; the z stick outside its dead band moves the reference at up to PILOT_SPEED_UP upward
  / PILOT_SPEED_DN downward (ArduSub's ``ModeAlthold``: the pilot's climb rate drives the position
  controller's target), kept within [0, ``z_max``];
* GUIDED, AUTO with a depth target, SURFACE (target 0 m): the reference slews to the target at those speeds.

The climb rate from the stick (:func:`pilot_climb`): zero inside the dead band d (fraction of full
deflection), then linear to full speed, s' = (|s| - d) / (1 - d).

**ROV** (:class:`SubROV`): per DOF of tau = [X, Y, Z, K, M, N] either the pilot's stick, scaled to
JS_GAIN x the largest force the weighted pseudo-inverse gives alone on that axis (``tau_max``, from the vehicle's
thrusters), or a hold by the project's anti-windup PID (:func:`oceangnc.control.pid.pid_run`, 003 eq. 3.10)
on the error of the held quantity with the measured rate as the error rate:

=========== ======== ======== ========== ============ =========================
mode        X, Y     Z        K, M       N (yaw)      held
=========== ======== ======== ========== ============ =========================
MANUAL      stick    stick    0          stick        nothing
STABILIZE   stick    stick    hold 0     hold / stick roll, pitch, heading
ACRO        stick    stick    hold 0     hold / stick (as STABILIZE)
ALT_HOLD    stick    hold     hold 0     hold / stick + depth (reference above)
POSHOLD     hold/stk hold     hold 0     hold / stick + position where the sticks were released
GUIDED/AUTO hold     hold     hold 0     hold         position target, depth target
SURFACE     stick    hold     hold 0     hold / stick depth reference slews to 0
no pilot    hold     hold     hold 0     hold         the scenario's set point (x, y, z, psi)
=========== ======== ======== ========== ============ =========================

"hold / stick": the heading is held while the yaw stick is inside its dead band and re-captured when it
is released. Position errors are rotated into the body axes by the heading. On ``_estop`` (disarmed or
e-stopped) every output is zero, no integrator moves and the held references are re-captured when it
clears; the outputs then come back with the resume ramp of :mod:`oceangnc.core.estop` (which the
back-calculation sees). The thrusts are the allocation's (``vehicle.allocation``), which ramps too.

**Towed UUV** (:class:`SubDepth`): the 003 UUV has no vertical thruster; its depth is set by the cable,
so the depth actuator is the winch (:class:`oceangnc.control.winch.WinchDepthController`, which reads
``uuv.depth_cmd`` and feeds ``uuv.depth_rate_cmd`` forward). In the stick modes the reference follows
the depth and the rate is the stick's, so the winch pays out or hauls in at the stick's rate (open loop
in depth, as ArduSub's throttle); with no pilot the configured target is held.
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit

from ..core.estop import RESUME_RAMP_S, resume_weight
from ..core.law import Ext, In, LawBlock, Layout, Opt, Out, Signals
from ..core.rotations import wrap
from .pid import PID_PARAMS, PID_STATE, pid_clear, pid_params, pid_run

#: ArduSub's mode numbers (ArduSub/mode.h)
STABILIZE, ACRO, ALT_HOLD, AUTO, GUIDED, CIRCLE, SURFACE, POSHOLD, MANUAL = 0, 1, 2, 3, 4, 7, 9, 16, 19
#: the modes :func:`depth_reference` and :class:`SubROV` fly
FLOWN = (STABILIZE, ACRO, ALT_HOLD, AUTO, GUIDED, SURFACE, POSHOLD, MANUAL)
NO_PILOT = -1.0


@njit(cache=True)
def pilot_climb(s, up, dn, dead):
    """Climb rate (m/s, up positive) for the z stick ``s`` in [-1, 1] (up positive): zero inside the
    dead band ``dead``, then linear to ``up`` (stick up) or ``dn`` (stick down) at full deflection."""
    a = abs(s)
    if a <= dead:
        return 0.0
    k = min(1.0, (a - dead) / (1.0 - dead))
    return k * up if s > 0.0 else -k * dn


@njit(cache=True)
def depth_reference(mode, entered, z, zc, stick_z, target, up, dn, dead, dt, z_max):
    """ArduSub's depth reference for one period (module docstring): returns (z_ref m, its rate m/s
    (down positive), 1.0 if the depth is held else 0.0). ``zc`` is the last reference, ``entered``
    true on the first period of the mode; ``target`` a depth (NaN: none)."""
    if mode == MANUAL or mode == STABILIZE or mode == ACRO:
        return z, -pilot_climb(stick_z, up, dn, dead), 0.0
    if entered or not math.isfinite(zc):
        zc = z
    if mode == SURFACE:
        target = 0.0
    elif mode != GUIDED and mode != AUTO:
        target = math.nan
    if math.isfinite(target):
        goal = min(z_max, max(0.0, target))
        d = goal - zc
        step = (dn if d > 0.0 else up) * dt
        if abs(d) <= step:
            return goal, d / dt, 1.0
        rate = math.copysign(step / dt, d)
        return zc + rate * dt, rate, 1.0
    rate = -pilot_climb(stick_z, up, dn, dead)
    new = min(z_max, max(0.0, zc + rate * dt))
    return new, (new - zc) / dt, 1.0


@njit(cache=True)
def level_from_body(phi, theta, a, b, c):
    """A body-axis vector (a, b, c) in the level frame of the heading: R_y(theta) R_x(phi) (Fossen 2021
    eq. 2.18 without the yaw rotation), e.g. the body velocity to (x', y', z') of that frame."""
    cf, sf, ct, st = math.cos(phi), math.sin(phi), math.cos(theta), math.sin(theta)
    y = cf * b - sf * c
    z = sf * b + cf * c
    return np.array([ct * a + st * z, y, -st * a + ct * z])


@njit(cache=True)
def body_from_level(phi, theta, a, b, c):
    """A level-frame vector (a, b, c) in the body axes: the transpose of :func:`level_from_body`."""
    cf, sf, ct, st = math.cos(phi), math.sin(phi), math.cos(theta), math.sin(theta)
    x = ct * a - st * c
    z = st * a + ct * c
    return np.array([x, cf * b + sf * z, -sf * b + cf * z])


# -- the towed UUV's depth reference ---------------------------------------------------------------------

DEPTH_SIGNALS = Signals(
    z=In("m"), mode=Ext("count"), pilot=Ext("bool"), stick_z=Ext("1"), target=Ext("m"), valid=Ext("count"),
    z_ref=Out("m"), rate=Out("m/s"), held=Out("bool"),
)  # fmt: skip
DEPTH_PARAMS = Layout("up", "dn", "dead", "z_max", "period", "z0")
DEPTH_STATE = Layout("prev", "zc")
_DS, _DP, _DX = DEPTH_SIGNALS.at, DEPTH_PARAMS.at, DEPTH_STATE.at


@njit(cache=True)
def sub_depth_law(t, sig, sl, st, pa):
    """The towed UUV's depth reference (module docstring): ``z_ref`` (m), its rate (m/s, the winch's
    feed-forward) and whether the depth is held; with no pilot the configured depth ``z0``."""
    z = sig[sl[_DS.z]]
    if sig[sl[_DS.pilot]] == 0.0 or not math.isfinite(z):
        st[_DX.prev] = NO_PILOT
        st[_DX.zc] = pa[_DP.z0]
        sig[sl[_DS.z_ref]] = pa[_DP.z0]
        sig[sl[_DS.rate]] = 0.0
        sig[sl[_DS.held]] = 1.0
        return
    mode = sig[sl[_DS.mode]]
    entered = mode != st[_DX.prev]
    st[_DX.prev] = mode
    target = sig[sl[_DS.target]] if int(sig[sl[_DS.valid]]) & 2 else math.nan
    zc, rate, held = depth_reference(
        mode, entered, z, st[_DX.zc], sig[sl[_DS.stick_z]], target, pa[_DP.up], pa[_DP.dn],
        pa[_DP.dead], pa[_DP.period], pa[_DP.z_max],
    )  # fmt: skip
    st[_DX.zc] = zc
    sig[sl[_DS.z_ref]] = zc
    sig[sl[_DS.rate]] = rate
    sig[sl[_DS.held]] = held


class SubDepth(LawBlock):
    """Depth reference of a towed body in ArduSub's modes (module docstring); law :func:`sub_depth_law`.

    Reads ``<body>.z`` (m) and the front end's ``<body>.sub_mode``, ``<body>.sub_pilot``,
    ``<body>.stick_z``, ``<body>.target_z``; writes ``<body>.depth_cmd`` (m), ``<body>.depth_rate_cmd``
    (m/s) and ``<body>.depth_held``. ``z0`` (m) is the depth held without a pilot; ``up`` / ``dn`` the
    pilot's climb / descent speeds (m/s, ArduSub PILOT_SPEED_UP / PILOT_SPEED_DN), ``dead`` the stick's dead
    band, ``z_max`` the deepest reference (m)."""

    role = "guidance"
    law = staticmethod(sub_depth_law)
    signals = DEPTH_SIGNALS

    def __init__(self, z0: float, period: float = 0.1, body: str = "uuv", up: float = 0.5, dn: float = 0.5,
                 dead: float = 0.1, z_max: float = 100.0):  # fmt: skip
        self.period, self.body, self.name = float(period), body, f"{body}_sub_depth"
        b = body
        self.bind(
            z=f"{b}.z", mode=f"{b}.sub_mode", pilot=f"{b}.sub_pilot", stick_z=f"{b}.stick_z", target=f"{b}.target_z",
            valid=f"{b}.target_valid", z_ref=f"{b}.depth_cmd", rate=f"{b}.depth_rate_cmd", held=f"{b}.depth_held",
        )  # fmt: skip
        self.pa = DEPTH_PARAMS.pack(up=up, dn=dn, dead=dead, z_max=z_max, period=self.period, z0=z0)
        self.st = DEPTH_STATE.pack(prev=NO_PILOT, zc=z0)

    def reset(self, rng) -> None:
        self.st[:] = DEPTH_STATE.pack(prev=NO_PILOT, zc=self.pa[_DP.z0])


# -- the ROV's 6-DOF pilot -------------------------------------------------------------------------------

ROV_SIGNALS = Signals(
    pos=In("m", 3), att=In("rad", 3), vel=In("m/s", 3), rate=In("rad/s", 3), mode=Ext("count"), pilot=Ext("bool"),
    stick=Ext("1", 4), target=Ext("m", 3), valid=Ext("count"), estop=Opt("bool"), force=Out("N", 3),
    moment=Out("N m", 3), ref=Out("m", 3), psi_ref=Out("rad"),
)  # fmt: skip
_NP, _NS = PID_PARAMS.size, PID_STATE.size
ROV_PARAMS = Layout(
    ("pid", 6 * _NP), ("tau_max", 6), "gain", "up", "dn", "dead", "z_max", "period", "ramp_s", "x0", "y0", "z0",
    "psi0",
)  # fmt: skip
ROV_STATE = Layout(("pid", 6 * _NS), "prev", "xc", "yc", "zc", "psic", "w")
_RS, _RP, _RX = ROV_SIGNALS.at, ROV_PARAMS.at, ROV_STATE.at
_RECAPTURE = -2.0  # prev mode after a stop: every reference is taken again where the vehicle is


@njit(cache=True)
def sub_rov_law(t, sig, sl, st, pa):
    """tau (N, N m, body axes) of the ROV in its ArduSub mode (module docstring's table), the held
    references (x, y, depth in m, heading in rad); zero on ``_estop``, ramped back after it."""
    dt = pa[_RP.period]
    stop = sl[_RS.estop] >= 0 and sig[sl[_RS.estop]] != 0.0
    st[_RX.w] = resume_weight(st[_RX.w], stop, dt, pa[_RP.ramp_s])
    w = st[_RX.w]
    x = sig[sl[_RS.pos]]
    y = sig[sl[_RS.pos + 1]]
    z = sig[sl[_RS.pos + 2]]
    psi = sig[sl[_RS.att + 2]]
    pilot = sig[sl[_RS.pilot]] != 0.0
    mode = sig[sl[_RS.mode]] if pilot else NO_PILOT
    if stop:
        st[_RX.prev] = _RECAPTURE
        st[_RX.xc], st[_RX.yc], st[_RX.zc], st[_RX.psic] = x, y, z, psi
        for i in range(3):
            sig[sl[_RS.force + i]] = 0.0
            sig[sl[_RS.moment + i]] = 0.0
            sig[sl[_RS.ref + i]] = sig[sl[_RS.pos + i]]
        sig[sl[_RS.psi_ref]] = psi
        return
    entered = mode != st[_RX.prev]
    st[_RX.prev] = mode
    dead = pa[_RP.dead]
    stick = np.zeros(4)
    if pilot:
        for i in range(4):
            stick[i] = sig[sl[_RS.stick + i]]
    hold = np.zeros(6)
    zrate = 0.0  # the depth reference's rate (m/s, down positive): the heave error's rate is zrate - z'
    valid = int(sig[sl[_RS.valid]]) if pilot else 0
    # depth
    if mode == NO_PILOT:
        st[_RX.zc] = pa[_RP.z0]
        hold[2] = 1.0
    else:
        tz = sig[sl[_RS.target + 2]] if valid & 2 else math.nan
        zc, zrate, hz = depth_reference(
            mode, entered, z, st[_RX.zc], stick[2], tz, pa[_RP.up], pa[_RP.dn], dead, dt, pa[_RP.z_max]
        )  # fmt: skip
        st[_RX.zc] = zc
        hold[2] = hz
    # attitude and heading
    if mode != MANUAL:
        hold[3] = 1.0
        hold[4] = 1.0
    if mode == NO_PILOT:
        st[_RX.psic] = pa[_RP.psi0]
        hold[5] = 1.0
    elif mode == MANUAL or abs(stick[3]) > dead:
        st[_RX.psic] = psi
    else:
        if entered:
            st[_RX.psic] = psi
        hold[5] = 1.0
    # position
    if mode == NO_PILOT:
        st[_RX.xc], st[_RX.yc] = pa[_RP.x0], pa[_RP.y0]
        hold[0] = hold[1] = 1.0
    elif mode == GUIDED or mode == AUTO:
        if valid & 1:
            st[_RX.xc], st[_RX.yc] = sig[sl[_RS.target]], sig[sl[_RS.target + 1]]
        elif entered:
            st[_RX.xc], st[_RX.yc] = x, y
        hold[0] = hold[1] = 1.0
    elif mode == POSHOLD and abs(stick[0]) <= dead and abs(stick[1]) <= dead:
        if entered:
            st[_RX.xc], st[_RX.yc] = x, y
        hold[0] = hold[1] = 1.0
    else:
        st[_RX.xc], st[_RX.yc] = x, y
    c = math.cos(psi)
    s = math.sin(psi)
    ex = st[_RX.xc] - x
    ey = st[_RX.yc] - y
    e = np.empty(6)
    e[0] = c * ex + s * ey
    e[1] = -s * ex + c * ey
    e[2] = st[_RX.zc] - z
    e[3] = -sig[sl[_RS.att]]
    e[4] = -sig[sl[_RS.att + 1]]
    e[5] = wrap(st[_RX.psic] - psi)
    # the stick on each axis (z up on the stick is -Z, down positive, in the body axes)
    direct = np.zeros(6)
    direct[0] = stick[0]
    direct[1] = stick[1]
    direct[2] = -stick[2]
    direct[5] = stick[3]
    # the held translations in the level frame of the heading (x ahead, y to starboard, z down: the errors'
    # frame), their rates from the body velocity by roll and pitch (ż, not w, is the depth's rate)
    lv = level_from_body(sig[sl[_RS.att]], sig[sl[_RS.att + 1]], sig[sl[_RS.vel]], sig[sl[_RS.vel + 1]],
                         sig[sl[_RS.vel + 2]])  # fmt: skip
    held = np.zeros(3)
    body = np.zeros(3)
    for i in range(6):
        if hold[i] != 0.0:
            de = (zrate - lv[2] if i == 2 else -lv[i]) if i < 3 else -sig[sl[_RS.rate + i - 3]]
            out = pid_run(st, _RX.pid + i * _NS, pa, _RP.pid + i * _NP, e[i], dt, de, True, 0.0, w)
        else:
            pid_clear(st, _RX.pid + i * _NS)
            out = w * pa[_RP.gain] * pa[_RP.tau_max + i] * direct[i]
        if i < 3:
            if hold[i] != 0.0:
                held[i] = out
            else:
                body[i] = out
        else:
            sig[sl[_RS.moment + i - 3]] = out
    fb = body_from_level(sig[sl[_RS.att]], sig[sl[_RS.att + 1]], held[0], held[1], held[2])
    for i in range(3):
        sig[sl[_RS.force + i]] = body[i] + fb[i]
    sig[sl[_RS.ref]] = st[_RX.xc]
    sig[sl[_RS.ref + 1]] = st[_RX.yc]
    sig[sl[_RS.ref + 2]] = st[_RX.zc]
    sig[sl[_RS.psi_ref]] = st[_RX.psic]


def axis_limits(allocation: np.ndarray, fwd, rev) -> np.ndarray:
    """The largest |tau_i| (N or N m) the allocation gives alone on each axis before a thruster reaches
    its limit: for the column P[:, i] of the n x 6 allocation matrix, min_j limit_j / |P_ji| (limit the
    forward or reverse one by the sign; infinite for an axis it does not control)."""
    out = np.full(6, np.inf)
    for i in range(6):
        col = allocation[:, i]
        for j, p in enumerate(col):
            if abs(p) > 1e-12:
                out[i] = min(out[i], (fwd[j] if p > 0 else rev[j]) / abs(p))
    return out


class SubROV(LawBlock):
    """A ROV of a vehicle file flown in ArduSub's modes (module docstring); law :func:`sub_rov_law`.

    Reads ``<body>.x/y/z``, ``phi/theta/psi``, ``u/v/w``, ``p/q/r`` and the front end's external signals;
    writes ``<body>.tau_X ... tau_N`` for the allocation and the held references ``<body>.ref_x``,
    ``ref_y``, ``depth_cmd`` (m) and ``psi_ref`` (rad).

    ``gains`` maps a DOF (``surge`` ... ``yaw``) to (k_p, k_i, k_d) as the scenario's ``control.gains``;
    ``tau_max`` the full-stick force/moment per axis (:func:`axis_limits`); ``setpoint`` the no-pilot
    hold (``x``, ``y``, ``z`` m, ``psi`` rad); ``gain`` ArduSub's JS_GAIN (0.5 by default)."""

    role = "controller"
    law = staticmethod(sub_rov_law)
    signals = ROV_SIGNALS

    def __init__(self, gains: dict, tau_max, setpoint: dict, period: float = 0.05, body: str = "vehicle",
                 gain: float = 0.5, up: float = 0.5, dn: float = 0.5, dead: float = 0.1,
                 z_max: float = 100.0):  # fmt: skip
        from ..models.vehicle import DOF_NAMES

        self.period, self.body, self.name = float(period), body, f"{body}_sub"
        b = body
        self.bind(
            pos=[f"{b}.x", f"{b}.y", f"{b}.z"], att=[f"{b}.phi", f"{b}.theta", f"{b}.psi"],
            vel=[f"{b}.u", f"{b}.v", f"{b}.w"], rate=[f"{b}.p", f"{b}.q", f"{b}.r"], mode=f"{b}.sub_mode",
            pilot=f"{b}.sub_pilot", stick=[f"{b}.stick_{a}" for a in "xyzr"],
            target=[f"{b}.target_n", f"{b}.target_e", f"{b}.target_z"], valid=f"{b}.target_valid", estop="_estop",
            force=[f"{b}.tau_{a}" for a in "XYZ"], moment=[f"{b}.tau_{a}" for a in "KMN"],
            ref=[f"{b}.ref_x", f"{b}.ref_y", f"{b}.depth_cmd"], psi_ref=f"{b}.psi_ref",
        )  # fmt: skip
        tmax = np.asarray(tau_max, float)
        pids = []
        for i, dof in enumerate(DOF_NAMES):
            kp, ki, kd = gains.get(dof, (0.0, 0.0, 0.0))
            lim = tmax[i] if math.isfinite(tmax[i]) else 1e9
            pids.append(PID_PARAMS.pack(pid_params(kp, ki, kd, -lim, lim)))
        self.pa = ROV_PARAMS.pack(
            pid=np.concatenate(pids), tau_max=np.where(np.isfinite(tmax), tmax, 0.0), gain=gain, up=up, dn=dn,
            dead=dead, z_max=z_max, period=self.period, ramp_s=RESUME_RAMP_S, x0=setpoint.get("x", 0.0),
            y0=setpoint.get("y", 0.0), z0=setpoint.get("z", 0.0), psi0=setpoint.get("psi", 0.0),
        )  # fmt: skip
        self.st = ROV_STATE.pack(pid=np.zeros(6 * _NS), prev=_RECAPTURE, xc=0.0, yc=0.0, zc=0.0, psic=0.0, w=1.0)

    def reset(self, rng) -> None:
        self.st[:] = ROV_STATE.pack(pid=np.zeros(6 * _NS), prev=_RECAPTURE, xc=0.0, yc=0.0, zc=0.0, psic=0.0, w=1.0)
