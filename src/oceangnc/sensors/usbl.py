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
fix; the values are then fresh, else they keep the last fix and downstream blocks must hold),
``usbl.pings_lost`` (count).
"""

from __future__ import annotations

import math

from numba import njit
from pydantic import Field

from ..core.blocks import Block
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


@register_block("sensor.usbl")
class USBL(Block):
    """USBL between bodies ``top`` and ``bottom`` (module docstring)."""

    role = "sensor"

    name = "usbl"

    def __init__(self, cfg: USBLConfig, top: str = "usv", bottom: str = "uuv"):
        self.cfg = cfg
        self.period = 1.0 / cfg.rate
        self.top = top
        self.bottom = bottom
        self.inputs = {f"{top}.x": "m", f"{top}.y": "m", f"{bottom}.x": "m", f"{bottom}.y": "m", f"{bottom}.z": "m"}
        self.optional_inputs = {f"{top}.z": "m"}  # a surface vessel: z = 0
        self.outputs = {
            "usbl.dn": "m",
            "usbl.de": "m",
            "usbl.dz": "m",
            "usbl.range": "m",
            "usbl.hrange": "m",
            "usbl.bearing": "rad",
            "usbl.valid": "bool",
            "usbl.pings_lost": "count",
        }

    def reset(self, rng) -> None:
        self.rng = rng
        self.lost = 0
        self.last = None

    def in_forced_dropout(self, t: float) -> bool:
        c = self.cfg
        return c.dropout_start >= 0 and c.dropout_start <= t < c.dropout_start + c.dropout_duration

    def compiled(self):
        """Compiled form for the fused loop (:func:`oceangnc.sensors._compiled.usbl_step`)."""
        if self.last is None:
            return None
        import numpy as np

        from ..core.fused import CompiledBlock

        c, a, b = self.cfg, self.top, self.bottom
        st = np.array([self.lost, 1.0, *self.last], float)
        pa = np.array(
            [
                c.q_max,
                c.p_drop,
                c.dropout_start,
                c.dropout_duration,
                c.degraded_gain,
                c.range_resolution,
                math.radians(c.angle_resolution_deg),
            ]
        )
        sig = [
            f"{b}.x",
            f"{a}.x",
            f"{b}.y",
            f"{a}.y",
            f"?{b}.z",
            f"?{a}.z",
            *(f"usbl.{k}" for k in ("dn", "de", "dz", "range", "hrange", "bearing")),
            "usbl.valid",
            "usbl.pings_lost",
        ]
        return CompiledBlock(usbl_step, sig, st, pa, rng=self.rng)

    def step(self, t: float, bus: dict) -> None:
        c = self.cfg
        a, b = self.top, self.bottom
        dn = bus[f"{b}.x"] - bus[f"{a}.x"]
        de = bus[f"{b}.y"] - bus[f"{a}.y"]
        dz = bus[f"{b}.z"] - bus.get(f"{a}.z", 0.0)
        h, q = usbl_geometry(dn, de, dz)
        u = self.rng.uniform(-1.0, 1.0, 4)
        degraded = q > c.q_max
        valid = not self.in_forced_dropout(t)
        if degraded and u[3] * 0.5 + 0.5 < c.p_drop:
            valid = False
        if valid:
            g = c.degraded_gain if degraded else 1.0
            ares = math.radians(c.angle_resolution_deg)
            self.last = usbl_fix(h, dn, de, dz, u[0], u[1], u[2], g, c.range_resolution, ares)
        else:
            self.lost += 1
        if self.last is not None:
            for k, v in zip(("dn", "de", "dz", "range", "hrange", "bearing"), self.last):
                bus[f"usbl.{k}"] = v
        bus["usbl.valid"] = 1.0 if valid else 0.0
        bus["usbl.pings_lost"] = float(self.lost)


@njit(cache=True)
def usbl_step(t, sig, sl, st, pa, rng):
    """:class:`oceangnc.sensors.usbl.USBL` (003 ch. 6.1.4, dropouts).

    slots: bottom.x, top.x, bottom.y, top.y, ?bottom.z, ?top.z | dn, de, dz, range, hrange, bearing,
    valid, pings_lost. state: lost, has_last, last (6). params: q_max, p_drop, dropout start,
    dropout duration, degraded gain, range resolution, angle resolution (rad).
    """
    dn = sig[sl[0]] - sig[sl[1]]
    de = sig[sl[2]] - sig[sl[3]]
    dz = (sig[sl[4]] if sl[4] >= 0 else 0.0) - (sig[sl[5]] if sl[5] >= 0 else 0.0)
    h, q = usbl_geometry(dn, de, dz)
    u0 = rng.uniform(-1.0, 1.0)
    u1 = rng.uniform(-1.0, 1.0)
    u2 = rng.uniform(-1.0, 1.0)
    u3 = rng.uniform(-1.0, 1.0)
    degraded = q > pa[0]
    valid = not (pa[2] >= 0 and pa[2] <= t < pa[2] + pa[3])
    if degraded and u3 * 0.5 + 0.5 < pa[1]:
        valid = False
    if valid:
        fix = usbl_fix(h, dn, de, dz, u0, u1, u2, pa[4] if degraded else 1.0, pa[5], pa[6])
        for i in range(6):
            st[2 + i] = fix[i]
        st[1] = 1.0
    else:
        st[0] += 1.0
    if st[1] != 0.0:
        for i in range(6):
            sig[sl[6 + i]] = st[2 + i]
    sig[sl[12]] = 1.0 if valid else 0.0
    sig[sl[13]] = st[0]
