"""Compiled forms of the sensor blocks (kernel convention: :mod:`oceangnc.control._compiled`).

Sensor kernels take a seventh argument, the block's own ``numpy.random.Generator`` (numba draws
from the very same generator object with NumPy's algorithms), and make the same draws in the same
order as the Python blocks, so noise and dropouts are identical on both paths for a given seed.
"""

from __future__ import annotations

import math

from numba import njit

from .filters import gauss_markov


@njit(cache=True)
def ring_slot(count, head, cap):
    """Slot for a new entry of a ring buffer of ``cap`` entries holding ``count`` from ``head`` (the
    oldest); returns (slot, new count, new head): a full buffer overwrites its oldest entry."""
    if count < cap:
        return (head + count) % cap, count + 1, head
    return head, count, (head + 1) % cap


@njit(cache=True)
def _get(sig, s, default):
    return sig[s] if s >= 0 else default


@njit(cache=True)
def gps_step(t, sig, sl, st, pa, rng):
    """:class:`oceangnc.sensors.gps.GPS` (003 ch. 6.1.1).

    slots: body.x, body.y | x, y, sog, cog, cog_valid, valid, hdop. state: bias n, bias e, cog,
    count, head, then the track history ring (t, x, y) x n. params: period, bias time constant,
    sigma_b, jitter, min_track, hdop, n.
    """
    x, y = gps_bias_fix(sig, sl, st, pa, rng)
    gps_publish(t, sig, sl, st, pa, x, y)


@njit(cache=True)
def gps_bias_fix(sig, sl, st, pa, rng):
    """One fix (m, NED) with the Gauss-Markov bias (state ``st[0:2]``) and white jitter, drawing in the
    order of :meth:`oceangnc.sensors.gps.GPS._fix`."""
    a = math.exp(-pa[0] / pa[1])
    w0 = rng.standard_normal()
    w1 = rng.standard_normal()
    w2 = rng.standard_normal()
    w3 = rng.standard_normal()
    st[0] = gauss_markov(st[0], a, pa[2], w0)
    st[1] = gauss_markov(st[1], a, pa[2], w1)
    return sig[sl[0]] + st[0] + pa[3] * w2, sig[sl[1]] + st[1] + pa[3] * w3


@njit(cache=True)
def gps_publish(t, sig, sl, st, pa, x, y):
    """The fix (x, y) into the track-history ring, the course and speed over ground from the oldest
    entry, and the GPS outputs (slots and state as :func:`gps_step`)."""
    n = int(pa[6])
    count = int(st[3])
    head = int(st[4])
    j, count, head = ring_slot(count, head, n)
    st[5 + 3 * j] = t
    st[6 + 3 * j] = x
    st[7 + 3 * j] = y
    st[3] = count
    st[4] = head
    t0 = st[5 + 3 * head]
    x0 = st[6 + 3 * head]
    y0 = st[7 + 3 * head]
    dn, de = x - x0, y - y0
    dist = math.hypot(dn, de)
    span = t - t0
    valid_cog = dist > pa[4] and span > 0
    if valid_cog:
        st[2] = math.atan2(de, dn)
    sig[sl[2]] = x
    sig[sl[3]] = y
    sig[sl[4]] = dist / span if span > 0 else 0.0
    sig[sl[5]] = st[2]
    sig[sl[6]] = 1.0 if valid_cog else 0.0
    sig[sl[7]] = 1.0
    sig[sl[8]] = pa[5]


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
