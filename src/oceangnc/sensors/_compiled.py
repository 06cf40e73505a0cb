"""Compiled forms of the sensor blocks (kernel convention: :mod:`oceangnc.control._compiled`).

Sensor kernels take a seventh argument, the block's own ``numpy.random.Generator`` (numba draws
from the very same generator object with NumPy's algorithms), and make the same draws in the same
order as the Python blocks, so noise and dropouts are identical on both paths for a given seed.
"""

from __future__ import annotations

from numba import njit


@njit(cache=True)
def _get(sig, s, default):
    return sig[s] if s >= 0 else default


@njit(cache=True)
def nav_step(t, sig, sl, st, pa):
    """The field test's navigation: USV from the GPS, UUV = USV + held USBL offset.

    slots: ?gps.x, ?gps.y, ?nav.usbl.dn, ?nav.usbl.de, ?gps.sog | nav.usv_x, nav.usv_y, nav.uuv_x,
    nav.uuv_y, nav.usv_u.
    """
    x = _get(sig, sl[0], 0.0)
    y = _get(sig, sl[1], 0.0)
    sig[sl[5]] = x
    sig[sl[6]] = y
    sig[sl[7]] = sig[sl[5]] + _get(sig, sl[2], 0.0)
    sig[sl[8]] = sig[sl[6]] + _get(sig, sl[3], 0.0)
    sig[sl[9]] = _get(sig, sl[4], 0.0)
