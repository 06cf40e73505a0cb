"""The linear dispersion relation of surface gravity waves in finite depth (Airy theory; DNV-RP-C205
sec. 3.2.2): the one home of the wave number, used by the wave field and by the sea's limits."""

from __future__ import annotations

import numpy as np

from ..units import G


def wave_number(omega, depth: float):
    """Wave numbers k (rad/m) of angular frequencies ``omega`` (rad/s) in water of ``depth`` (m):
    omega^2 = g k tanh(k h), by Newton from the deep-water value."""
    w = np.atleast_1d(np.asarray(omega, dtype=np.float64))
    k = w**2 / G
    for _ in range(50):
        th = np.tanh(k * depth)
        f = G * k * th - w**2
        df = G * th + G * k * depth * (1.0 - th**2)
        step = f / df
        k = k - step
        if np.all(np.abs(step) <= 1e-14 * k):
            break
    return k
