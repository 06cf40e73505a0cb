"""Compiled GPS with the white-noise error model and outage windows (either error model) for the
fused loop (issue 19; kernel convention: :mod:`oceangnc.sensors._compiled`, which holds the
Gauss-Markov model without outages).

The draws are those of :meth:`oceangnc.sensors.gps.GPS._fix` in the same order from the block's
own generator (white: two normals per fix, none when sigma = 0 or inside an outage), so the fixes are
identical on both paths for a given seed.
"""

from __future__ import annotations

import math

from numba import njit


@njit(cache=True)
def gps_fix_step(t, sig, sl, st, pa, rng):
    """:class:`oceangnc.sensors.gps.GPS`, both error models, with outages.

    slots: body.x, body.y | x, y, sog, cog, cog_valid, valid, hdop. state: bias n, bias e, cog,
    count, head, then the track history ring (t, x, y) x n. params: period, bias time constant,
    sigma_b, jitter, min_track, hdop, n, white (1/0), sigma, m outages, then (start, end) x m.
    """
    m = int(pa[9])
    for i in range(m):
        if pa[10 + 2 * i] <= t < pa[11 + 2 * i]:
            sig[sl[7]] = 0.0
            return
    if pa[7] != 0.0:
        x = sig[sl[0]]
        y = sig[sl[1]]
        if pa[8] > 0:
            x = x + rng.normal(0.0, pa[8])
            y = y + rng.normal(0.0, pa[8])
    else:
        a = math.exp(-pa[0] / pa[1])
        q = pa[2] * math.sqrt(1.0 - a * a)
        w0 = rng.standard_normal()
        w1 = rng.standard_normal()
        w2 = rng.standard_normal()
        w3 = rng.standard_normal()
        st[0] = a * st[0] + q * w0
        st[1] = a * st[1] + q * w1
        x = sig[sl[0]] + st[0] + pa[3] * w2
        y = sig[sl[1]] + st[1] + pa[3] * w3
    n = int(pa[6])
    count = int(st[3])
    head = int(st[4])
    if count < n:
        j = (head + count) % n
        count += 1
    else:
        j = head
        head = (head + 1) % n
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
