"""Compiled GPS with the white-noise error model and outage windows (either error model) for the
fused loop (issue 19; kernel convention: :mod:`oceangnc.sensors._compiled`, which holds the
Gauss-Markov model without outages).

The draws are those of :meth:`oceangnc.sensors.gps.GPS._fix` in the same order from the block's
own generator (white: two normals per fix, none when sigma = 0 or inside an outage), so the fixes are
identical on both paths for a given seed.
"""

from __future__ import annotations

from numba import njit

from ._compiled import gps_bias_fix, gps_publish


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
        x, y = gps_bias_fix(sig, sl, st, pa, rng)
    gps_publish(t, sig, sl, st, pa, x, y)
