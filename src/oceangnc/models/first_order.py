"""First-order USV model of document 000: speed and yaw-rate lags with speed-dependent coefficients.

Equations (000_709eacce50bfa23e.txt eq. 8 and 15) and the kinematics of eq. 1 without sway
(the identified model has no sway state)::

    T_v(u) u' + u = K_v(u) delta_T          speed u (m/s), shaft speed delta_T (rev/min)
    T_r(u) r' + r = K_r(u) delta_S          yaw rate r (rad/s), rudder delta_S (rad)
    x' = u cos(psi),  y' = u sin(psi),  psi' = r      (NED)

Coefficients (000 table 2, least squares over 9 straight and 6 turning sea trials)::

    K_v = 0.0004 u + 0.0014   (m/s)/rpm        T_v = 1.1737 u - 2.2474   s
    K_r = -0.0113 u + 0.7176  1/s              T_r = -0.1534 u + 2.6341  s

Units. K_v is per rev/min, as the paper's delta_T [rpm] (nomenclature). K_r is a rate ratio in 1/s:
it assumes delta_S in rad with r in rad/s (identically, delta_S in deg with r in deg/s). With
delta_S in deg and r in rad/s it would be 57.3 times smaller; at 6 m/s and 10 deg of rudder our
reading gives r = 6.5 deg/s (a 53 m turning radius), which fits a fast ~10 m USV, while the other
reading would give 0.11 deg/s (a 3 km circle), so the rad/rad reading is the one the trials support.

Clamping the schedule (SPEC.md 000 notes). The laws are only valid over the trial ranges,
4.87-16.02 m/s straight (K_v, T_v) and 4.02-8.74 m/s turning (K_r, T_r). T_v would be negative
below 1.915 m/s (an unstable model), yet the paper's figs 18 and 21 start from rest. We therefore
evaluate each coefficient at the speed clipped to its trial range, ``f(clip(u, lo, hi))``: from rest
the boat accelerates with T_v(4.87) = 3.47 s and K_v(4.87) = 0.00335 (m/s)/rpm, and above the range
the last identified values are held. The plant publishes ``usv.schedule_clamped`` (1 while the
speed is outside either range) and warns once (``RuntimeWarning``) the first time it happens.

Operating-speed variant. 000 sec. 4.1 says the model "depends on the specific speed u_0": each
trial identifies a *linear* model at its speed. With ``schedule = "operating"`` the coefficients are
evaluated at an operating speed read from the bus (``usv.u_op``, e.g. a trial's target speed), so
the plant is exactly that linear model; with the default ``"speed"`` they follow the instantaneous
speed, which makes the speed loop nonlinear (near equilibrium its time constant is
T_v / (1 - 0.0004 delta_T), about 4 T_v at 12 m/s) and a straight run from rest is then no
longer a first-order lag with T_v(U).

State ``x = [x_n, y_e, psi, u, r]`` (m, m, rad, m/s, rad/s); inputs ``[usv.rpm, usv.delta_s, usv.u_op]``
(rev/min, rad, m/s); parameters :data:`LAYOUT` (generated from the declared names);
:func:`first_order_model` is the :class:`~oceangnc.core.model.Model` (plant, linearisation, EKF).
"""

from __future__ import annotations

import math
import warnings
from typing import Literal

import numpy as np
from numba import njit
from pydantic import Field, model_validator

from ..core.blocks import Plant
from ..core.estop import RESUME_RAMP_S, resume_weight
from ..core.law import In, Layout, LawBlock, Opt, Out, Signals
from ..core.fused import advance_and_publish, plant_bus_keys, rk4_stepper_imports
from ..core.csmath import ccos, csin
from ..core.model import Model, Param, ParamLayout
from ..io.config import StrictModel

VEHICLE = "usv-first-order"
STATES = (("x", "m"), ("y", "m"), ("psi", "rad"), ("u", "m/s"), ("r", "rad/s"))
INPUTS = (("rpm", "rpm"), ("delta_s", "rad"), ("u_op", "m/s"))
STATE_NAMES = tuple(k for k, _ in STATES)
INPUT_NAMES = ("usv.rpm", "usv.delta_s", "usv.u_op")
#: parameters (000 table 2), generated layout
LAYOUT = ParamLayout(
    [
        Param("kv_slope", "(m/s)/rpm per m/s"),
        Param("kv_intercept", "(m/s)/rpm"),
        Param("tv_slope", "s per m/s"),
        Param("tv_intercept", "s"),
        Param("kr_slope", "1/s per m/s"),
        Param("kr_intercept", "1/s"),
        Param("tr_slope", "s per m/s"),
        Param("tr_intercept", "s"),
        Param("straight_lo", "m/s"),
        Param("straight_hi", "m/s"),
        Param("turn_lo", "m/s"),
        Param("turn_hi", "m/s"),
        Param("use_operating_speed", "bool", description="1: coefficients at u_op, 0: at the speed"),
    ]
)
P_NAMES = LAYOUT.names
(_KVS, _KVI, _TVS, _TVI, _KRS, _KRI, _TRS, _TRI, _SLO, _SHI, _TLO, _THI, _OPER) = LAYOUT.indices(*P_NAMES)


class FirstOrderConfig(StrictModel):
    """The first-order USV (000 table 2) and its actuator limits and initial state."""

    kv_slope: float = Field(
        0.0004, ge=-1.0, le=1.0, description="K_v = kv_slope u + kv_intercept: slope, (m/s)/rpm per m/s"
    )
    kv_intercept: float = Field(0.0014, ge=-1.0, le=1.0, description="K_v intercept, (m/s)/rpm")
    tv_slope: float = Field(1.1737, ge=-100, le=100, description="T_v = tv_slope u + tv_intercept: slope, s per m/s")
    tv_intercept: float = Field(-2.2474, ge=-1000, le=1000, description="T_v intercept, s")
    kr_slope: float = Field(-0.0113, ge=-10, le=10, description="K_r = kr_slope u + kr_intercept: slope, 1/s per m/s")
    kr_intercept: float = Field(0.7176, ge=-10, le=10, description="K_r intercept (delta_S in rad, r in rad/s), 1/s")
    tr_slope: float = Field(-0.1534, ge=-100, le=100, description="T_r = tr_slope u + tr_intercept: slope, s per m/s")
    tr_intercept: float = Field(2.6341, ge=-1000, le=1000, description="T_r intercept, s")
    straight_lo_mps: float = Field(4.87, ge=0, le=100, description="lowest speed of the straight trials, m/s")
    straight_hi_mps: float = Field(16.02, ge=0, le=100, description="highest speed of the straight trials, m/s")
    turn_lo_mps: float = Field(4.02, ge=0, le=100, description="lowest speed of the turning trials, m/s")
    turn_hi_mps: float = Field(8.74, ge=0, le=100, description="highest speed of the turning trials, m/s")
    rudder_limit_deg: float = Field(35.0, gt=0, le=90, description="rudder angle limit, deg")
    schedule: Literal["speed", "operating"] = Field(
        "speed",
        description="coefficients at the instantaneous speed ('speed') or at the operating speed u_0 "
        "read from the bus key usv.u_op ('operating', the linear model of a trial)",
    )
    rpm_max: float = Field(2100.0, gt=0, le=1e5, description="largest shaft speed, rpm")
    rpm_min: float = Field(0.0, ge=0, le=1e5, description="smallest shaft speed (no reverse), rpm")
    x0: float = Field(0.0, ge=-1e7, le=1e7, description="initial north position, m")
    y0: float = Field(0.0, ge=-1e7, le=1e7, description="initial east position, m")
    psi0_deg: float = Field(0.0, ge=-360, le=360, description="initial heading, deg")
    u0: float = Field(0.0, ge=0, le=50, description="initial speed, m/s")
    r0_degps: float = Field(0.0, ge=-90, le=90, description="initial yaw rate, deg/s")

    @model_validator(mode="after")
    def _check(self):
        if self.straight_lo_mps > self.straight_hi_mps:
            raise ValueError("straight_lo_mps must be <= straight_hi_mps")
        if self.turn_lo_mps > self.turn_hi_mps:
            raise ValueError("turn_lo_mps must be <= turn_hi_mps")
        if self.rpm_min > self.rpm_max:
            raise ValueError("rpm_min must be <= rpm_max")
        for name, lo, hi in (
            ("T_v", self.straight_lo_mps, self.straight_hi_mps),
            ("T_r", self.turn_lo_mps, self.turn_hi_mps),
        ):
            for u in (lo, hi):
                T = self.coefficients(u)[name]
                if not T > 0.0:
                    raise ValueError(f"{name}({u:g} m/s) = {T:.4g} s: time constants must be > 0 over the trial range")
        return self

    def params(self) -> np.ndarray:
        """Flat parameter array in the layout :data:`LAYOUT`."""
        v = {k: getattr(self, k) for k in P_NAMES[:8]}
        v.update(
            straight_lo=self.straight_lo_mps,
            straight_hi=self.straight_hi_mps,
            turn_lo=self.turn_lo_mps,
            turn_hi=self.turn_hi_mps,
            use_operating_speed=1.0 if self.schedule == "operating" else 0.0,
        )
        return LAYOUT.pack(v)

    def coefficients(self, u: float) -> dict:
        """K_v ((m/s)/rpm), T_v (s), K_r (1/s), T_r (s) at speed ``u`` (m/s), with the clamped schedule."""
        # the pure-Python twin of the compiled schedule: config validation must not call numba (it
        # runs at import time for the scenario defaults, and a numba call costs ~1 s in a new process)
        kv, tv, kr, tr = schedule.py_func(float(u), self.params())
        return {"K_v": kv, "T_v": tv, "K_r": kr, "T_r": tr}

    def trim_rpm(self, u: float) -> float:
        """Shaft speed (rpm) holding the steady speed ``u`` (m/s): u = K_v(u) n."""
        return float(u) / self.coefficients(u)["K_v"]

    def max_dt(self) -> float:
        """RK4 stability limit (s): 2.5 times the smallest time constant over the trial ranges."""
        ts = [
            self.coefficients(u)[k]
            for u in (self.straight_lo_mps, self.straight_hi_mps, self.turn_lo_mps, self.turn_hi_mps)
            for k in ("T_v", "T_r")
        ]
        return 2.5 * min(ts)


@njit(cache=True)
def schedule(u, p):
    """(K_v, T_v, K_r, T_r) at speed ``u`` (m/s), each law evaluated at u clipped to its trial range.

    The clip compares real parts and keeps ``u`` itself inside the range (complex step: d/du there)."""
    us = p[_SLO] if u.real < p[_SLO].real else (p[_SHI] if u.real > p[_SHI].real else u)
    ut = p[_TLO] if u.real < p[_TLO].real else (p[_THI] if u.real > p[_THI].real else u)
    return (p[_KVS] * us + p[_KVI], p[_TVS] * us + p[_TVI], p[_KRS] * ut + p[_KRI], p[_TRS] * ut + p[_TRI])


class FirstOrderSchedule:
    """One law of the clamped schedule as a ``coefficients(u) -> (K, T)`` callable for the autopilots of
    :mod:`oceangnc.control.pole_placement`: ``law = "nomoto"`` gives (K_r, T_r), ``"speed"`` (K_v, T_v).

    ``schedule_params`` (the layout :data:`LAYOUT`) lets the autopilots' compiled forms evaluate the
    same :func:`schedule` inside the fused loop (issue 19).
    """

    def __init__(self, cfg: FirstOrderConfig, law: str):
        if law not in ("nomoto", "speed"):
            raise ValueError(f"law must be 'nomoto' or 'speed', got {law!r}")
        self.law = law
        self.schedule_params = cfg.params()

    def __call__(self, u: float) -> tuple[float, float]:
        kv, tv, kr, tr = schedule.py_func(float(u), self.schedule_params)
        return (kr, tr) if self.law == "nomoto" else (kv, tv)


@njit(cache=True)
def first_order_rhs(t, x, u, p, out):
    """dx/dt of the first-order USV (000 eq. 8, 15 and 1); layouts in the module docstring."""
    psi = x[2]
    uu = x[3]
    r = x[4]
    kv, tv, kr, tr = schedule(u[2] + 0.0 * uu if p[_OPER].real > 0.5 else uu, p)
    out[0] = uu * ccos(psi)
    out[1] = uu * csin(psi)
    out[2] = r
    out[3] = (kv * u[0] - uu) / tv
    out[4] = (kr * u[1] - r) / tr


def first_order_model(cfg: FirstOrderConfig | None = None, params=None) -> Model:
    """The first-order USV of 000 (eq. 8, 15, 1) as a :class:`~oceangnc.core.model.Model`."""
    p = (cfg or FirstOrderConfig()).params() if params is None else np.asarray(params, dtype=np.float64)
    return Model(
        "first-order",
        first_order_rhs,
        STATES,
        INPUTS,
        LAYOUT,
        p,
        bound=1e7,
        description="000 first-order speed/yaw-rate USV (Nomoto), states x, y, psi, u, r",
    )


class FirstOrderUSV(Plant):
    """The first-order USV as a plant; publishes ``usv.<x,y,psi,u,r>``, ``usv.speed``, ``usv.schedule_clamped``.

    ``usv.psi`` is wrapped to (-pi, pi]. A ``RuntimeWarning`` is issued once per plant the first time
    the speed leaves a trial range (the coefficients are then held at the range's end).
    """

    def __init__(self, cfg: FirstOrderConfig, name: str = "usv"):
        x0 = np.array([cfg.x0, cfg.y0, math.radians(cfg.psi0_deg), cfg.u0, math.radians(cfg.r0_degps)])
        inputs = [k.replace("usv.", f"{name}.") for k in INPUT_NAMES]
        super().__init__(
            **first_order_model(cfg).plant_args(name, x0, inputs, declare=True),
            max_dt=cfg.max_dt(),
            input_defaults={f"{name}.u_op": 0.0},
            extra_outputs={f"{name}.speed": "m/s", f"{name}.schedule_clamped": "bool"},
        )
        self.cfg = cfg
        self._warned = False

        n = self.name
        self._out_keys = [f"{n}.{k}" for k in ("x", "y", "psi", "u", "r", "speed", "schedule_clamped")]
        oper = 1.0 if cfg.schedule == "operating" else 0.0
        #: the schedule's ranges (m/s), operating-point flag, then set by the law: left a range, speed then
        self._cp = np.array(
            [cfg.straight_lo_mps, cfg.straight_hi_mps, cfg.turn_lo_mps, cfg.turn_hi_mps, oper, 0.0, 0.0]
        )
        self._sig = np.zeros(8)
        self._sl = np.arange(8, dtype=np.int64)

    def compiled_form(self, slot_of):
        """The fused loop's form: the RK4 stepper, then :func:`first_order_publish` (as :meth:`publish`)."""
        uop = f"{self.name}.u_op"
        form = advance_and_publish(self, slot_of, rk4_stepper_imports(self.rhs), self._out_keys, first_order_publish)
        form.args["oslots"] = np.append(form.args["oslots"], slot_of(uop) if uop in plant_bus_keys(slot_of) else -1)
        form.args["cp"] = self._cp
        form.code[-1] = "_pub_{adv}({x}, sig, {oslots}, {cp})"
        return form

    def publish(self, bus: dict) -> None:
        """The outputs of :func:`first_order_publish` (the fused loop's), and the range warning."""
        uop = bus.get(f"{self.name}.u_op")
        self._sl[7] = -1 if uop is None else 7
        self._sig[7] = 0.0 if uop is None else uop
        first_order_publish(self.x, self._sig, self._sl, self._cp)
        bus.update(zip(self._out_keys, self._sig[:7].tolist()))
        self.after_fused(bus)

    def _warn(self, u: float) -> None:
        """Warn once per plant that the speed ``u`` (m/s) left the trial ranges."""
        if self._warned:
            return
        self._warned = True
        c = self.cfg
        warnings.warn(
            f"{VEHICLE}: speed {u:.2f} m/s is outside the trial ranges of 000 table 2 "
            f"(straight {c.straight_lo_mps:g}-{c.straight_hi_mps:g} m/s, turning {c.turn_lo_mps:g}-"
            f"{c.turn_hi_mps:g} m/s); coefficients are held at the range ends",
            RuntimeWarning,
            stacklevel=3,
        )

    def after_fused(self, bus: dict) -> None:  # also after each Python publish
        """After a fused call: the warning :meth:`publish` gives, if the speed left the ranges in it."""
        if self._cp[5] != 0.0:
            self._warn(float(self._cp[6]))


@njit(cache=True)
def first_order_publish(x, sig, slots, cp):
    """The first-order USV's outputs (:class:`FirstOrderUSV`, both paths).

    slots: x, y, psi, u, r, speed, schedule_clamped, u_op (-1: absent). cp: straight lo/hi, turn
    lo/hi (m/s), operating schedule (1/0), then set here: left a range (1/0), the speed then (m/s),
    for the plant's warning (:meth:`~oceangnc.models.first_order.FirstOrderUSV.after_fused`).
    """
    for i in range(5):
        sig[slots[i]] = x[i]
    sig[slots[2]] = (x[2] + math.pi) % (2 * math.pi) - math.pi
    sig[slots[5]] = abs(x[3])
    u = x[3]
    if cp[4] != 0.0 and slots[7] >= 0:
        u = sig[slots[7]]
    out = not (cp[0] <= u <= cp[1] and cp[2] <= u <= cp[3])
    sig[slots[6]] = 1.0 if out else 0.0
    if out and cp[5] == 0.0:
        cp[5] = 1.0
        cp[6] = u


ACTUATOR_SIGNALS = Signals(
    delta_cmd=In("rad"), rpm_cmd=In("rpm"), estop=Opt("bool"), delta=Out("rad"), rpm=Out("rpm"), delta_deg=Out("deg")
)
ACTUATOR_PARAMS = Layout("dmax", "nmin", "nmax", "ramp_s", "period")
ACTUATOR_STATE = Layout("w")
_SA, _PA, _XA = ACTUATOR_SIGNALS.at, ACTUATOR_PARAMS.at, ACTUATOR_STATE.at


@njit(cache=True)
def rudder_engine_law(t, sig, sl, st, pa):
    """Rudder (rad) limited to +-dmax, engine (rpm) limited to [nmin, nmax]; both zero on ``_estop``,
    after which the engine ramps back, n = w sat(n_cmd) with w rising 0 -> 1 over ``ramp_s`` (no
    thrust step at Reset; the rudder, no thrust, follows its command at once)."""
    stop = sl[_SA.estop] >= 0 and sig[sl[_SA.estop]] != 0.0
    st[_XA.w] = resume_weight(st[_XA.w], stop, pa[_PA.period], pa[_PA.ramp_s])
    d = 0.0 if stop else sig[sl[_SA.delta_cmd]]
    n = 0.0 if stop else sig[sl[_SA.rpm_cmd]]
    d = min(pa[_PA.dmax], max(-pa[_PA.dmax], d))
    n = min(pa[_PA.nmax], max(pa[_PA.nmin], n))
    sig[sl[_SA.delta]] = d
    sig[sl[_SA.rpm]] = n if st[_XA.w] >= 1.0 else st[_XA.w] * n
    sig[sl[_SA.delta_deg]] = math.degrees(d)


class FirstOrderActuators(LawBlock):
    """Rudder and engine: commands -> saturated inputs of the first-order USV (:func:`rudder_engine_law`).

    Reads ``usv.delta_s_cmd`` (rad) and ``usv.rpm_cmd`` (rev/min); writes ``usv.delta_s`` limited to
    +-``rudder_limit_deg`` and ``usv.rpm`` limited to [rpm_min, rpm_max]; also ``usv.delta_s_deg``
    for plots. An emergency stop (``_estop``) zeroes both; the engine ramps back over 2 s after it.
    """

    name = "usv_actuators"
    law = staticmethod(rudder_engine_law)
    signals = ACTUATOR_SIGNALS

    def __init__(self, cfg: FirstOrderConfig, period: float = 0.05, body: str = "usv", ramp_s: float = RESUME_RAMP_S):
        self.period = float(period)
        self.body = body
        self.dmax = math.radians(cfg.rudder_limit_deg)
        self.nmin = cfg.rpm_min
        self.nmax = cfg.rpm_max
        b = body
        self.bind(
            delta_cmd=f"{b}.delta_s_cmd",
            rpm_cmd=f"{b}.rpm_cmd",
            estop="_estop",
            delta=f"{b}.delta_s",
            rpm=f"{b}.rpm",
            delta_deg=f"{b}.delta_s_deg",
        )
        self.pa = ACTUATOR_PARAMS.pack(
            dmax=self.dmax, nmin=self.nmin, nmax=self.nmax, ramp_s=ramp_s, period=self.period
        )
        self.st = ACTUATOR_STATE.pack(w=1.0)
