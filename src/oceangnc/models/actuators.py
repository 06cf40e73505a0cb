"""Thruster curves and actuator limits.

USV thrusters (003 eq. 2.5, Minn Kota, 36.2 kgf rated): the printed 5th-order thrust-voltage
polynomial over the 12-bit DAC range 0.05-4.68 V,

    P(V) [kgf] = -0.4968 V^5 + 5.7702 V^4 - 21.755 V^3 + 29.0135 V^2 - 3.3987 V - 13.081,

does not reproduce the text's own claims (it gives -13.18 / 29.22 kgf at the ends and -0.75..-3.3 kgf
inside the 1.6-3.2 V dead zone). We impose them separately (SPEC.md, 003 notes): zero thrust on
[1.6, 3.2] V, and on each branch the polynomial rescaled affinely so that it is 0 at the dead-zone
edge and takes the printed end value (-13.83 kgf at the reverse end, +29.12 kgf at 4.68 V). P has a
minimum at 0.0629 V (its derivative's roots are 0.0629, 1.645, 2.715, 4.87 V), so on 0.05-0.0629 V
it would *decrease* the reverse thrust again; the reverse branch therefore saturates at that minimum
(full reverse from 0.0629 V down). Both branches are then strictly monotonic and invertible.

UUV thrusters (003 eq. 2.18, Tecnadyne): ``T(V) = 0.002 V^5 + 0.03 V^4 + 0.356 V^3 + 0.47 V^2 +
0.782 V`` printed without units; 85.2 at 5 V is plausible only in newtons (7.7 kgf = 75.5 N rated
forward), so it is read in N, odd-symmetric for reverse, saturated at +7.7 / -3.2 kgf.
"""

from __future__ import annotations

import numpy as np
from numba import njit

from ..core.estop import RESUME_RAMP_S, resume_weight  # noqa: F401 (RESUME_RAMP_S re-exported)
from ..core.law import param, In, Layout, LawBlock, Opt, Out, Signals
from ..units import KGF

USV_POLY_KGF = np.array([-0.4968, 5.7702, -21.755, 29.0135, -3.3987, -13.081])  # highest power first
USV_V_MIN, USV_V_MAX = 0.05, 4.68  # V, DAC range
USV_DEAD_LO, USV_DEAD_HI = 1.6, 3.2  # V, dead zone
USV_T_REV_KGF, USV_T_FWD_KGF = -13.83, 29.12  # kgf at the ends of the range
USV_RATED_KGF = 36.2  # Minn Kota rated thrust, kgf
USV_V_REV_FULL = float(
    min(
        (
            r.real
            for r in np.roots(np.polyder(USV_POLY_KGF))
            if abs(r.imag) < 1e-12 and USV_V_MIN <= r.real <= USV_DEAD_LO
        ),
        default=USV_V_MIN,
    )
)  # 0.0629 V

UUV_POLY_N = np.array([0.002, 0.03, 0.356, 0.47, 0.782, 0.0])  # N vs V, highest power first
UUV_T_FWD_N = 7.7 * KGF
UUV_T_REV_N = -3.2 * KGF


@njit(cache=True, inline="always")
def _polyval(c, x):
    y = 0.0
    for a in c:
        y = y * x + a
    return y


@njit(cache=True, inline="always")
def usv_thrust_from_voltage(v):
    """USV thruster thrust (N) from DAC voltage (V), 003 eq. 2.5 with dead zone and end values imposed."""
    if v < USV_V_MIN:
        v = USV_V_MIN
    elif v > USV_V_MAX:
        v = USV_V_MAX
    if USV_DEAD_LO <= v <= USV_DEAD_HI:
        return 0.0
    if v > USV_DEAD_HI:
        p0 = _polyval(USV_POLY_KGF, USV_DEAD_HI)
        p1 = _polyval(USV_POLY_KGF, USV_V_MAX)
        return USV_T_FWD_KGF * (_polyval(USV_POLY_KGF, v) - p0) / (p1 - p0) * KGF
    if v < USV_V_REV_FULL:
        v = USV_V_REV_FULL
    p0 = _polyval(USV_POLY_KGF, USV_DEAD_LO)
    p1 = _polyval(USV_POLY_KGF, USV_V_REV_FULL)
    return USV_T_REV_KGF * (_polyval(USV_POLY_KGF, v) - p0) / (p1 - p0) * KGF


def usv_voltage_from_thrust(thrust_n: float) -> float:
    """Inverse of :func:`usv_thrust_from_voltage` (V); 0 N maps to the dead zone's middle (2.4 V)."""
    from scipy.optimize import brentq

    t = float(thrust_n)
    if t == 0.0:
        return 0.5 * (USV_DEAD_LO + USV_DEAD_HI)
    if t > 0:
        if t >= USV_T_FWD_KGF * KGF:
            return USV_V_MAX
        return brentq(lambda v: usv_thrust_from_voltage(v) - t, USV_DEAD_HI, USV_V_MAX, xtol=1e-10)
    if t <= USV_T_REV_KGF * KGF:
        return USV_V_REV_FULL
    return brentq(lambda v: usv_thrust_from_voltage(v) - t, USV_V_REV_FULL, USV_DEAD_LO, xtol=1e-10)


@njit(cache=True)
def uuv_thrust_from_voltage(v):
    """UUV thruster thrust (N) from command voltage (V, -5..5), 003 eq. 2.18 read in N, saturated."""
    a = abs(v)
    if a > 5.0:
        a = 5.0
    t = _polyval(UUV_POLY_N, a)
    t = t if v >= 0 else -t
    if t > UUV_T_FWD_N:
        t = UUV_T_FWD_N
    elif t < UUV_T_REV_N:
        t = UUV_T_REV_N
    return t


@njit(cache=True)
def saturate(x, lo, hi):
    """Clip x to [lo, hi] (comparing real parts, so it also runs in complex arithmetic for complex step)."""
    return lo if x.real < lo.real else (hi if x.real > hi.real else x)


# -- the thruster bank: one law for the USV's and the UUV's thrusters --------------------------------

#: parameters and state of :func:`thrusters_law`; the signal slots are ``_estop`` (optional), the m
#: commands, then the m thrusts (offsets computed from ``m``: the USV has 2 thrusters, the UUV 3)
THRUSTER_PARAMS = Layout("m", "hi", "lo", "voltage", "ramp_s", "period")
THRUSTER_STATE = Layout("w")
_P, _X = THRUSTER_PARAMS.at, THRUSTER_STATE.at


@njit(cache=True)
def thrusters_law(t, sig, sl, st, pa):
    """Thrusts (N) of a bank of m thrusters: each command (N; or DAC volts through 003 eq. 2.5 when
    ``voltage``, 2.4 V = zero when absent) limited to [lo, hi]; all zero at once on ``_estop``, and
    after the stop is released the thrusts ramp back, T = w sat(T_cmd) with w rising from 0 to 1 over
    ``ramp_s`` (no thrust step at Reset, on every front end). w starts at 1: a run without an e-stop
    is not affected."""
    m = int(pa[_P.m])
    stop = sl[0] >= 0 and sig[sl[0]] != 0.0
    st[_X.w] = resume_weight(st[_X.w], stop, pa[_P.period], pa[_P.ramp_s])
    for i in range(m):
        if stop:
            thrust = 0.0
        elif pa[_P.voltage] != 0.0:
            thrust = usv_thrust_from_voltage(sig[sl[1 + i]] if sl[1 + i] >= 0 else 2.4)
        else:
            thrust = sig[sl[1 + i]]
        sig[sl[1 + m + i]] = st[_X.w] * min(pa[_P.hi], max(pa[_P.lo], thrust))


class ThrusterBank(LawBlock):
    """Saturated thrusters with the e-stop and its resume ramp (:func:`thrusters_law`).

    Reads ``<body>.thrust_<side>_cmd`` (N; ``<body>.volt_<side>_cmd`` (V) in voltage mode) and the
    optional ``_estop``; writes ``<body>.thrust_<side>`` (N) in [lo, hi].
    """

    law = staticmethod(thrusters_law)
    hi = param(_P.hi, "upper thrust limit, N (settable while running)")
    lo = param(_P.lo, "lower thrust limit, N (settable while running)")

    def __init__(self, body: str, sides, hi: float, lo: float, period: float, voltage: bool = False,
                 ramp_s: float = RESUME_RAMP_S):  # fmt: skip
        m = len(sides)
        self.period = float(period)
        self.body = body
        self.mode = "voltage" if voltage else "thrust"
        cmd = In("N", m) if not voltage else Opt("V", m)
        self.signals = Signals(estop=Opt("bool"), cmd=cmd, out=Out("N", m))
        kind = "volt" if voltage else "thrust"
        self.bind(
            estop="_estop",
            cmd=[f"{body}.{kind}_{s}_cmd" for s in sides],
            out=[f"{body}.thrust_{s}" for s in sides],
        )
        self.pa = THRUSTER_PARAMS.pack(
            m=m, hi=float(hi), lo=float(lo), voltage=1.0 if voltage else 0.0, ramp_s=ramp_s, period=self.period
        )
        self.st = THRUSTER_STATE.pack(w=1.0)
