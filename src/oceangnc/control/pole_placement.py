"""Pole-placed heading PD and speed P autopilots for first-order models (document 000 eq. 22-31).

Heading (000 eq. 22-27). The two-loop PD ``delta_S = K1 (K2 (psi_c - psi) - psi')`` (22) on the
Nomoto model ``T psi'' + psi' = K delta_S`` (8, 23) closes to
``T psi'' + (1 + K K1) psi' + K K1 K2 psi = K K1 K2 psi_c`` (24); matching it to
``psi'' + 2 zeta w_n psi' + w_n^2 psi = w_n^2 psi_c`` (25) gives

    K1 = (2 zeta w_n T - 1) / K          (26)
    K2 = w_n^2 T / (2 zeta w_n T - 1)    (27)

which needs ``2 zeta w_n T > 1`` (else K1 <= 0 and the loop would need positive feedback of the
rate). The closed loop is an exact second-order system with no zero, so a small step overshoots by
``exp(-pi zeta / sqrt(1 - zeta^2))``.

Speed (000 eq. 28-31). ``delta_T = K1 (v_c - v)`` (28) on ``T v' + v = K delta_T`` (15, 29; the
printed (29) has ``+1`` for ``+v``) gives ``v' + (1 + K K1)/T v = K K1/T v_c`` (30); placing the
pole at ``2 zeta w_n`` as the paper does gives ``K1 = (2 zeta w_n T - 1) / K`` (31). The loop is
first order with time constant ``1 / (2 zeta w_n)`` and, being proportional only, keeps a steady
error ``v_c / (2 zeta w_n T)``.

Gains are recomputed at each controller step from a ``coefficients(u) -> (K, T)`` callable, so the
same blocks serve a fixed identified model or the speed-scheduled model of 000 table 2.
"""

from __future__ import annotations

import math
from collections.abc import Callable

from ..core.blocks import Block
from ..core.registry import register_block
from ..errors import ConfigError


def _check(K: float, T: float, zeta: float, wn: float, what: str) -> float:
    if not (zeta > 0 and wn > 0):
        raise ConfigError(f"{what}: zeta and w_n must be > 0, got zeta={zeta}, w_n={wn}")
    if K == 0 or not math.isfinite(K) or not (T > 0):
        raise ConfigError(f"{what}: need a finite non-zero gain K and T > 0, got K={K}, T={T}")
    a = 2.0 * zeta * wn * T
    if a <= 1.0:
        raise ConfigError(
            f"{what}: 2 zeta w_n T = {a:.3f} <= 1 (zeta={zeta}, w_n={wn} rad/s, T={T:.4g} s): "
            f"the gains (000 eq. 26/31) would be <= 0; raise w_n above {1.0 / (2 * zeta * T):.3f} rad/s"
        )
    return a


def heading_gains(K: float, T: float, zeta: float, wn: float) -> tuple[float, float]:
    """(K1, K2) of the heading PD (000 eq. 26, 27): K1 in rad of rudder per rad/s, K2 in 1/s."""
    a = _check(K, T, zeta, wn, "heading autopilot")
    return (a - 1.0) / K, wn * wn * T / (a - 1.0)


def speed_gain(K: float, T: float, zeta: float, wn: float) -> float:
    """K1 of the speed P controller (000 eq. 31), in input units (e.g. rpm) per m/s."""
    a = _check(K, T, zeta, wn, "speed autopilot")
    return (a - 1.0) / K


def predicted_overshoot(zeta: float) -> float:
    """Step overshoot (fraction) of the second-order closed loop (25) with damping ``zeta`` < 1."""
    if zeta >= 1.0:
        return 0.0
    return math.exp(-math.pi * zeta / math.sqrt(1.0 - zeta * zeta))


def _design(block, coefficients, zeta: float, wn: float, period: float, body: str) -> None:
    """The design data both autopilots keep: the coefficient schedule, the poles (zeta, w_n), rate, body."""
    block.coefficients = coefficients
    block.zeta = float(zeta)
    block.wn = float(wn)
    block.period = float(period)
    block.body = body


@register_block("usv.heading_pd")
class HeadingAutopilot(Block):
    """Heading PD (000 eq. 22) with pole-placed gains (26, 27).

    Reads ``<b>.psi_cmd``, ``<b>.psi`` (rad) and ``<b>.r`` (rad/s) and ``<b>.u`` (m/s, for the
    schedule); writes ``<b>.delta_s_cmd`` (rad) and the gains ``<b>.hdg_k1``, ``<b>.hdg_k2``. The
    heading error is wrapped to (-pi, pi] so that a command across north turns the short way.

    ``coefficients(u)`` returns the Nomoto (K_r [1/s], T_r [s]) at speed u.
    """

    role = "controller"

    name = "heading_autopilot"
    coefficients: Callable[[float], tuple[float, float]]
    zeta: float
    wn: float
    body: str

    def __init__(self, coefficients, zeta: float, wn: float, period: float = 0.05, body: str = "usv"):
        _design(self, coefficients, zeta, wn, period, body)
        self.inputs = {f"{body}.psi_cmd": "rad", f"{body}.psi": "rad", f"{body}.r": "rad/s", f"{body}.u": "m/s"}
        self.outputs = {f"{body}.delta_s_cmd": "rad", f"{body}.hdg_k1": "1", f"{body}.hdg_k2": "1/s"}

    def gains(self, u: float) -> tuple[float, float]:
        K, T = self.coefficients(u)
        return heading_gains(K, T, self.zeta, self.wn)

    def step(self, t: float, bus: dict) -> None:
        from ._compiled_first_order import heading_pd_law

        b = self.body
        K, T = self.coefficients(bus[f"{b}.u"])
        _check(K, T, self.zeta, self.wn, "heading autopilot")
        d, k1, k2 = heading_pd_law(K, T, self.zeta, self.wn, bus[f"{b}.psi_cmd"], bus[f"{b}.psi"], bus[f"{b}.r"])
        bus[f"{b}.delta_s_cmd"] = d
        bus[f"{b}.hdg_k1"] = k1
        bus[f"{b}.hdg_k2"] = k2

    def compiled(self):
        """Compiled form (:func:`oceangnc.control._compiled_first_order.heading_pd_step`) when the
        coefficients are the first-order schedule (:class:`~oceangnc.models.first_order.FirstOrderSchedule`)."""
        return _scheduled_form(self, "nomoto", ["psi_cmd", "psi", "r", "u", "delta_s_cmd", "hdg_k1", "hdg_k2"])


@register_block("usv.speed_p")
class SpeedAutopilot(Block):
    """Speed P controller (000 eq. 28) with the pole-placed gain (31), designed at the commanded speed.

    Reads ``<b>.u_cmd`` and ``<b>.u`` (m/s); writes ``<b>.rpm_cmd`` (input units, rpm for the
    first-order USV) and ``<b>.spd_k1``. ``coefficients(u)`` returns (K_v, T_v) at speed u.
    """

    role = "controller"

    name = "speed_autopilot"
    coefficients: Callable[[float], tuple[float, float]]
    zeta: float
    wn: float
    body: str

    def __init__(self, coefficients, zeta: float, wn: float, period: float = 0.05, body: str = "usv"):
        _design(self, coefficients, zeta, wn, period, body)
        self.inputs = {f"{body}.u_cmd": "m/s", f"{body}.u": "m/s"}
        self.outputs = {f"{body}.rpm_cmd": "rpm", f"{body}.spd_k1": "1"}

    def step(self, t: float, bus: dict) -> None:
        from ._compiled_first_order import speed_p_law

        b = self.body
        vc = bus[f"{b}.u_cmd"]
        K, T = self.coefficients(vc)
        _check(K, T, self.zeta, self.wn, "speed autopilot")
        n, k1 = speed_p_law(K, T, self.zeta, self.wn, vc, bus[f"{b}.u"])
        bus[f"{b}.rpm_cmd"] = n
        bus[f"{b}.spd_k1"] = k1

    def compiled(self):
        """Compiled form (:func:`oceangnc.control._compiled_first_order.speed_p_step`) on the first-order schedule."""
        return _scheduled_form(self, "speed", ["u_cmd", "u", "rpm_cmd", "spd_k1"])


def _scheduled_form(block, law: str, signals: list[str]):
    """The compiled form of an autopilot whose coefficients are the first-order schedule ``law``, else None."""
    import numpy as np

    from ..core.fused import CompiledBlock
    from . import _compiled_first_order as kern

    sched = block.coefficients
    if getattr(sched, "law", None) != law or getattr(sched, "schedule_params", None) is None:
        return None  # an arbitrary coefficients callable: the Python path
    kernel = kern.heading_pd_step if law == "nomoto" else kern.speed_p_step
    params = np.concatenate([[block.zeta, block.wn], np.asarray(sched.schedule_params, dtype=np.float64)])
    return CompiledBlock(kernel, [f"{block.body}.{k}" for k in signals], params=params)
