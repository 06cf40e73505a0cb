"""Anti-windup PID with back-calculation (003 eq. 3.10).

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

The gains are plain attributes so that an operator console can change them while running.

Hold and bumpless resume. ``hold(True)`` freezes the integrator (an emergency stop holds the
actuators at zero: integrating the error then would wind the integrator up, and the release would
jump to full thrust). ``hold(False, ramp_s)`` resumes: for ``ramp_s`` seconds of controller steps
the output is blended from the output held during the stop (0) to the live PID output,
``u = u_hold + w (sat(v) - u_hold)``, ``w = elapsed / ramp_s``; the back-calculation sees this
ramped ``u`` as its limit, so the integrator does not wind up during the ramp either.
"""

from __future__ import annotations

import math

from numba import njit


@njit(cache=True)
def pid_output(kp, kd, integral, e, e_dot, ff):
    """v = K_p e + I + K_d e_dot + feed-forward: the unsaturated output (the one home of eq. 3.10's sum;
    :meth:`PID.step` and the compiled :func:`oceangnc.control._compiled.pid_step` call it)."""
    return kp * e + integral + kd * e_dot + ff


@njit(cache=True)
def pid_integral(integral, dt, ki, kw, e, u, v):
    """The integrator after one forward-Euler step of I' = K_i (e + K_w (u - v)) (back-calculation)."""
    return integral + dt * ki * (e + kw * (u - v))


class PID:
    """Discrete anti-windup PID.

    Parameters
    ----------
    kp, ki, kd : float
        Gains (output units per error unit, per error unit and second, per error unit per second).
    u_min, u_max : float
        Output limits (output units); -inf/inf for none.
    kw : float or None
        Back-calculation gain inside the integral (dimensionless ratio error/output); default
        ``1 / kp`` (003 eq. 3.10), or ``1`` when ``kp == 0``.
    """

    def __init__(
        self,
        kp: float,
        ki: float = 0.0,
        kd: float = 0.0,
        u_min: float = -math.inf,
        u_max: float = math.inf,
        kw: float | None = None,
    ):
        if u_min > u_max:
            raise ValueError(f"PID limits: u_min={u_min} > u_max={u_max}")
        self.kp = float(kp)
        self.ki = float(ki)
        self.kd = float(kd)
        self.u_min = float(u_min)
        self.u_max = float(u_max)
        self._kw = kw
        self.reset()

    @property
    def kw(self) -> float:
        if self._kw is not None:
            return float(self._kw)
        return 1.0 / self.kp if self.kp != 0.0 else 1.0

    def reset(self, integral: float = 0.0) -> None:
        """Clear the integrator (or set it) and the derivative memory."""
        self.integral = float(integral)
        self._e_prev: float | None = None
        self.v = 0.0  # last unsaturated output
        self.u = 0.0  # last saturated output
        self.held = False
        self._u_hold = 0.0
        self._ramp_left = 0.0
        self._ramp_s = 0.0

    def hold(self, on: bool, ramp_s: float = 2.0, u_hold: float = 0.0) -> None:
        """Freeze (``on``) or release the integrator; a release ramps the output from ``u_hold`` over
        ``ramp_s`` seconds (bumpless resume after an emergency stop)."""
        if on and not self.held:
            self.held = True
            self._u_hold = float(u_hold)
            self._ramp_left = 0.0
        elif not on and self.held:
            self.held = False
            self._ramp_s = max(0.0, float(ramp_s))
            self._ramp_left = self._ramp_s

    def step(self, e: float, dt: float, e_dot: float | None = None, feedforward: float = 0.0) -> float:
        """One controller update with error ``e`` over period ``dt`` (s); returns the saturated output.

        ``e_dot`` is the error rate if known (else a backward difference); ``feedforward`` is added
        before saturation.
        """
        if e_dot is None:
            e_dot = 0.0 if self._e_prev is None else (e - self._e_prev) / dt
        self._e_prev = e
        v = float(pid_output(self.kp, self.kd, self.integral, e, e_dot, feedforward))
        u = min(self.u_max, max(self.u_min, v))
        if self.held:  # stopped: the integrator keeps its value, the output is what the stop holds
            self.v = v
            self.u = self._u_hold
            return self._u_hold
        if self._ramp_left > 0.0:
            w = 1.0 - self._ramp_left / self._ramp_s
            u = self._u_hold + w * (u - self._u_hold)
            self._ramp_left = max(0.0, self._ramp_left - dt)
        self.integral = float(pid_integral(self.integral, dt, self.ki, self.kw, e, u, v))
        self.v = v
        self.u = u
        return u
