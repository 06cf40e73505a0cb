"""UUV leader-follower PID control (003 ch. 3.3.1, eq. 3.12-3.13).

Three anti-windup PIDs (:class:`oceangnc.control.pid.PID`, eq. 3.10 with K_w = 1/K_p):

* n = 1, *position*: the error is the distance to the target point (the leader-follower offset
  l_x^d, l_y^d of eq. 3.8) along the UUV's own axis, e_1 = lf.e_x (m, positive when the target is
  ahead). Both stern thrusters get the same command, U_port = U_stbd = U_f,1 (eq. 3.13).
* n = 2, *relative angle*: e_2 = wrap(psi_usv - psi_uuv) (eq. 3.9), the UUV keeps the USV's heading.
* n = 3, *heading to the USV*: e_3 = wrap(alpha - psi_uuv), alpha the LOS bearing from the UUV to
  the USV (table 3-2), which brings the UUV back under the USV.

The bow thruster follows n = 2 while the range l < R and n = 3 when l > R (eq. 3.13). In mode
``relative-angle`` (003 fig. 4-6 (a)) it always follows n = 2. A bow thrust T_b > 0 pushes the bow to
starboard (N = T_b B_f > 0), so a positive heading error gives a positive command. When the active
heading loop switches, the newly active PID starts from the other's integral (bumpless transfer,
our choice; 003 does not say).

Derivatives: the range loop differentiates its error by a backward difference passed through a
first-order low-pass (``range_d_cutoff_hz``: the USBL updates the error in steps of 0.5 s, and the
raw difference would turn each step into a thrust spike); the heading loops use the measured yaw
rates, e_dot = r_usv - r_uuv (n = 2) and -r_uuv (n = 3).
"""

from __future__ import annotations

from typing import Literal

import numpy as np
from numba import njit
from pydantic import Field

from ..core.config import StrictModel
from ..core.estop import RESUME_RAMP_S, resume_weight
from ..core.law import FALSE, TRUE, In, LawBlock, Layout, Opt, Out, Signals
from ..core.registry import register_block
from ..models.uuv import UUVConfig
from ..sensors.filters import lowpass_coefficient, lowpass_step
from ..units import KGF
from .pid import PID, PID_PARAMS, PID_STATE, pid_params, pid_run


class UUVPIDConfig(StrictModel):
    """Gains of the UUV PID loops (tuned by hand on the combined model; docs/combined-vehicle.md)."""

    range_kp: float = Field(40.0, ge=0, le=1e5, description="position loop proportional gain, N/m")
    range_ki: float = Field(4.0, ge=0, le=1e5, description="position loop integral gain, N/(m s)")
    range_kd: float = Field(30.0, ge=0, le=1e5, description="position loop derivative gain, N s/m")
    range_d_cutoff_hz: float = Field(1.0, gt=0, le=100, description="low-pass cut-off of the range error rate, Hz")
    angle_kp: float = Field(40.0, ge=0, le=1e5, description="relative-angle loop proportional gain, N/rad")
    angle_ki: float = Field(0.0, ge=0, le=1e5, description="relative-angle loop integral gain, N/(rad s)")
    angle_kd: float = Field(25.0, ge=0, le=1e5, description="relative-angle loop derivative gain, N s/rad")
    los_kp: float = Field(40.0, ge=0, le=1e5, description="heading-to-USV loop proportional gain, N/rad")
    los_ki: float = Field(0.0, ge=0, le=1e5, description="heading-to-USV loop integral gain, N/(rad s)")
    los_kd: float = Field(25.0, ge=0, le=1e5, description="heading-to-USV loop derivative gain, N s/rad")


class UUVPIDParams(UUVPIDConfig):
    """The gains and what the block takes from its scenario (``build_block(..., given=...)``)."""

    uuv: UUVConfig = Field(..., description="the UUV driven: its thrust limits, kgf")
    mode: Literal["relative-angle", "relative-angle-plus-heading"] = Field(..., description="formation mode")


UUV_PID_SIGNALS = Signals(
    e_x=In("m"),
    r_uuv=In("rad/s"),
    outside=In("bool"),
    rel_err=In("rad"),
    r_usv=In("rad/s"),
    psi_usv=In("rad"),
    los_err=In("rad"),
    los=In("rad"),
    estop=Opt("bool"),
    port=Out("N"),
    stbd=Out("N"),
    bow=Out("N"),
    psi_d=Out("rad"),
    loop=Out("count"),
)
UUV_PID_PARAMS = Layout(
    ("pos", PID_PARAMS.size), ("ang", PID_PARAMS.size), ("los", PID_PARAMS.size), "h", "a", "angle_only"
)
UUV_PID_STATE = Layout(
    ("pos", PID_STATE.size),
    ("ang", PID_STATE.size),
    ("los", PID_STATE.size),
    "active",
    "e1_prev",
    "has_e1",
    "y",
    "has_y",
    "w",
)
_S, _P, _X = UUV_PID_SIGNALS.at, UUV_PID_PARAMS.at, UUV_PID_STATE.at
_HAS_E = PID_STATE.at.has_e_prev


@njit(cache=True)
def uuv_pid_law(t, sig, sl, st, pa):
    """The UUV's three PIDs (module docstring; 003 eq. 3.12-3.13): U_port = U_stbd = PID_1(e_1) with
    e_1 = lf.e_x (m) and its low-passed backward difference as the rate; the bow thruster from PID_2
    (relative angle, e_dot = r_usv - r_uuv) inside the range R, PID_3 (bearing to the USV, e_dot =
    -r_uuv) outside it, with the integral handed over at a switch. Outputs in N; ``uuv_ctrl.loop`` is
    2 or 3. While ``_estop`` is set the thrust is zero and no PID moves; after it the outputs
    ramp back with the resume weight (:mod:`oceangnc.core.estop`)."""
    h = pa[_P.h]
    if sl[_S.estop] >= 0 and sig[sl[_S.estop]] != 0.0:
        st[_X.w] = 0.0
        sig[sl[_S.port]] = 0.0
        sig[sl[_S.stbd]] = 0.0
        sig[sl[_S.bow]] = 0.0
        return
    w = st[_X.w] = resume_weight(st[_X.w], FALSE, h, RESUME_RAMP_S)
    e1 = sig[sl[_S.e_x]]
    d = 0.0 if st[_X.has_e1] == 0.0 else (e1 - st[_X.e1_prev]) / h
    st[_X.e1_prev] = e1
    st[_X.has_e1] = 1.0
    if st[_X.has_y] == 0.0:
        st[_X.y] = d
        st[_X.has_y] = 1.0
    else:
        st[_X.y] = lowpass_step(st[_X.y], pa[_P.a], d)
    u1 = pid_run(st, _X.pos, pa, _P.pos, e1, h, st[_X.y], TRUE, 0.0, w)
    r_uuv = sig[sl[_S.r_uuv]]
    outside = sig[sl[_S.outside]] > 0.5 and pa[_P.angle_only] == 0.0
    loop = 3.0 if outside else 2.0
    if loop != st[_X.active]:  # bumpless: the loop taking over starts from the other's integral
        if loop == 3.0:
            st[_X.los] = st[_X.ang]
            st[_X.los + _HAS_E] = 0.0
        else:
            st[_X.ang] = st[_X.los]
            st[_X.ang + _HAS_E] = 0.0
        st[_X.active] = loop
    if loop == 2.0:
        ub = pid_run(st, _X.ang, pa, _P.ang, sig[sl[_S.rel_err]], h, sig[sl[_S.r_usv]] - r_uuv, TRUE, 0.0, w)
        psi_d = sig[sl[_S.psi_usv]]
    else:
        ub = pid_run(st, _X.los, pa, _P.los, sig[sl[_S.los_err]], h, -r_uuv, TRUE, 0.0, w)
        psi_d = sig[sl[_S.los]]
    sig[sl[_S.port]] = u1
    sig[sl[_S.stbd]] = u1
    sig[sl[_S.bow]] = ub
    sig[sl[_S.psi_d]] = psi_d
    sig[sl[_S.loop]] = loop


@register_block("uuv.pid")
class UUVPIDController(LawBlock):
    """PID leader-follower controller of the UUV (module docstring); law :func:`uuv_pid_law`.

    Reads the leader-follower signals ``lf.*`` (:class:`oceangnc.guidance.leader_follower.LeaderFollower`)
    and the yaw rates (bus keys ``meas["r_usv"]``, ``meas["r_uuv"]``); writes
    ``uuv.thrust_port_cmd``, ``uuv.thrust_stbd_cmd``, ``uuv.thrust_bow_cmd`` (N),
    ``uuv_ctrl.psi_d`` (rad, the heading the active loop follows) and ``uuv_ctrl.loop`` (2 or 3).
    ``pos``, ``ang`` and ``los`` are :class:`~oceangnc.control.pid.PID` views of its state.
    """

    role = "controller"
    name = "uuv_control"
    law = staticmethod(uuv_pid_law)
    signals = UUV_PID_SIGNALS
    params_model = UUVPIDParams

    def __init__(
        self, cfg: UUVPIDConfig, uuv_cfg, period: float = 0.05, mode: str = "relative-angle-plus-heading", meas=None
    ):
        self.cfg = cfg
        self.period = float(period)
        self.mode = mode
        hi = uuv_cfg.max_thrust_kgf * KGF
        lo = -uuv_cfg.max_reverse_kgf * KGF
        self.meas = {"r_usv": "usv.r", "r_uuv": "uuv.r", "psi_usv": "usv.psi", **(meas or {})}
        m = self.meas
        self.bind(
            e_x="lf.e_x",
            r_uuv=m["r_uuv"],
            outside="lf.outside",
            rel_err="lf.rel_heading_err",
            r_usv=m["r_usv"],
            psi_usv=m["psi_usv"],
            los_err="lf.los_err",
            los="lf.los",
            estop="_estop",
            port="uuv.thrust_port_cmd",
            stbd="uuv.thrust_stbd_cmd",
            bow="uuv.thrust_bow_cmd",
            psi_d="uuv_ctrl.psi_d",
            loop="uuv_ctrl.loop",
        )
        self.pa = UUV_PID_PARAMS.pack(
            pos=PID_PARAMS.pack(pid_params(cfg.range_kp, cfg.range_ki, cfg.range_kd, lo, hi)),
            ang=PID_PARAMS.pack(pid_params(cfg.angle_kp, cfg.angle_ki, cfg.angle_kd, lo, hi)),
            los=PID_PARAMS.pack(pid_params(cfg.los_kp, cfg.los_ki, cfg.los_kd, lo, hi)),
            h=self.period,
            a=lowpass_coefficient(cfg.range_d_cutoff_hz, self.period),
            angle_only=1.0 if mode == "relative-angle" else 0.0,
        )
        self.st = np.zeros(UUV_PID_STATE.size)
        self.st[_X.w] = 1.0
        self.pos = PID.view(self.st, _X.pos, self.pa, _P.pos)
        self.ang = PID.view(self.st, _X.ang, self.pa, _P.ang)
        self.los = PID.view(self.st, _X.los, self.pa, _P.los)

    @classmethod
    def from_context(cls, params: UUVPIDParams, ctx) -> UUVPIDController:
        """Built from a scenario's ``control.uuv`` slot (:func:`oceangnc.core.registry.build_block`):
        its own parameters (the gains, the vehicle ``uuv`` for the thrust limits, the formation
        ``mode``), measured yaw rates and USV heading from ``ctx.signal``."""
        return cls(
            params,
            params.uuv,
            ctx.period,
            mode=params.mode,
            meas={"r_usv": ctx.signal("usv.r"), "r_uuv": ctx.signal("uuv.r"), "psi_usv": ctx.signal("usv.psi")},
        )

    def reset(self, rng) -> None:
        self.st[:] = 0.0
        self.st[_X.active] = 2.0
        self.st[_X.w] = 1.0
