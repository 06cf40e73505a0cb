"""Building the combined plant's arrays from its configs: the flat parameter array (layout in
:mod:`._combined_layout`), the initial state (a straight cable between the two attachment points) and
the state names, with the configuration checks that need the whole assembly.
"""

from __future__ import annotations

import math

import numpy as np

from ..core.caches import cheapest
from ..errors import ConfigError
from ._combined_layout import (
    H_ATT,
    H_BED,
    H_BED_D,
    H_BED_GX,
    H_BED_GY,
    H_BED_MU,
    H_BED_R,
    H_BED_W,
    H_BED_Z,
    H_BRI,
    H_CV,
    H_CVE,
    H_EA,
    H_FIX,
    H_KDRAG,
    H_KDT,
    H_L0,
    H_LAW,
    H_MA,
    H_MC,
    H_N,
    H_NMAX,
    H_PO,
    H_TOP,
    H_UO,
    H_VO,
    H_WA,
    H_WCAP,
    H_WIN,
    H_WMIN,
    H_WO,
    H_WSEG,
    H_WT,
    H_WTAU,
    H_WV,
    N_USV,
    P_SCR,
    P_USV,
    P_UUV,
    UUV_NP,
    _ends,
)
from ._combined_bridle import bridle_block
from .cable import CableConfig
from .usv import STATE_NAMES as USV_STATES
from .usv import USVConfig
from .uuv import STATE_NAMES as UUV_STATES
from .uuv import UUVConfig


#: how much longer than the cable the start gap may be (strain): a straight start state stretched by
#: more than 10 % is beyond the elongation at break of tow cables (steel 1-2 %, polyester and nylon rope
#: 10-20 %) and starts the run with a snap load (2 m cable to a UUV at 3 m: 44 %, 6.9 kN), issue 26;
#: ``cable-current`` starts at 4 %, its static stretch under the UUV's submerged weight (EA 3.7 kN)
START_SLACK = 0.10


def _check(cable: CableConfig, uuv: UUVConfig) -> None:
    if cable.segments < 1:
        raise ConfigError(f"cable.segments = {cable.segments}: allowed range 1 <= value")
    for key, v in (
        ("cable.length", cable.length),
        ("cable.diameter", cable.diameter),
        ("cable.E", cable.E),
        ("cable.density", cable.density),
        ("uuv.mass", uuv.mass),
    ):
        if not (v > 0 and math.isfinite(v)):
            raise ConfigError(f"{key} = {v}: must be > 0")


def segmentation(c: CableConfig, winch) -> tuple[float, int, int]:
    """(nominal segment length l0 (m), initial segment count n, node slots n_max) of the cable; with a
    winch, n_max covers the drum's whole capacity."""
    if winch is None:
        return c.l0, c.segments, c.segments
    l0 = c.segment_length if c.segment_length is not None else c.length / c.segments
    if winch.capacity < c.length:
        raise ConfigError(
            f"cable.length = {c.length:g}: above the drum's capacity winch.capacity = {winch.capacity:g} m"
        )
    if winch.min_length > c.length:
        raise ConfigError(f"cable.length = {c.length:g}: below winch.min_length = {winch.min_length:g} m")
    n = max(1, int(round(c.length / l0)))
    nmax = max(n, int(math.ceil(winch.capacity / l0 + 0.5)) + 1)
    return l0, n, nmax


def build_arrays(
    usv_cfg: USVConfig, uuv_cfg: UUVConfig, c: CableConfig, top: str, integrator: str, winch, seabed, ends=_ends
):
    """(p, x0, state names, n_max) of a combined plant; ``winch``/``seabed`` None when absent; ``ends`` the
    plant's compiled :func:`._combined_layout._ends` (its copy without the plant's absent features)."""
    _check(c, uuv_cfg)
    has_winch = winch is not None
    has_bed = seabed is not None
    l0, n, nmax = segmentation(c, winch)
    psi0 = math.radians(usv_cfg.psi0_deg)
    cps, sps = math.cos(psi0), math.sin(psi0)
    top0 = (usv_cfg.x0 + cps * c.top_x - sps * c.top_y, usv_cfg.y0 + sps * c.top_x + cps * c.top_y, c.top_z)
    p = np.zeros(P_SCR + 40 * (nmax + 1) + 30 * (nmax + 1) + 36)
    p[H_N] = n
    p[H_TOP] = 1.0 if top == "fixed" else 0.0
    p[H_FIX : H_FIX + 3] = top0
    p[H_ATT : H_ATT + 3] = c.top_point
    area = c.area
    p[H_L0] = l0
    p[H_EA] = c.EA
    p[H_CV] = c.damping
    p[H_CVE] = 0.0 if integrator == "rk4-split" else c.damping
    p[H_MC] = c.density * area * l0
    p[H_MA] = c.added_mass_coeff * c.rho_water * area * l0
    p[H_WSEG] = c.weight_per_length * l0
    if c.drag_law == "normal-tangential":
        p[H_LAW] = 1.0
        p[H_KDRAG] = 0.5 * c.rho_water * c.cd_n * c.diameter * l0 if c.drag_on else 0.0
        p[H_KDT] = 0.5 * c.rho_water * c.cd_t * math.pi * c.diameter * l0 if c.drag_on else 0.0
    else:
        p[H_KDRAG] = 0.5 * c.rho_water * c.cd * c.diameter * l0 if c.drag_on else 0.0
    p[P_USV : P_USV + N_USV] = usv_cfg.params()
    bridle = c.attachment == "bridle"
    b = c.bridle
    # with the bridle the cable ends at its junction, which starts at the rigged apex
    p[P_UUV : P_UUV + UUV_NP] = uuv_cfg.params(tow_point=(b.apex_x, b.apex_y, b.apex_z) if bridle else c.tow_point)
    if bridle:  # its block at the end of p (layout ._combined_bridle.BRIDLE), its offset in the header
        p[H_BRI] = p.size
        p = np.concatenate([p, bridle_block(b)])
    if has_bed:
        sl = math.tan(math.radians(seabed.slope_deg))
        ds = math.radians(seabed.slope_direction_deg)
        p[H_BED] = 1.0
        p[H_BED_D] = seabed.depth
        p[H_BED_GX] = sl * math.cos(ds)
        p[H_BED_GY] = sl * math.sin(ds)
        p[H_BED_MU] = seabed.friction
        p[H_BED_W] = seabed.contact_frequency
        p[H_BED_Z] = seabed.contact_damping_ratio
        p[H_BED_R] = uuv_cfg.diameter / 2.0
        zb = seabed.depth + p[H_BED_GX] * top0[0] + p[H_BED_GY] * top0[1]
        if zb <= top0[2]:
            raise ConfigError(
                f"environment.seabed.depth = {seabed.depth:g}: the seabed ({zb:.3g} m deep under "
                f"the USV) is above the cable's attachment point (cable.top_z = {c.top_z:g} m)"
            )
    # state layout
    if has_winch:
        uo, wo, po = 6, 18, 20
        vo = po + 3 * (nmax - 1)
        size = vo + 3 * (nmax - 1)
        p[H_WIN] = 1.0
        p[H_WO] = wo
        p[H_NMAX] = nmax
        p[H_WV] = winch.speed_max
        p[H_WA] = winch.accel_max
        p[H_WT] = winch.tension_max
        p[H_WCAP] = winch.capacity
        p[H_WMIN] = winch.min_length
        p[H_WTAU] = winch.time_constant
    else:
        po = 6
        vo = 6 + 3 * (n - 1)
        uo = 6 + 6 * (n - 1)
        size = uo + 12
    p[H_PO], p[H_VO], p[H_UO] = po, vo, uo
    # initial state: USV, straight cable between the attachment points, UUV
    x0 = np.zeros(size)
    x0[:6] = [usv_cfg.x0, usv_cfg.y0, psi0, usv_cfg.u0, 0.0, 0.0]
    x0[uo : uo + 12] = uuv_cfg.initial_state()
    if has_winch:
        x0[wo] = c.length
    pos = np.zeros(3 * (n + 1))
    vel = np.zeros(3 * (n + 1))
    # one call at build time: compiled when cached, else its Python body (the same code; a first run's
    # second process compiles _ends meanwhile for the fused loop's kernels, core.caches.compile_ahead)
    cheapest(ends)(x0, p, n, pos, vel)
    pos = pos.reshape(-1, 3)
    gap = float(np.linalg.norm(pos[n] - pos[0]))
    if gap > c.length * (1.0 + START_SLACK):  # a cable stretched at t = 0: a start-up snap load, not a run
        raise ConfigError(
            f"cable.length = {c.length:g} m is shorter than the {gap:.2f} m between its attachment points at "
            f"the start ({100 * (gap / c.length - 1):.0f} % stretch, more than {100 * START_SLACK:.0f} %; USV at ({usv_cfg.x0:g}, {usv_cfg.y0:g}), UUV at uuv.x0/y0/z0 = ({uuv_cfg.x0:g}, "
            f"{uuv_cfg.y0:g}, {uuv_cfg.z0:g}) m): lengthen the cable or start the UUV within its reach"
        )
    vel = vel.reshape(-1, 3)
    lt = c.length - (n - 1) * l0
    for i in range(1, n):
        f = (lt + (i - 1) * l0) / c.length  # unstretched arc-length fraction of node i
        x0[po + 3 * (i - 1) : po + 3 * i] = (1 - f) * pos[0] + f * pos[n]
        x0[vo + 3 * (i - 1) : vo + 3 * i] = (1 - f) * vel[0] + f * vel[n]
    names = [f"usv.{s}" for s in USV_STATES]
    cab = [f"cable.{a}{i}" for i in range(1, nmax) for a in "xyz"]
    cab += [f"cable.v{a}{i}" for i in range(1, nmax) for a in "xyz"]
    if has_winch:
        names += [f"uuv.{s}" for s in UUV_STATES] + ["winch.length", "winch.speed"] + cab
    else:
        names += cab + [f"uuv.{s}" for s in UUV_STATES]
    return p, x0, names, nmax
