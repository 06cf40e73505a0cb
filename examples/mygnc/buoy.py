"""A spar buoy in heave: m_total z'' = -rho g A_wp z - b z' + F (z down, m; F the winch force, N):
a plant in one file, with its declared states, inputs and parameters (oceangnc.core.model.Model)."""

import numpy as np
from numba import njit

from oceangnc.core.model import Model, ParamLayout

LAYOUT = ParamLayout([("m_total", "kg"), ("k_heave", "N/m"), ("b", "N s/m")])
M, K, B = LAYOUT.indices("m_total", "k_heave", "b")


@njit(cache=True)
def buoy_rhs(t, x, u, p, out):
    """dx/dt for x = [z (m), w (m/s)] and u = [F (N)]."""
    out[0] = x[1]
    out[1] = (u[0] - p[K] * x[0] - p[B] * x[1]) / p[M]


def buoy_model(m_total=400.0, diameter=0.5, b=300.0) -> Model:
    """The buoy's model: mass with added mass (kg), waterplane stiffness rho g A_wp (N/m), damping (N s/m)."""
    k = 1025.0 * 9.81 * np.pi * diameter**2 / 4
    p = LAYOUT.pack({"m_total": m_total, "k_heave": k, "b": b})
    return Model("buoy", buoy_rhs, [("z", "m"), ("w", "m/s")], [("force", "N")], LAYOUT, p, bound=1e4)
