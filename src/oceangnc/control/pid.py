"""Anti-windup PID with back-calculation (003 eq. 3.10): one compiled law, :func:`pid_step`.

003 eq. 3.10: ``U = K_p e + K_I int(e + K_w (sat(U) - U)) dt + K_D e_dot``, i.e.

    v(t)  = K_p e + I + K_d e_dot
    u(t)  = sat(v) in [u_min, u_max]
    I'    = K_i (e + K_w (u - v))        (back-calculation, K_w = 1 / K_p by default)

When the output saturates, the integrator is driven back at rate K_i K_w = K_i / K_p = 1 / T_i, so
it does not wind up: the tracking time constant equals the integral time, a standard choice
(Astrom & Hagglund 2006, sec. 3.5).
The integrator is advanced with the forward-Euler rule at the controller's own period, as on a
microcontroller. The derivative uses the given rate (e.g. the measured yaw rate, avoiding
derivative kick) or a backward difference of the error.

A PID is two slices of its block's flat arrays (:mod:`oceangnc.core.law`): its state
:data:`PID_STATE` (integral, last error, ...) in the block's ``st`` and its gains :data:`PID_PARAMS` in
the block's ``pa``. A controller's law calls :func:`pid_step` on its PIDs' offsets; the class
:class:`PID` is a Python view of the same two slices (for a plain-Python controller, a test, or an
operator reading and changing gains) whose :meth:`PID.step` calls the same compiled function.

Emergency stop. A controller whose law reads ``_estop`` does not step its PIDs while it is set (the
outputs are zero, the integrators keep their values, nothing winds up); when it clears, it scales
its PIDs' outputs by the resume weight w (0 -> 1 over 2 s, :mod:`oceangnc.core.estop`), as the
thrusters do, and the back-calculation sees the scaled output, so the integrators do not wind up
during the ramp either (no overshoot after Reset).
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit

from ..core.law import Layout

#: a PID's state in its block's state array: integral I, last error, 1 once there is one, last
#: unsaturated output v, last saturated output u
PID_STATE = Layout("integral", "e_prev", "has_e_prev", "v", "u")
#: a PID's parameters in its block's parameter array: gains, output limits, back-calculation gain
PID_PARAMS = Layout("kp", "ki", "kd", "u_min", "u_max", "kw")
_X, _P = PID_STATE.at, PID_PARAMS.at
_N_STATE = PID_STATE.size


@njit(cache=True, inline="always")
def pid_output(kp, kd, integral, e, e_dot, ff):
    """v = K_p e + I + K_d e_dot + feed-forward: the unsaturated output of eq. 3.10."""
    return kp * e + integral + kd * e_dot + ff


@njit(cache=True, inline="always")
def pid_integral(integral, dt, ki, kw, e, u, v):
    """The integrator after one forward-Euler step of I' = K_i (e + K_w (u - v)) (back-calculation)."""
    return integral + dt * ki * (e + kw * (u - v))


@njit(cache=True)
def pid_step_w(st, o, pa, q, e, dt, e_dot, has_e_dot, ff, u_min, u_max, w):
    """One update of the PID whose state is ``st[o:o+5]`` (:data:`PID_STATE`) and gains ``pa[q:q+6]``
    (:data:`PID_PARAMS`), error ``e`` over the period ``dt`` (s), error rate ``e_dot`` when
    ``has_e_dot`` (else a backward difference), feed-forward ``ff`` added before the saturation to
    [``u_min``, ``u_max``] (a controller may narrow its PID's limits each step), and the output scaled
    by the e-stop resume weight ``w`` (:func:`oceangnc.core.estop.resume_weight`; 1 without a stop),
    which the back-calculation sees. Returns u (eq. 3.10)."""
    if not has_e_dot:
        e_dot = 0.0 if st[o + _X.has_e_prev] == 0.0 else (e - st[o + _X.e_prev]) / dt
    st[o + _X.e_prev] = e
    st[o + _X.has_e_prev] = 1.0
    v = pid_output(pa[q + _P.kp], pa[q + _P.kd], st[o + _X.integral], e, e_dot, ff)
    u = w * min(u_max, max(u_min, v))
    st[o + _X.integral] = pid_integral(st[o + _X.integral], dt, pa[q + _P.ki], pa[q + _P.kw], e, u, v)
    st[o + _X.v] = v
    st[o + _X.u] = u
    return u


@njit(cache=True)
def pid_step(st, o, pa, q, e, dt, e_dot, has_e_dot, ff, u_min, u_max):
    """:func:`pid_step_w` without a resume ramp (w = 1)."""
    return pid_step_w(st, o, pa, q, e, dt, e_dot, has_e_dot, ff, u_min, u_max, 1.0)


@njit(cache=True, inline="always")
def pid_run(st, o, pa, q, e, dt, e_dot, has_e_dot, ff, w):
    """:func:`pid_step_w` within the PID's own output limits (``u_min``, ``u_max`` of its gains)."""
    return pid_step_w(st, o, pa, q, e, dt, e_dot, has_e_dot, ff, pa[q + _P.u_min], pa[q + _P.u_max], w)


@njit(cache=True)
def pid_clear(st, o):
    """Clear a PID's state (integral, derivative memory, outputs)."""
    for i in range(_N_STATE):
        st[o + i] = 0.0


def default_kw(kp: float) -> float:
    """The back-calculation gain of eq. 3.10, K_w = 1 / K_p (1 when K_p = 0)."""
    return 1.0 / kp if kp != 0.0 else 1.0


def pid_params(kp: float, ki: float = 0.0, kd: float = 0.0, u_min: float = -math.inf, u_max: float = math.inf, kw=None):
    """A PID's :data:`PID_PARAMS` entries as a dict (``kw`` None: :func:`default_kw`); refuses u_min > u_max."""
    if u_min > u_max:
        raise ValueError(f"PID limits: u_min={u_min} > u_max={u_max}")
    kp = float(kp)
    return {
        "kp": kp,
        "ki": float(ki),
        "kd": float(kd),
        "u_min": float(u_min),
        "u_max": float(u_max),
        "kw": default_kw(kp) if kw is None else float(kw),
    }


class PID:
    """A PID as a Python object: a view of its state and gains (own arrays, or slices of a block's).

    Parameters
    ----------
    kp, ki, kd : float
        Gains (output units per error unit, per error unit and second, per error unit per second).
    u_min, u_max : float
        Output limits (output units); -inf/inf for none.
    kw : float or None
        Back-calculation gain inside the integral (dimensionless ratio error/output); default
        ``1 / kp`` (003 eq. 3.10), or ``1`` when ``kp == 0``; it follows ``kp`` when ``kp`` is changed.
    st, pa : arrays, optional
        Views of a block's arrays to use instead of own ones (:meth:`view`).
    """

    def __init__(self, kp=0.0, ki=0.0, kd=0.0, u_min=-math.inf, u_max=math.inf, kw=None, *, st=None, pa=None):
        self.pa = pa if pa is not None else PID_PARAMS.pack(pid_params(kp, ki, kd, u_min, u_max, kw))
        self.st = st if st is not None else PID_STATE.pack(dict.fromkeys(PID_STATE.names, 0.0))
        self._kw_default = kw is None and pa is None

    @classmethod
    def view(cls, st: np.ndarray, o: int, pa: np.ndarray, q: int) -> PID:
        """The PID whose state is ``st[o:o+5]`` and gains ``pa[q:q+6]`` (writes go to those arrays)."""
        p = cls(st=st[o : o + PID_STATE.size], pa=pa[q : q + PID_PARAMS.size])
        p._kw_default = p.pa[_P.kw] == default_kw(float(p.pa[_P.kp]))
        return p

    def _get(name, arr, i, doc):  # noqa: N805 (a property factory)
        def fget(self):
            return float(getattr(self, arr)[i])

        def fset(self, value):
            getattr(self, arr)[i] = float(value)

        return property(fget, fset, doc=doc)

    ki = _get("ki", "pa", _P.ki, "integral gain")
    kd = _get("kd", "pa", _P.kd, "derivative gain")
    u_min = _get("u_min", "pa", _P.u_min, "lower output limit")
    u_max = _get("u_max", "pa", _P.u_max, "upper output limit")
    kw = _get("kw", "pa", _P.kw, "back-calculation gain")
    integral = _get("integral", "st", _X.integral, "integrator state I")
    v = _get("v", "st", _X.v, "last unsaturated output")
    u = _get("u", "st", _X.u, "last saturated output")
    del _get

    @property
    def kp(self) -> float:
        """Proportional gain; setting it moves a default back-calculation gain K_w = 1/K_p with it."""
        return float(self.pa[_P.kp])

    @kp.setter
    def kp(self, value: float) -> None:
        self.pa[_P.kp] = float(value)
        if self._kw_default:
            self.pa[_P.kw] = default_kw(float(value))

    def reset(self, integral: float = 0.0) -> None:
        """Clear the derivative memory and the outputs; set the integrator (0 by default)."""
        pid_clear(self.st, 0)
        self.st[_X.integral] = float(integral)

    def step(self, e: float, dt: float, e_dot: float | None = None, feedforward: float = 0.0) -> float:
        """One update (:func:`pid_step`) with error ``e`` over period ``dt`` (s); returns the saturated
        output. ``e_dot`` is the error rate if known (else a backward difference); ``feedforward`` is
        added before saturation."""
        has = e_dot is not None
        return float(
            pid_step(
                self.st, 0, self.pa, 0, float(e), float(dt), float(e_dot) if has else 0.0, has,
                float(feedforward), self.pa[_P.u_min], self.pa[_P.u_max],
            )
        )  # fmt: skip
