"""Published outputs of the combined plant: one compiled call fills every signal of a publish."""

from __future__ import annotations

import math

import numpy as np
from numba import njit

from ..core.rotations import heading_speed
from ._combined_layout import (
    VAR_KEYS,
    H_N,
    H_L0,
    H_MC,
    H_BED,
    H_WIN,
    H_WO,
    H_WV,
    H_WT,
    H_WCAP,
    top_l0,
    seabed_depth,
)
from ._combined_kernels import cable_state
from ._combined_winch import winch_command
from .usv import STATE_NAMES as USV_STATES
from .uuv import STATE_NAMES as UUV_STATES

# numpy scalars, not literals: one compiled heading_speed for every caller (numba specialises on literals)
_I2, _I3 = np.int64(2), np.int64(3)


# feature switches (oceangnc.core.variants): True here, so the functions as written handle every
# configuration (the runtime flags in p decide); ._combined_variants compiles copies with the features
# a plant does not use switched off, whose code numba then never compiles
BED = WINCH = True


@njit(cache=True)
def _fill_outputs(x, p, o_uuv, nodes, ends, out):
    """Published outputs in the order of ``CombinedPlant._out_keys`` (see :meth:`CombinedPlant.publish`)."""
    cable_state(x, p, nodes, ends)
    for i in range(6):
        out[i] = x[i]
    out[2], out[6] = heading_speed(x, _I2, _I3, _I2)  # as USVPlant.publish
    for i in range(12):
        out[7 + i] = x[o_uuv + i]
    out[12], out[19] = heading_speed(x, o_uuv + 5, o_uuv + 6, _I3)  # as UUVPlant.publish
    out[20] = math.sqrt(ends[0] ** 2 + ends[1] ** 2 + ends[2] ** 2)
    out[21] = math.sqrt(ends[3] ** 2 + ends[4] ** 2 + ends[5] ** 2)
    m = nodes.size
    dx = nodes[m - 3] - nodes[0]
    dy = nodes[m - 2] - nodes[1]
    dz = nodes[m - 1] - nodes[2]
    out[22] = math.degrees(math.atan2(math.hypot(dx, dy), dz))
    for i in range(m):
        out[23 + i] = nodes[i]


@njit(cache=True)
def _fill_outputs_var(x, p, o_uuv, nodes, ends, out, u, nmax):
    """As :func:`_fill_outputs` for a winch and/or seabed plant: node columns for ``nmax`` + 1 nodes (the
    inactive ones at the tow point; ``cable.nodes`` tells how many are active), then cable.length, cable.nodes, cable.mass, winch.{speed, speed_cmd_sat,
    cmd_saturated, rendering, at_capacity, tension, power}, uuv.altitude, cable.nodes_on_bed."""
    n = int(p[H_N])
    m = 3 * (n + 1)
    _fill_outputs(x, p, o_uuv, nodes[0:m], ends, out)
    for i in range(m, 3 * (nmax + 1)):  # inactive node slots: collapsed onto the tow point
        out[23 + i] = nodes[m - 3 + i % 3]
    k = 23 + 3 * (nmax + 1)
    l0 = p[H_L0]
    lt = top_l0(x, p, n)
    ttop = out[20]
    if WINCH and p[H_WIN] > 0.5:
        wo = int(p[H_WO])
        L = x[wo]
        sd = x[wo + 1]
        vmax = p[H_WV]
        out[k] = L
        out[k + 3] = sd
        out[k + 4] = winch_command(x, u, p, ttop)
        out[k + 5] = 1.0 if abs(u[9]) > vmax else 0.0
        out[k + 6] = 1.0 if ttop > p[H_WT] else 0.0
        out[k + 7] = 1.0 if (L >= p[H_WCAP] and u[9] > 0.0) else 0.0
        out[k + 8] = ttop
        out[k + 9] = -ttop * sd
    else:
        out[k] = (n - 1) * l0 + lt
        for j in range(3, 10):
            out[k + j] = 0.0
        out[k + 8] = ttop
    out[k + 1] = n + 1.0
    # mass of cable in the water: the segment masses the dynamics use, summed
    out[k + 2] = p[H_MC] * (n - 1) + p[H_MC] * lt / l0
    if BED and p[H_BED] > 0.5:
        out[k + 10] = seabed_depth(p, x[o_uuv], x[o_uuv + 1]) - x[o_uuv + 2]
        cnt = 0
        for i in range(1, n):
            if nodes[3 * i + 2] > seabed_depth(p, nodes[3 * i], nodes[3 * i + 1]) - 1e-3:
                cnt += 1
        out[k + 11] = cnt
    else:
        out[k + 10] = np.nan
        out[k + 11] = 0.0


_UNITS = {
    "x": "m",
    "y": "m",
    "z": "m",
    "psi": "rad",
    "phi": "rad",
    "theta": "rad",
    "u": "m/s",
    "v": "m/s",
    "w": "m/s",
    "p": "rad/s",
    "q": "rad/s",
    "r": "rad/s",
    "speed": "m/s",
    "top_tension": "N",
    "bottom_tension": "N",
    "angle_deg": "deg",
    "length": "m",
    "nodes": "count",
    "mass": "kg",
    "speed_cmd_sat": "m/s",
    "cmd_saturated": "bool",
    "rendering": "bool",
    "at_capacity": "bool",
    "tension": "N",
    "power": "W",
    "altitude": "m",
    "nodes_on_bed": "count",
}


def _unit_of(key: str) -> str:
    body, _, leaf = key.partition(".")
    if body == "cable" and leaf[:1] in "xyz" and leaf[1:].isdigit():
        return "m"
    return _UNITS[leaf]


def output_keys(nmax: int, has_winch: bool, has_bed: bool):
    """(published keys, their indices in the full output vector of :func:`_fill_outputs_var` or None
    without winch and seabed, length of that full vector)."""
    base = [
        *(f"usv.{s}" for s in USV_STATES),
        "usv.speed",
        *(f"uuv.{s}" for s in UUV_STATES),
        "uuv.speed",
        "cable.top_tension",
        "cable.bottom_tension",
        "cable.angle_deg",
        *(f"cable.{a}{i}" for i in range(nmax + 1) for a in "xyz"),
    ]
    keys = list(base)
    idx = None
    if has_winch or has_bed:
        keys += [
            k
            for k in VAR_KEYS
            if (has_winch or not k.startswith("winch.") or k == "winch.tension")
            and (has_bed or k not in ("uuv.altitude", "cable.nodes_on_bed"))
        ]
        full = base + VAR_KEYS
        idx = np.array([full.index(k) for k in keys])
    return keys, idx, len(base) + len(VAR_KEYS)
