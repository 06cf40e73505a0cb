"""Ship parameters: state/input names and units, the generated parameter layout :data:`LAYOUT` with
the offsets compiled code uses, and :class:`ShipConfig` (S-175, Son & Nomoto 1981, with thrusters,
lags and limits; docs/berthing.md). Re-exported by :mod:`oceangnc.models.ship_lowspeed`.
"""

from __future__ import annotations
import math
import numpy as np
from pydantic import Field
from ..core.model import Param, ParamLayout
from ..io.config import StrictModel
from ..units import RHO_AIR, RHO_WATER


STATES = (
    ("x", "m"),
    ("y", "m"),
    ("psi", "rad"),
    ("u", "m/s"),
    ("v", "m/s"),
    ("r", "rad/s"),
    ("delta", "rad"),
    ("n", "Hz"),
    ("n_bow", "Hz"),
    ("n_stern", "Hz"),
)  # shaft speeds in rev/s
INPUTS = (
    ("rudder_cmd", "rad"),
    ("n_prop_cmd", "Hz"),
    ("n_bow_cmd", "Hz"),
    ("n_stern_cmd", "Hz"),
    ("current_n", "m/s"),
    ("current_e", "m/s"),
    ("wind_n", "m/s"),
    ("wind_e", "m/s"),
)
STATE_NAMES = tuple(k for k, _ in STATES)
INPUT_NAMES = (
    "ship.rudder_cmd",
    "ship.n_prop_cmd",
    "ship.n_bow_cmd",
    "ship.n_stern_cmd",
    "env.current_n",
    "env.current_e",
    "env.wind_n",
    "env.wind_e",
)

#: parameter layout of :meth:`ShipConfig.params` (dimensional, SI), generated from the declared names
LAYOUT = ParamLayout(
    [
        Param(k, u)
        for k, u in (
            ("L", "m"),
            ("T", "m"),
            ("rho", "kg/m^3"),
            ("m", "kg"),
            ("xG", "m"),
            ("m11", "kg"),
            ("M1_11", "kg"),
            ("M1_12", "kg m"),
            ("M1_21", "kg m"),
            ("M1_22", "kg m^2"),
            ("X_uu", "kg/m"),
            ("X_vr", "kg"),
            ("X_vv", "kg/m"),
            ("X_rr", "kg m"),
            ("Y_v", "kg/m"),
            ("Y_r", "kg"),
            ("m_x", "kg"),
            ("Nv_drift", "kg"),
            ("N_r", "kg m"),
            ("alpha0", "rad"),
            ("C_D", "1"),
            ("C_Yr", "1"),
            ("C_Nr", "1"),
            ("A_R", "m^2"),
            ("f_alpha", "1"),
            ("t_R", "1"),
            ("a_H", "1"),
            ("x_H", "m"),
            ("x_R", "m"),
            ("gamma_R", "1"),
            ("c_Rr", "1"),
            ("eps", "1"),
            ("kappa", "1"),
            ("D", "m"),
            ("t_p", "1"),
            ("w_p", "1"),
            ("a1", "1"),
            ("a2", "1"),
            ("a3", "1"),
            ("b_B", "N s^2"),
            ("b_S", "N s^2"),
            ("x_TB", "m"),
            ("x_TS", "m"),
            ("tau_p", "s"),
            ("tau_d", "s"),
            ("tau_tb", "s"),
            ("tau_ts", "s"),
            ("n_max", "rev/s"),
            ("delta_max", "rad"),
            ("delta_rate", "rad/s"),
            ("nB_max", "rev/s"),
            ("nS_max", "rev/s"),
            ("rho_air", "kg/m^3"),
            ("A_F", "m^2"),
            ("A_L", "m^2"),
            ("L_oa", "m"),
            ("c_x", "1"),
            ("c_y", "1"),
            ("c_n", "1"),
        )
    ]
)
P_NAMES = LAYOUT.names
P = {k: LAYOUT.index(k) for k in P_NAMES}


class ShipConfig(StrictModel):
    """S-175 container ship (Son & Nomoto 1981) with thrusters, lags and limits; see docs/berthing.md."""

    length: float = Field(175.0, gt=10, le=500, description="length between perpendiculars L, m")
    beam: float = Field(25.4, gt=1, le=80, description="beam B, m")
    draft: float = Field(8.5, gt=0.5, le=30, description="mean draft T, m")
    displacement: float = Field(21222.0, gt=10, le=1e6, description="displacement volume, m3")
    x_g: float = Field(0.0, ge=-20, le=20, description="longitudinal centre of gravity from midship, m")
    rho: float = Field(RHO_WATER, gt=900, le=1100, description="water density, kg/m3")
    # Son & Nomoto (1981) non-dimensional (prime) coefficients, forces on rho/2 L^2 U^2,
    # moments on rho/2 L^3 U^2, masses on rho/2 L^3, inertias on rho/2 L^5
    mx_p: float = Field(0.000238, ge=0, le=0.1, description="surge added mass m_x' = -X_udot', -")
    my_p: float = Field(0.007049, ge=0, le=0.1, description="sway added mass m_y' = -Y_vdot', -")
    iz_p: float = Field(0.000456, gt=0, le=0.1, description="yaw inertia I_z', -")
    jz_p: float = Field(0.000419, ge=0, le=0.1, description="added yaw inertia J_z' = -N_rdot', -")
    yrdot_p: float = Field(-0.000502, ge=-0.01, le=0.01, description="Y_rdot' (Clarke et al. 1983), -")
    nvdot_p: float = Field(-0.000275, ge=-0.01, le=0.01, description="N_vdot' (Clarke et al. 1983), -")
    xuu_p: float = Field(-0.0004226, ge=-0.1, le=0, description="X'_uu resistance, -")
    xvr_p: float = Field(-0.00311, ge=-0.1, le=0.1, description="X'_vr, -")
    xvv_p: float = Field(-0.00386, ge=-0.1, le=0.1, description="X'_vv, -")
    xrr_p: float = Field(0.00020, ge=-0.1, le=0.1, description="X'_rr, -")
    yv_p: float = Field(-0.0116, ge=-0.1, le=0, description="Y'_v, -")
    yr_p: float = Field(0.00242, ge=-0.1, le=0.1, description="Y'_r, -")
    nv_p: float = Field(-0.0038545, ge=-0.1, le=0.1, description="N'_v, -")
    nr_p: float = Field(-0.00222, ge=-0.1, le=0, description="N'_r, -")
    alpha0_deg: float = Field(85.0, gt=45, lt=135, description="drift angle of zero hull yaw moment alpha_0, deg")
    c_d: float = Field(1.0, ge=0, le=2, description="cross-flow drag coefficient C_Dv, -")
    c_yr: float = Field(1.0, ge=0, le=2, description="yaw factor C_Yr in the sway cross-flow integral, -")
    c_nr: float = Field(1.0, ge=0, le=2, description="yaw factor C_Nr in the yaw cross-flow integral, -")
    # rudder (Son & Nomoto)
    rudder_area: float = Field(33.0376, gt=0, le=500, description="rudder area A_R, m2")
    rudder_aspect: float = Field(1.8219, gt=0.2, le=6, description="rudder aspect ratio Lambda, -")
    t_r: float = Field(0.29, ge=0, lt=1, description="steering resistance deduction t_R (1 - 0.71), -")
    a_h: float = Field(0.237, ge=0, le=1, description="rudder force increase factor a_H, -")
    x_h_p: float = Field(-0.48, ge=-1, le=0, description="x'_H, acting point of the hull-induced force / L, -")
    x_r_p: float = Field(-0.5, ge=-1, le=0, description="x'_R, rudder position / L, -")
    gamma_r: float = Field(0.088, ge=0, le=1, description="flow straightening of sway at the rudder gamma_R, -")
    c_rr: float = Field(-0.156, ge=-1, le=1, description="yaw term of the rudder inflow c_Rr, -")
    epsilon: float = Field(0.921, gt=0, le=2, description="wake ratio at rudder/propeller epsilon, -")
    kappa: float = Field(0.631, ge=0, le=2, description="propeller race factor kappa, -")
    # propeller (Son & Nomoto): K_T = 0.527 - 0.455 J
    prop_diameter: float = Field(6.533, gt=0.1, le=15, description="propeller diameter D, m")
    t_p: float = Field(0.175, ge=0, lt=1, description="thrust deduction t_p, -")
    w_p: float = Field(0.184, ge=0, lt=1, description="wake fraction w_p, -")
    kt_a1: float = Field(0.527, gt=0, le=1, description="K_T = a1 + a2 J + a3 J^2: a1, -")
    kt_a2: float = Field(-0.455, ge=-2, le=0, description="K_T coefficient a2, -")
    kt_a3: float = Field(0.0, ge=-2, le=2, description="K_T coefficient a3, -")
    n_max_rpm: float = Field(160.0, gt=0, le=1000, description="propeller shaft speed limit, rpm")
    # thrusters (chosen: ~20 tf tunnel thrusters of ~1500 kW)
    thruster_force_kn: float = Field(200.0, gt=0, le=2000, description="bow/stern thruster force at full rpm, kN")
    thruster_rpm_max: float = Field(250.0, gt=0, le=3000, description="thruster speed limit, rpm")
    x_tb: float = Field(73.5, ge=0, le=250, description="bow thruster position from midship x_TB, m")
    x_ts: float = Field(-73.5, ge=-250, le=0, description="stern thruster position from midship x_TS, m")
    # actuator lags and limits
    tau_prop: float = Field(6.0, ge=0.01, le=100, description="propeller time constant tau_P, s")
    tau_rudder: float = Field(1.0, ge=0.01, le=100, description="rudder time constant tau_delta, s")
    tau_thruster: float = Field(3.0, ge=0.01, le=100, description="thruster time constants tau_tB = tau_tS, s")
    rudder_max_deg: float = Field(35.0, gt=0, le=45, description="rudder angle limit, deg")
    rudder_rate_degps: float = Field(2.32, gt=0, le=100, description="rudder rate limit (IMO 35-30 deg in 28 s), deg/s")
    # windage
    rho_air: float = Field(RHO_AIR, gt=0, le=2, description="air density, kg/m3")
    area_front: float = Field(500.0, gt=0, le=1e4, description="frontal windage area A_F, m2")
    area_side: float = Field(2500.0, gt=0, le=1e5, description="lateral windage area A_L, m2")
    c_x: float = Field(0.7, ge=0, le=2, description="wind surge coefficient, -")
    c_y: float = Field(0.85, ge=0, le=2, description="wind sway coefficient, -")
    c_n: float = Field(0.10, ge=0, le=1, description="wind yaw coefficient, -")
    # initial state
    x0: float = Field(0.0, ge=-1e6, le=1e6, description="initial north position, m")
    y0: float = Field(0.0, ge=-1e6, le=1e6, description="initial east position, m")
    psi0_deg: float = Field(0.0, ge=-360, le=360, description="initial heading, deg")
    u0: float = Field(0.0, ge=-5, le=15, description="initial surge speed, m/s")
    n0_rpm: float = Field(0.0, ge=-1000, le=1000, description="initial propeller speed, rpm")

    @property
    def mass(self) -> float:
        """Ship mass rho * displacement, kg."""
        return self.rho * self.displacement

    def params(self) -> np.ndarray:
        """Flat parameter array in the layout :data:`P_NAMES` (dimensional, SI)."""
        L, T, rho = self.length, self.draft, self.rho
        q2, q3, q4, q5 = 0.5 * rho * L**2, 0.5 * rho * L**3, 0.5 * rho * L**4, 0.5 * rho * L**5
        m = self.mass
        mx = self.mx_p * q3
        my = self.my_p * q3
        iz = self.iz_p * q5
        jz = self.jz_p * q5
        yrdot = self.yrdot_p * q4
        nvdot = self.nvdot_p * q4
        lam = self.rudder_aspect
        nmax = self.n_max_rpm / 60.0
        ntmax = self.thruster_rpm_max / 60.0
        b = self.thruster_force_kn * 1e3 / ntmax**2
        vals = {
            "L": L,
            "T": T,
            "rho": rho,
            "m": m,
            "xG": self.x_g,
            "m11": m + mx,
            "M1_11": m + my,
            "M1_12": m * self.x_g - yrdot,
            "M1_21": m * self.x_g - nvdot,
            "M1_22": iz + jz,
            "X_uu": self.xuu_p * q2,
            "X_vr": (self.xvr_p + self.my_p) * q3,
            "X_vv": self.xvv_p * q2,
            "X_rr": self.xrr_p * q4,
            "Y_v": self.yv_p * q2,
            "Y_r": self.yr_p * q3,
            "m_x": mx,
            "Nv_drift": self.nv_p * q3,
            "N_r": self.nr_p * q4,
            "alpha0": math.radians(self.alpha0_deg),
            "C_D": self.c_d,
            "C_Yr": self.c_yr,
            "C_Nr": self.c_nr,
            "A_R": self.rudder_area,
            "f_alpha": 6.13 * lam / (lam + 2.25),
            "t_R": self.t_r,
            "a_H": self.a_h,
            "x_H": self.x_h_p * L,
            "x_R": self.x_r_p * L,
            "gamma_R": self.gamma_r,
            "c_Rr": self.c_rr,
            "eps": self.epsilon,
            "kappa": self.kappa,
            "D": self.prop_diameter,
            "t_p": self.t_p,
            "w_p": self.w_p,
            "a1": self.kt_a1,
            "a2": self.kt_a2,
            "a3": self.kt_a3,
            "b_B": b,
            "b_S": b,
            "x_TB": self.x_tb,
            "x_TS": self.x_ts,
            "tau_p": self.tau_prop,
            "tau_d": self.tau_rudder,
            "tau_tb": self.tau_thruster,
            "tau_ts": self.tau_thruster,
            "n_max": nmax,
            "delta_max": math.radians(self.rudder_max_deg),
            "delta_rate": math.radians(self.rudder_rate_degps),
            "nB_max": ntmax,
            "nS_max": ntmax,
            "rho_air": self.rho_air,
            "A_F": self.area_front,
            "A_L": self.area_side,
            "L_oa": L,
            "c_x": self.c_x,
            "c_y": self.c_y,
            "c_n": self.c_n,
        }
        return LAYOUT.pack(vals)


# -- force components ------------------------------------------------------------------------------
