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

Gains are recomputed at each controller step from the speed-scheduled coefficients of 000 table 2
(:func:`oceangnc.models.first_order.schedule`, evaluated inside the law; a fixed identified model is a
schedule with zero slopes). A design with ``2 zeta w_n T <= 1`` is refused when the scenario is built;
the law writes NaN if one is met while running, which the loop reports as a divergence.
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit

from ..core.law import In, LawBlock, Layout, Out, Signals
from ..core.registry import register_block
from ..core.rotations import wrap
from ..errors import ConfigError
from ..models.first_order import FirstOrderSchedule, schedule


@njit(cache=True)
def pole_placed_k1(K, T, zeta, wn):
    """K1 = (2 zeta w_n T - 1) / K (000 eq. 26 and 31); NaN when 2 zeta w_n T <= 1 or K = 0."""
    a = 2.0 * zeta * wn * T
    if a <= 1.0 or K == 0.0:
        return math.nan
    return (a - 1.0) / K


@njit(cache=True)
def heading_pd_control(K, T, zeta, wn, psi_cmd, psi, r):
    """(delta_S_cmd rad, K1, K2) of the heading PD ``K1 (K2 wrap(psi_c - psi) - r)`` (000 eq. 22, 26, 27)."""
    a = 2.0 * zeta * wn * T
    k1 = pole_placed_k1(K, T, zeta, wn)
    k2 = wn * wn * T / (a - 1.0)
    e = wrap(psi_cmd - psi)
    return k1 * (k2 * e - r), k1, k2


@njit(cache=True)
def speed_p_control(K, T, zeta, wn, vc, v):
    """(delta_T_cmd, K1) of the speed P controller ``K1 (v_c - v)`` (000 eq. 28, 31)."""
    k1 = pole_placed_k1(K, T, zeta, wn)
    return k1 * (vc - v), k1


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
    _check(K, T, zeta, wn, "heading autopilot")
    _, k1, k2 = heading_pd_control(K, T, zeta, wn, 0.0, 0.0, 0.0)
    return float(k1), float(k2)


def speed_gain(K: float, T: float, zeta: float, wn: float) -> float:
    """K1 of the speed P controller (000 eq. 31), in input units (e.g. rpm) per m/s."""
    _check(K, T, zeta, wn, "speed autopilot")
    return float(pole_placed_k1(K, T, zeta, wn))


def predicted_overshoot(zeta: float) -> float:
    """Step overshoot (fraction) of the second-order closed loop (25) with damping ``zeta`` < 1."""
    if zeta >= 1.0:
        return 0.0
    return math.exp(-math.pi * zeta / math.sqrt(1.0 - zeta * zeta))


#: the autopilots' parameters: the poles, then the schedule's parameters (000 table 2) from _SCHED on
AUTOPILOT_HEAD = Layout("zeta", "wn")
_ZETA, _WN, _SCHED = AUTOPILOT_HEAD.at.zeta, AUTOPILOT_HEAD.at.wn, AUTOPILOT_HEAD.size
HDG_SIGNALS = Signals(psi_cmd=In("rad"), psi=In("rad"), r=In("rad/s"), u=In("m/s"),
                      delta=Out("rad"), k1=Out("1"), k2=Out("1/s"))  # fmt: skip
SPD_SIGNALS = Signals(u_cmd=In("m/s"), u=In("m/s"), rpm=Out("rpm"), k1=Out("1"))
_HS, _SS = HDG_SIGNALS.at, SPD_SIGNALS.at


@njit(cache=True)
def heading_pd_law(t, sig, sl, st, pa):
    """Heading PD (000 eq. 22) with gains (26, 27) on the Nomoto (K_r, T_r) scheduled at the speed u:
    writes delta_S_cmd (rad), K1 and K2."""
    kv, tv, kr, tr = schedule(sig[sl[_HS.u]], pa[_SCHED:])
    d, k1, k2 = heading_pd_control(kr, tr, pa[_ZETA], pa[_WN], sig[sl[_HS.psi_cmd]], sig[sl[_HS.psi]], sig[sl[_HS.r]])
    sig[sl[_HS.delta]] = d
    sig[sl[_HS.k1]] = k1
    sig[sl[_HS.k2]] = k2


@njit(cache=True)
def speed_p_law(t, sig, sl, st, pa):
    """Speed P controller (000 eq. 28) with gain (31) on (K_v, T_v) scheduled at the commanded speed:
    writes the engine command (rpm) and K1."""
    vc = sig[sl[_SS.u_cmd]]
    kv, tv, kr, tr = schedule(vc, pa[_SCHED:])
    n, k1 = speed_p_control(kv, tv, pa[_ZETA], pa[_WN], vc, sig[sl[_SS.u]])
    sig[sl[_SS.rpm]] = n
    sig[sl[_SS.k1]] = k1


def _design(block, coefficients: FirstOrderSchedule, zeta: float, wn: float, period: float, body: str) -> None:
    """The design data both autopilots keep: the coefficient schedule, the poles (zeta, w_n), rate, body,
    and the law's parameters (zeta, w_n, the schedule's parameters)."""
    if getattr(coefficients, "schedule_params", None) is None:
        raise ConfigError(f"{type(block).__name__}: coefficients must be a first-order schedule (FirstOrderSchedule)")
    block.coefficients = coefficients
    block.zeta = float(zeta)
    block.wn = float(wn)
    block.period = float(period)
    block.body = body
    sched = np.asarray(coefficients.schedule_params, dtype=np.float64)
    block.pa = np.concatenate([AUTOPILOT_HEAD.pack(zeta=block.zeta, wn=block.wn), sched])
    block.st = np.zeros(1)


@register_block("usv.heading_pd")
class HeadingAutopilot(LawBlock):
    """Heading PD (000 eq. 22) with pole-placed gains (26, 27); law :func:`heading_pd_law`.

    Reads ``<b>.psi_cmd``, ``<b>.psi`` (rad) and ``<b>.r`` (rad/s) and ``<b>.u`` (m/s, for the
    schedule); writes ``<b>.delta_s_cmd`` (rad) and the gains ``<b>.hdg_k1``, ``<b>.hdg_k2``. The
    heading error is wrapped to (-pi, pi] so that a command across north turns the short way.

    ``coefficients`` is the Nomoto schedule (:class:`~oceangnc.models.first_order.FirstOrderSchedule`).
    """

    role = "controller"
    name = "heading_autopilot"
    law = staticmethod(heading_pd_law)
    signals = HDG_SIGNALS

    def __init__(self, coefficients, zeta: float, wn: float, period: float = 0.05, body: str = "usv"):
        _design(self, coefficients, zeta, wn, period, body)
        b = body
        self.bind(psi_cmd=f"{b}.psi_cmd", psi=f"{b}.psi", r=f"{b}.r", u=f"{b}.u",
                  delta=f"{b}.delta_s_cmd", k1=f"{b}.hdg_k1", k2=f"{b}.hdg_k2")  # fmt: skip

    def gains(self, u: float) -> tuple[float, float]:
        """(K1, K2) at speed u (m/s), 000 eq. 26-27; ConfigError for a design the schedule cannot meet."""
        K, T = self.coefficients(u)
        return heading_gains(K, T, self.zeta, self.wn)


@register_block("usv.speed_p")
class SpeedAutopilot(LawBlock):
    """Speed P controller (000 eq. 28) with the pole-placed gain (31), designed at the commanded speed;
    law :func:`speed_p_law`.

    Reads ``<b>.u_cmd`` and ``<b>.u`` (m/s); writes ``<b>.rpm_cmd`` (rpm for the first-order USV) and
    ``<b>.spd_k1``. ``coefficients`` is the speed schedule (K_v, T_v).
    """

    role = "controller"
    name = "speed_autopilot"
    law = staticmethod(speed_p_law)
    signals = SPD_SIGNALS

    def __init__(self, coefficients, zeta: float, wn: float, period: float = 0.05, body: str = "usv"):
        _design(self, coefficients, zeta, wn, period, body)
        b = body
        self.bind(u_cmd=f"{b}.u_cmd", u=f"{b}.u", rpm=f"{b}.rpm_cmd", k1=f"{b}.spd_k1")
