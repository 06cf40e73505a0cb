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

from pydantic import Field

from ..core.blocks import Block
from ..core.registry import register_block
from ..io.config import StrictModel
from ..sensors.filters import LowPass
from ..units import KGF
from .usv_control import aw_pid


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


@register_block("uuv.pid")
class UUVPIDController(Block):
    """PID leader-follower controller of the UUV (module docstring).

    Reads the leader-follower signals ``lf.*`` (:class:`oceangnc.guidance.leader_follower.LeaderFollower`)
    and the yaw rates (bus keys ``meas["r_usv"]``, ``meas["r_uuv"]``); writes
    ``uuv.thrust_port_cmd``, ``uuv.thrust_stbd_cmd``, ``uuv.thrust_bow_cmd`` (N),
    ``uuv_ctrl.psi_d`` (rad, the heading the active loop follows) and ``uuv_ctrl.loop`` (2 or 3).
    """

    role = "controller"

    name = "uuv_control"

    def __init__(
        self, cfg: UUVPIDConfig, uuv_cfg, period: float = 0.05, mode: str = "relative-angle-plus-heading", meas=None
    ):
        self.cfg = cfg
        self.period = float(period)
        self.mode = mode
        hi = uuv_cfg.max_thrust_kgf * KGF
        lo = -uuv_cfg.max_reverse_kgf * KGF
        self.meas = {"r_usv": "usv.r", "r_uuv": "uuv.r", "psi_usv": "usv.psi", **(meas or {})}
        self.pos = aw_pid(cfg.range_kp, cfg.range_ki, cfg.range_kd, lo, hi)
        self.ang = aw_pid(cfg.angle_kp, cfg.angle_ki, cfg.angle_kd, lo, hi)
        self.los = aw_pid(cfg.los_kp, cfg.los_ki, cfg.los_kd, lo, hi)
        m = self.meas
        self.inputs = {
            "lf.e_x": "m",
            "lf.outside": "bool",
            "lf.rel_heading_err": "rad",
            "lf.los_err": "rad",
            "lf.los": "rad",
            m["r_usv"]: "rad/s",
            m["r_uuv"]: "rad/s",
            m["psi_usv"]: "rad",
        }
        self.outputs = {
            "uuv.thrust_port_cmd": "N",
            "uuv.thrust_stbd_cmd": "N",
            "uuv.thrust_bow_cmd": "N",
            "uuv_ctrl.psi_d": "rad",
            "uuv_ctrl.loop": "count",
        }

    params_model = UUVPIDConfig

    @classmethod
    def from_context(cls, params: UUVPIDConfig, ctx) -> UUVPIDController:
        """Built from a scenario's ``control.uuv`` slot (:func:`oceangnc.core.registry.build_block`):
        ``ctx.cfg.uuv`` for the thrust limits, ``ctx.info["mode"]`` the formation mode, measured yaw
        rates and USV heading from ``ctx.signal``."""
        return cls(
            params,
            ctx.cfg.uuv,
            ctx.period,
            mode=ctx.info.get("mode", "relative-angle-plus-heading"),
            meas={"r_usv": ctx.signal("usv.r"), "r_uuv": ctx.signal("uuv.r"), "psi_usv": ctx.signal("usv.psi")},
        )

    def reset(self, rng) -> None:
        self.pos.reset()
        self.ang.reset()
        self.los.reset()
        self.active = 2
        self.e1_prev = None
        self.e1_rate = LowPass(self.cfg.range_d_cutoff_hz, self.period)

    def compiled(self):
        """Compiled form for the fused loop (:func:`oceangnc.control._compiled.uuv_pid_step`)."""
        from ..core.fused import CompiledBlock
        from ._compiled import arr, pid_params, pid_state, uuv_pid_step

        m = self.meas
        sig = [
            "lf.e_x",
            m["r_uuv"],
            "lf.outside",
            "lf.rel_heading_err",
            m["r_usv"],
            m["psi_usv"],
            "lf.los_err",
            "lf.los",
            "uuv.thrust_port_cmd",
            "uuv.thrust_stbd_cmd",
            "uuv.thrust_bow_cmd",
            "uuv_ctrl.psi_d",
            "uuv_ctrl.loop",
        ]
        lp = self.e1_rate
        st = arr(
            pid_state(self.pos)
            + pid_state(self.ang)
            + pid_state(self.los)
            + [
                self.active,
                self.e1_prev if self.e1_prev is not None else 0.0,
                0.0 if self.e1_prev is None else 1.0,
                lp.y if lp.y is not None else 0.0,
                0.0 if lp.y is None else 1.0,
            ]
        )
        pa = arr(
            pid_params(self.pos)
            + pid_params(self.ang)
            + pid_params(self.los)
            + [self.period, lp.a, 1.0 if self.mode == "relative-angle" else 0.0]
        )
        return CompiledBlock(uuv_pid_step, sig, st, pa)

    def step(self, t: float, bus: dict) -> None:
        h = self.period
        e1 = bus["lf.e_x"]
        d = 0.0 if self.e1_prev is None else (e1 - self.e1_prev) / h
        self.e1_prev = e1
        u1 = self.pos.step(e1, h, e_dot=self.e1_rate(d))
        r_uuv = bus[self.meas["r_uuv"]]
        outside = bus["lf.outside"] > 0.5 and self.mode != "relative-angle"
        loop = 3 if outside else 2
        if loop != self.active:
            (self.los if loop == 3 else self.ang).integral = (self.ang if loop == 3 else self.los).integral
            (self.los if loop == 3 else self.ang)._e_prev = None
            self.active = loop
        if loop == 2:
            ub = self.ang.step(bus["lf.rel_heading_err"], h, e_dot=bus[self.meas["r_usv"]] - r_uuv)
            psi_d = bus[self.meas["psi_usv"]]
        else:
            ub = self.los.step(bus["lf.los_err"], h, e_dot=-r_uuv)
            psi_d = bus["lf.los"]
        bus["uuv.thrust_port_cmd"] = u1
        bus["uuv.thrust_stbd_cmd"] = u1
        bus["uuv.thrust_bow_cmd"] = ub
        bus["uuv_ctrl.psi_d"] = psi_d
        bus["uuv_ctrl.loop"] = float(loop)
