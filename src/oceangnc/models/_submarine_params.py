"""The submarine's published coefficients (002 tables 5.2/5.3, the published EKF estimates), their
non-dimensional scale powers, and :class:`SubmarineVerticalConfig` (002 table 4.1). Re-exported by
:mod:`oceangnc.models.submarine_vertical`.
"""

from __future__ import annotations
import numpy as np
from pydantic import Field
from ..core.model import Param, ParamLayout
from ..io.config import StrictModel

COEFF_NAMES = ("Zw", "Zwdot", "Zq", "Zqdot", "Zds", "Mw", "Mwdot", "Mq", "Mqdot", "Mds")
CONST_NAMES = ("m", "Iy_nd", "W", "B", "xG", "zG", "rho", "L", "U")
#: parameter layout, generated from the declared names (002 table 2.1 primes, then table 4.1 constants)
LAYOUT = ParamLayout(
    [Param(k, "1", description=f"{k}' (002 table 2.1 scaling)") for k in COEFF_NAMES]
    + [
        Param("m", "kg"),
        Param("Iy_nd", "1"),
        Param("W", "N"),
        Param("B", "N"),
        Param("xG", "m"),
        Param("zG", "m"),
        Param("rho", "kg/m^3"),
        Param("L", "m"),
        Param("U", "m/s"),
    ]
)
P_NAMES = LAYOUT.names


#: True non-dimensional coefficients, 002 tables 5.2 and 5.3 (M_w' with the physical + sign).
TRUE_COEFFS = {
    "Zw": -0.01991,
    "Zwdot": -0.01258,
    "Zq": -0.006371,
    "Zqdot": -0.000016,
    "Zds": -0.008791,
    "Mw": 0.004059,
    "Mwdot": -0.004970,
    "Mq": -0.002995,
    "Mqdot": -0.005198,
    "Mds": -0.003663,
}
#: The truncated values of 002 table 4.1 (used as a possible set of initial guesses).
TABLE41_COEFFS = {
    "Zw": -0.019,
    "Zwdot": -0.0125,
    "Zq": -0.0063,
    "Zqdot": -0.00001,
    "Zds": -0.0087,
    "Mw": 0.004,
    "Mwdot": -0.0049,
    "Mq": -0.0029,
    "Mqdot": -0.0051,
    "Mds": -0.0036,
}
#: Published estimates, 002 tables 5.2/5.3: (5-5 zig-zag, 10-5 zig-zag).
PUBLISHED_ESTIMATES = {
    "Zw": (-0.01989, -0.01990),
    "Zwdot": (-0.01256, -0.01250),
    "Zq": (-0.00634, -0.00629),
    "Zqdot": (-0.0000159, -0.0000154),
    "Zds": (-0.00874, -0.00871),
    "Mw": (0.004051, 0.004060),
    "Mwdot": (-0.004965, -0.004967),
    "Mq": (-0.002990, -0.002992),
    "Mqdot": (-0.005195, -0.005192),
    "Mds": (-0.003661, -0.00362),
}
#: Table 2.1 scale of each coefficient: (power of L, power of U) in rho/2 L^a U^b.
SCALE_POWERS = {
    "Zw": (2, 1),
    "Zwdot": (3, 0),
    "Zq": (3, 1),
    "Zqdot": (4, 0),
    "Zds": (2, 2),
    "Mw": (3, 1),
    "Mwdot": (4, 0),
    "Mq": (4, 1),
    "Mqdot": (5, 0),
    "Mds": (3, 2),
}


class SubmarineVerticalConfig(StrictModel):
    """Constants of 002 table 4.1 and the true coefficients of tables 5.2/5.3 (non-dimensional)."""

    U: float = Field(3.084, gt=0, le=30, description="constant forward speed, m/s")
    m: float = Field(293160.0, gt=0, le=1e8, description="mass, kg")
    Iy_nd: float = Field(0.0006088, gt=0, le=1, description="pitch inertia I_y / (rho/2 L^5), -")
    W: float = Field(2872968.0, gt=0, le=1e9, description="weight, N")
    B: float = Field(2872968.0, gt=0, le=1e9, description="buoyancy, N")
    xG: float = Field(0.0, ge=-50, le=50, description="longitudinal CG position from the CB, m")
    zG: float = Field(0.27414, ge=-5, le=5, description="vertical CG position below the CB (BG), m")
    rho: float = Field(1025.9, gt=900, le=1100, description="water density, kg/m^3")
    L: float = Field(63.955, gt=0, le=500, description="length, m")
    Zw: float = Field(TRUE_COEFFS["Zw"], ge=-1, le=1, description="Z_w', -")
    Zwdot: float = Field(TRUE_COEFFS["Zwdot"], ge=-1, le=1, description="Z_wdot', -")
    Zq: float = Field(TRUE_COEFFS["Zq"], ge=-1, le=1, description="Z_q', -")
    Zqdot: float = Field(TRUE_COEFFS["Zqdot"], ge=-1, le=1, description="Z_qdot', -")
    Zds: float = Field(TRUE_COEFFS["Zds"], ge=-1, le=1, description="Z_ds', -")
    Mw: float = Field(TRUE_COEFFS["Mw"], ge=-1, le=1, description="M_w' (Munk moment, positive), -")
    Mwdot: float = Field(TRUE_COEFFS["Mwdot"], ge=-1, le=1, description="M_wdot', -")
    Mq: float = Field(TRUE_COEFFS["Mq"], ge=-1, le=1, description="M_q', -")
    Mqdot: float = Field(TRUE_COEFFS["Mqdot"], ge=-1, le=1, description="M_qdot', -")
    Mds: float = Field(TRUE_COEFFS["Mds"], ge=-1, le=1, description="M_ds', -")
    w0: float = Field(0.028, ge=-5, le=5, description="initial heave velocity (table 4.1), m/s")
    theta0_deg: float = Field(0.0, ge=-90, le=90, description="initial pitch, deg")
    q0_degps: float = Field(0.0, ge=-90, le=90, description="initial pitch rate, deg/s")
    z0: float = Field(20.0, ge=0, le=1e4, description="initial depth (table 4.1), m")

    def params(self) -> np.ndarray:
        """Flat parameter array in the layout of :data:`P_NAMES`."""
        return np.array([getattr(self, k) for k in P_NAMES], dtype=np.float64)

    def x0(self) -> np.ndarray:
        """Initial plant state [w, theta, q, z]."""
        return np.array([self.w0, np.radians(self.theta0_deg), np.radians(self.q0_degps), self.z0])
