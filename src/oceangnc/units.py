"""Unit conversions used at the edges only (inputs, outputs, configs that speak the user's units).

Everything inside oceangnc is SI: m, s, kg, N, rad. Names carry their unit suffix where it is not SI
(``direction_deg``, ``thrust_kgf``, ``speed_kn``).
"""

from __future__ import annotations

import math

G = 9.80665  #: standard gravity, m/s^2
KGF = G  #: one kilogram-force in N
KNOT = 1852.0 / 3600.0  #: one knot in m/s
RPM = 2.0 * math.pi / 60.0  #: one rev/min in rad/s
DEG = math.pi / 180.0  #: one degree in rad
RHO_WATER = 1025.0  #: sea water density, kg/m^3
RHO_AIR = 1.225  #: air density at 15 degC, kg/m^3


def kgf_to_n(kgf):
    """kilogram-force -> newton."""
    return kgf * KGF


def n_to_kgf(n):
    """newton -> kilogram-force."""
    return n / KGF


def knots_to_mps(kn):
    """knots -> m/s."""
    return kn * KNOT


def mps_to_knots(v):
    """m/s -> knots."""
    return v / KNOT


def rpm_to_rad_s(rpm):
    """rev/min -> rad/s."""
    return rpm * RPM


def wrap_angle(a):
    """Wrap an angle (rad, scalar or array) to (-pi, pi]: :func:`oceangnc.core.rotations.wrap_array`."""
    from .core.rotations import wrap_array

    return wrap_array(a)
