"""USBL acoustic positioning between the USV (transceiver) and the UUV (transponder).

003 ch. 6.1.2 and appendix B table C-3 (SeaTrac X150 / X010): outputs in NED the relative
distance, relative angle and relative depth; range resolution +-50 mm, angular resolution +-1 deg.
Each ping (every 1/``rate`` s) measures the vector d = p_uuv - p_usv (m, NED) as

    slant range   rho   = |d| + e_r,                  e_r ~ U(-0.05, 0.05) m
    bearing       beta  = atan2(d_E, d_N) + e_b,      e_b ~ U(-1, 1) deg
    depression    gamma = atan2(d_D, |d_NE|) + e_g,   e_g ~ U(-1, 1) deg

and reports d back from (rho, beta, gamma). The "+-" resolutions are read as uniform error bounds.

Usable range (003 ch. 6.1.2): with 0.8 m relative depth the fix became "not smooth ... unreliable"
beyond about 4 m horizontal range, i.e. when the ratio q = |d_NE| / |d_D| exceeds about 4/0.8 = 5
(a grazing acoustic path). Beyond ``q_max`` each ping is lost with probability ``p_drop`` and the
surviving fixes have their errors scaled by ``degraded_gain`` (the tank errors grew from 0.9/2.1 cm
at 2.4 m to 10/16.5 cm at 4.4 m, five to ten times). Degraded and intermittent, not absent.

A forced dropout window [``dropout_start``, ``dropout_start + dropout_duration``) loses every ping
(for tests and what-if runs). Outputs: ``usbl.dn``, ``usbl.de``, ``usbl.dz`` (m), ``usbl.range``
(slant, m), ``usbl.hrange`` (m), ``usbl.bearing`` (rad), ``usbl.valid`` (1 when the last ping gave a
fix; the values are then fresh, else they keep the last fix and downstream blocks must hold; 0
before the first fix), ``usbl.pings_lost`` (count). Law: :func:`usbl_law`.
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit
from pydantic import Field

from ..core.law import In, LawBlock, Layout, Opt, Out, Signals
from ..core.registry import register_block
from ..io.config import StrictModel


class USBLConfig(StrictModel):
    rate: float = Field(2.0, gt=0, le=40, description="ping (update) rate, Hz")
    range_resolution: float = Field(0.05, ge=0, le=10, description="range error bound (table C-3: 50 mm), m")
    angle_resolution_deg: float = Field(1.0, ge=0, le=30, description="angle error bound (table C-3: 1 deg), deg")
    q_max: float = Field(
        5.0, gt=0, le=1e3, description="horizontal range / relative depth beyond which fixes degrade (003: 4 m / 0.8 m)"
    )
    p_drop: float = Field(0.5, ge=0, le=1, description="probability of losing a ping beyond q_max")
    degraded_gain: float = Field(5.0, ge=1, le=100, description="error scale of fixes beyond q_max")
    dropout_start: float = Field(-1.0, ge=-1, le=1e6, description="start of a forced dropout window (-1: none), s")
    dropout_duration: float = Field(0.0, ge=0, le=1e6, description="length of the forced dropout window, s")


@njit(cache=True)
def usbl_geometry(dn, de, dz):
    """(horizontal range h (m), h / |dz|): the slant geometry that decides the degraded cone."""
    h = math.hypot(dn, de)
    return h, h / max(abs(dz), 1e-6)


@njit(cache=True)
def usbl_fix(h, dn, de, dz, u0, u1, u2, g, range_res, angle_res):
    """One USBL fix (003 ch. 6.1.4): slant range, bearing and elevation of the true offset (dn, de, dz)
    with uniform errors u0..u2 in [-1, 1] scaled by the resolutions (m, rad) times the gain ``g``
    (> 1 when degraded); returns (dn, de, dz, range, horizontal range, bearing) in m and rad."""
    rho = math.sqrt(h * h + dz * dz) + g * range_res * u0
    ea = angle_res * g
    beta = math.atan2(de, dn) + ea * u1
    gam = math.atan2(dz, h) + ea * u2
    rho = max(rho, 0.0)
    hm = rho * math.cos(gam)
    return hm * math.cos(beta), hm * math.sin(beta), rho * math.sin(gam), rho, hm, beta


SIGNALS = Signals(
    bottom_x=In("m"),
    top_x=In("m"),
    bottom_y=In("m"),
    top_y=In("m"),
    bottom_z=In("m"),
    top_z=Opt("m"),  # a surface vessel: z = 0
    dn=Out("m"),
    de=Out("m"),
    dz=Out("m"),
    range=Out("m"),
    hrange=Out("m"),
    bearing=Out("rad"),
    valid=Out("bool"),
    pings_lost=Out("count"),
)
#: q_max, p_drop, forced dropout start and duration (s), degraded gain, range (m) and angle (rad) resolutions
PARAMS = Layout("q_max", "p_drop", "dropout_start", "dropout_duration", "degraded_gain", "range_res", "angle_res")
#: pings lost, whether a fix was made, and the last fix (dn, de, dz, range, hrange, bearing: m, rad)
STATE = Layout("lost", "has_last", ("last", 6))
S, P, X = SIGNALS.at, PARAMS.at, STATE.at


@njit(cache=True)
def usbl_law(t, sig, sl, st, pa, rng):
    """One ping (module docstring): four uniform draws in [-1, 1] (range, bearing, elevation errors,
    then the drop), the ping lost inside the forced window or, beyond q_max, with probability p_drop;
    a fix (:func:`usbl_fix`, errors scaled by the degraded gain beyond q_max) or one more lost ping.
    The last fix is published (from the first fix on) with ``valid`` and the count of lost pings."""
    dn = sig[sl[S.bottom_x]] - sig[sl[S.top_x]]
    de = sig[sl[S.bottom_y]] - sig[sl[S.top_y]]
    dz = sig[sl[S.bottom_z]] - (sig[sl[S.top_z]] if sl[S.top_z] >= 0 else 0.0)
    h, q = usbl_geometry(dn, de, dz)
    u0 = rng.uniform(-1.0, 1.0)
    u1 = rng.uniform(-1.0, 1.0)
    u2 = rng.uniform(-1.0, 1.0)
    u3 = rng.uniform(-1.0, 1.0)
    degraded = q > pa[P.q_max]
    start = pa[P.dropout_start]
    valid = not (start >= 0 and start <= t < start + pa[P.dropout_duration])
    if degraded and u3 * 0.5 + 0.5 < pa[P.p_drop]:
        valid = False
    if valid:
        g = pa[P.degraded_gain] if degraded else 1.0
        fix = usbl_fix(h, dn, de, dz, u0, u1, u2, g, pa[P.range_res], pa[P.angle_res])
        for i in range(6):
            st[X.last + i] = fix[i]
        st[X.has_last] = 1.0
    else:
        st[X.lost] += 1.0
    if st[X.has_last] != 0.0:
        sig[sl[S.dn]] = st[X.last]
        sig[sl[S.de]] = st[X.last + 1]
        sig[sl[S.dz]] = st[X.last + 2]
        sig[sl[S.range]] = st[X.last + 3]
        sig[sl[S.hrange]] = st[X.last + 4]
        sig[sl[S.bearing]] = st[X.last + 5]
    sig[sl[S.valid]] = 1.0 if valid else 0.0
    sig[sl[S.pings_lost]] = st[X.lost]


@register_block("sensor.usbl")
class USBL(LawBlock):
    """USBL between bodies ``top`` and ``bottom`` (module docstring); law :func:`usbl_law`."""

    role = "sensor"
    name = "usbl"
    law = staticmethod(usbl_law)
    signals = SIGNALS
    draws = True

    def __init__(self, cfg: USBLConfig, top: str = "usv", bottom: str = "uuv"):
        self.cfg = cfg
        self.period = 1.0 / cfg.rate
        self.top = top
        self.bottom = bottom
        a, b = top, bottom
        outs = {k: f"usbl.{k}" for k in ("dn", "de", "dz", "range", "hrange", "bearing", "valid", "pings_lost")}
        self.bind(bottom_x=f"{b}.x", top_x=f"{a}.x", bottom_y=f"{b}.y", top_y=f"{a}.y", bottom_z=f"{b}.z",
                  top_z=f"{a}.z", **outs)  # fmt: skip
        self.pa = PARAMS.pack(
            q_max=cfg.q_max,
            p_drop=cfg.p_drop,
            dropout_start=cfg.dropout_start,
            dropout_duration=cfg.dropout_duration,
            degraded_gain=cfg.degraded_gain,
            range_res=cfg.range_resolution,
            angle_res=math.radians(cfg.angle_resolution_deg),
        )
        self.st = np.zeros(STATE.size)

    def reset(self, rng) -> None:
        self.rng = rng
        self.st[:] = 0.0

    def in_forced_dropout(self, t: float) -> bool:
        c = self.cfg
        return c.dropout_start >= 0 and c.dropout_start <= t < c.dropout_start + c.dropout_duration

    @property
    def lost(self) -> int:
        """Pings lost so far."""
        return int(self.st[X.lost])

    @property
    def last(self) -> tuple | None:
        """The last fix (dn, de, dz, range, hrange, bearing; m, rad), None before the first."""
        return tuple(float(v) for v in self.st[X.last : X.last + 6]) if self.st[X.has_last] else None
