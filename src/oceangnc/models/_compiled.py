"""Compiled forms of actuator blocks, environment blocks and plant outputs for the fused loop.

Kernel convention: :mod:`oceangnc.core.fused` (``kernel(t, sig, slots, state, params)``). Plants are
integrated in the fused loop with their own compiled steppers; what is here publishes their outputs into the signal array in the
order of the Python ``publish``. The ship's (``ship_publish``) is in :mod:`oceangnc.models.ship_lowspeed`,
so that other scenarios do not import the ship model.
"""

from __future__ import annotations

import math

from numba import njit


@njit(cache=True)
def constant_current_step(t, sig, sl, st, pa):
    """:class:`oceangnc.environment.OceanCurrent` with ``model = "constant"``: params speed, direction (rad)."""
    sig[sl[0]] = pa[0] * math.cos(pa[1])
    sig[sl[1]] = pa[0] * math.sin(pa[1])
    sig[sl[2]] = pa[0]
    sig[sl[3]] = math.degrees(pa[1])


@njit(cache=True)
def steady_wind_step(t, sig, sl, st, pa):
    """:class:`oceangnc.environment.Wind` without gusts: params speed, direction from (deg)."""
    speed = max(0.0, pa[0] + 0.0)
    to = math.radians(pa[1]) + math.pi
    sig[sl[0]] = speed * math.cos(to)
    sig[sl[1]] = speed * math.sin(to)
    sig[sl[2]] = speed
    sig[sl[3]] = pa[1]
