"""Depth or altitude of a towed UUV held by the winch's drum speed (issue 16).

:class:`WinchDepthController` (registered ``"winch.depth"``) computes the line speed command
``winch.speed_cmd`` (m/s, + paying out) from the UUV's depth ``uuv.z`` (mode ``"depth"``) or its altitude
above the seabed ``uuv.altitude`` (mode ``"altitude"``):

    e = z_ref - z            (depth mode: too shallow -> pay out)
    e = a - a_ref            (altitude mode: too high -> pay out)
    s_c = K_p e + K_i int e + K_d de/dt + ds_ref/dt   (PID, back-calculation anti-windup, feed-forward)

The reference may move: in depth mode a trapezoidal profile (``profile``: list of (t, z) breakpoints,
linearly interpolated), whose rate is fed forward (for a cable hanging nearly vertically a metre of
payout is a metre of depth). **Tension**: above ``tension_margin`` x the winch's tension limit the
command is raised to at least K_T (T - T_margin), so the controller pays out rather than drive the
tension to the limit (the winch itself renders at the limit as the last resort). The command is
saturated to +-``speed_max`` (the winch saturates again and logs it).

When a block writes ``uuv.depth_cmd`` (depth mode; the ArduSub depth reference of
:class:`oceangnc.control.ardusub.SubDepth`), that is the target and ``uuv.depth_rate_cmd`` its
fed-forward rate, in place of ``target`` / ``profile``. While ``_estop`` is set (a MAVLink vehicle
disarmed or e-stopped) the command is 0 m/s.
"""

from __future__ import annotations

import math
from typing import Literal

import numpy as np
from numba import njit
from pydantic import Field

from ..core.config import StrictModel
from ..core.law import In, LawBlock, Layout, Opt, Out, Signals
from ..core.registry import register_block
from .pid import PID, PID_PARAMS, PID_STATE, pid_params, pid_run


class WinchControlConfig(StrictModel):
    """Gains and limits of the depth/altitude-by-winch loop."""

    mode: Literal["depth", "altitude"] = Field("depth", description="hold the UUV's depth or its altitude")
    target: float = Field(5.0, ge=0, le=1e4, description="depth (depth mode) or altitude target, m")
    profile: list[tuple[float, float]] = Field(
        [],
        description="depth mode: (t s, z m) breakpoints of a moving target, linear between them "
        "(empty: the constant target)",
    )
    kp: float = Field(0.3, ge=0, le=100, description="proportional gain, (m/s)/m")
    ki: float = Field(0.01, ge=0, le=100, description="integral gain, (m/s)/(m s)")
    kd: float = Field(0.0, ge=0, le=1000, description="derivative gain (on the measured error), (m/s)/(m/s)")
    speed_max: float = Field(0.5, gt=0, le=5, description="command limit, m/s")
    tension_margin: float = Field(
        0.8, gt=0, le=1, description="fraction of the winch's tension limit where the loop starts paying out, -"
    )
    tension_gain: float = Field(0.005, ge=0, le=10, description="K_T: payout per newton above the margin, (m/s)/N")
    rate: float = Field(10.0, gt=0, le=1000, description="loop rate, Hz")


@njit(cache=True)
def profile_reference(t, pt, pz):
    """(z, dz/dt) of the piecewise-linear profile through ``(pt[i], pz[i])`` at ``t`` (m, m/s).

    ``z`` is ``numpy.interp(t, pt, pz)`` operation for operation (held at the end values outside
    the breakpoints); the rate is the slope of the segment containing ``t`` (0 outside, and at a
    breakpoint the slope of the segment that starts there): the feed-forward of the depth loop
    (:class:`oceangnc.control.winch.WinchDepthController`).
    """
    n = pt.size
    # i = numpy.searchsorted(pt, t, side="right"): breakpoints at or before t
    lo, hi = 0, n
    while lo < hi:
        mid = (lo + hi) // 2
        if pt[mid] <= t:
            lo = mid + 1
        else:
            hi = mid
    i = lo
    if t < pt[0]:
        z = pz[0]
    elif t > pt[n - 1] or t == pt[n - 1]:
        z = pz[n - 1]
    else:
        j = i - 1
        if t == pt[j]:
            z = pz[j]
        else:
            slope = (pz[j + 1] - pz[j]) / (pt[j + 1] - pt[j])
            z = slope * (t - pt[j]) + pz[j]
            if math.isnan(z):
                z = slope * (t - pt[j + 1]) + pz[j + 1]
                if math.isnan(z) and pz[j] == pz[j + 1]:
                    z = pz[j]
    rate = 0.0
    if 0 < i < n:
        rate = (pz[i] - pz[i - 1]) / (pt[i] - pt[i - 1])
    return z, rate


@njit(cache=True)
def tension_payout(s, tension, t_margin, gain, s_max):
    """Winch command ``s`` (m/s) raised to at least ``min(s_max, gain (T - T_margin))`` when the top
    tension ``T`` (N) is above ``T_margin``: pay out rather than drive the tension to the limit."""
    if tension > t_margin:
        s = max(s, min(s_max, gain * (tension - t_margin)))
    return s


WINCH_SIGNALS = Signals(
    y=In("m"), tension=Opt("N"), ref=Opt("m"), ref_rate=Opt("m/s"), estop=Opt("bool"), cmd=Out("m/s"),
    target=Out("m"), error=Out("m"),
)  # fmt: skip
#: the winch loop's parameters; the profile's m breakpoint times and depths follow from _WP.pt on
WINCH_HEAD = Layout(("pid", PID_PARAMS.size), "period", "altitude", "t_margin", "t_gain", "speed_max", "target", "m")
_WS, _WP = WINCH_SIGNALS.at, WINCH_HEAD.at
_PT = WINCH_HEAD.size


@njit(cache=True)
def winch_depth_law(t, sig, sl, st, pa):
    """The depth/altitude-by-winch loop (module docstring): the target (constant, or the profile at t
    with its rate fed forward in depth mode), e = z_ref - z (depth) or a - a_ref (altitude) in m, the
    PID's line speed (m/s) raised by :func:`tension_payout` above the tension margin; a non-finite
    measurement gives 0 m/s. Writes the command, the target and the error."""
    m = int(pa[_WP.m])
    if sl[_WS.ref] >= 0:  # a depth reference on the bus (ArduSub's modes, oceangnc.control.ardusub)
        ref = sig[sl[_WS.ref]]
        rate = sig[sl[_WS.ref_rate]] if sl[_WS.ref_rate] >= 0 else 0.0
    elif m > 0:
        ref, rate = profile_reference(t, pa[_PT : _PT + m], pa[_PT + m : _PT + 2 * m])
    else:
        ref, rate = pa[_WP.target], 0.0
    y = sig[sl[_WS.y]]
    stop = sl[_WS.estop] >= 0 and sig[sl[_WS.estop]] != 0.0
    if not math.isfinite(y) or stop:
        sig[sl[_WS.cmd]] = 0.0
        sig[sl[_WS.target]] = ref
        sig[sl[_WS.error]] = 0.0
        return
    depth = pa[_WP.altitude] == 0.0
    e = (ref - y) if depth else (y - ref)
    s = pid_run(st, 0, pa, _WP.pid, e, pa[_WP.period], 0.0, False, rate if depth else 0.0, 1.0)
    tension = sig[sl[_WS.tension]] if sl[_WS.tension] >= 0 else 0.0
    sig[sl[_WS.cmd]] = tension_payout(s, tension, pa[_WP.t_margin], pa[_WP.t_gain], pa[_WP.speed_max])
    sig[sl[_WS.target]] = ref
    sig[sl[_WS.error]] = e


@register_block("winch.depth")
class WinchDepthController(LawBlock):
    """Drum speed command for a depth or altitude target (module docstring); law :func:`winch_depth_law`.

    Reads ``uuv.z`` or ``uuv.altitude`` (m) and ``cable.top_tension`` (N); writes ``winch.speed_cmd``
    (m/s), ``winch.target`` (m: the current depth or altitude target) and ``winch.error`` (m).
    ``pid`` is a :class:`~oceangnc.control.pid.PID` view of its state.
    """

    name = "winch_control"
    law = staticmethod(winch_depth_law)
    signals = WINCH_SIGNALS

    def __init__(self, cfg: WinchControlConfig, tension_max: float):
        self.cfg = cfg
        self.period = 1.0 / cfg.rate
        self.tension_max = float(tension_max)
        self.meas = "uuv.z" if cfg.mode == "depth" else "uuv.altitude"
        ref = "uuv.depth" if cfg.mode == "depth" else "uuv.altitude"  # uuv.depth_cmd / uuv.altitude_cmd
        self.bind(y=self.meas, tension="cable.top_tension", ref=f"{ref}_cmd", ref_rate=f"{ref}_rate_cmd",
                  estop="_estop", cmd="winch.speed_cmd", target="winch.target", error="winch.error")  # fmt: skip
        prof = np.asarray(cfg.profile, float) if cfg.profile else np.zeros((0, 2))
        self._pt = prof[:, 0] if len(prof) else None
        self._pz = prof[:, 1] if len(prof) else None
        head = WINCH_HEAD.pack(
            pid=PID_PARAMS.pack(pid_params(cfg.kp, cfg.ki, cfg.kd, -cfg.speed_max, cfg.speed_max)),
            period=self.period,
            altitude=0.0 if cfg.mode == "depth" else 1.0,
            t_margin=cfg.tension_margin * self.tension_max,
            t_gain=cfg.tension_gain,
            speed_max=cfg.speed_max,
            target=cfg.target,
            m=len(prof),
        )
        self.pa = np.concatenate([head, prof[:, 0], prof[:, 1]])
        self.st = np.zeros(PID_STATE.size)
        self.pid = PID.view(self.st, 0, self.pa, _WP.pid)

    def reset(self, rng) -> None:
        self.st[:] = 0.0

    def reference(self, t: float) -> tuple[float, float]:
        """(target m, its rate m/s) at time ``t``."""
        if self._pt is None:
            return self.cfg.target, 0.0
        z, rate = profile_reference(float(t), self._pt, self._pz)
        return float(z), float(rate)
