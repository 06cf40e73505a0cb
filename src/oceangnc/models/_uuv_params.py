"""UUV parameters: state/input names, the REMUS-100 coefficients of Prestero (2001) scaled to this
vehicle, the generated parameter layout :data:`LAYOUT` (with the ``P_*`` offsets compiled code uses) and
:class:`UUVConfig` (003 ch. 2.2, table 2-5). Re-exported by :mod:`oceangnc.models.uuv`.
"""

from __future__ import annotations
import math
import numpy as np
from pydantic import Field
from ..core.model import Param, ParamLayout
from ..io.config import StrictModel
from ..units import KGF, RHO_WATER, G
from .actuators import UUV_T_FWD_N, UUV_T_REV_N


STATE_NAMES = ("x", "y", "z", "phi", "theta", "psi", "u", "v", "w", "p", "q", "r")
INPUT_NAMES = ("uuv.thrust_port", "uuv.thrust_stbd", "uuv.thrust_bow", "env.current_n", "env.current_e")

#: REMUS-100 coefficients of Prestero (2001) (SI, SNAME names; "uu" = u|u|), and the exponents
#: (a, b) of the length and diameter scale factors used to carry them to this vehicle.
REMUS_PRESTERO = {
    # added mass
    "X_udot": (-0.93, 1, 2),
    "Y_vdot": (-35.5, 1, 2),
    "Z_wdot": (-35.5, 1, 2),
    "K_pdot": (-0.0704, 1, 4),
    "M_qdot": (-4.88, 3, 2),
    "N_rdot": (-4.88, 3, 2),
    "Y_rdot": (1.93, 2, 2),
    "Z_qdot": (-1.93, 2, 2),
    "M_wdot": (-1.93, 2, 2),
    "N_vdot": (1.93, 2, 2),
    # quadratic (cross-flow and axial) drag
    "X_uu": (-1.62, 0, 2),
    "Y_vv": (-131.0, 1, 1),
    "Z_ww": (-131.0, 1, 1),
    "K_pp": (-0.130, 1, 4),
    "M_qq": (-188.0, 4, 1),
    "N_rr": (-94.0, 4, 1),
    # totals of body lift, fin lift and added-mass cross terms (Munk moment etc.)
    "Y_uv": (-28.6, 0, 2),
    "Z_uw": (-28.6, 0, 2),
    "M_uw": (24.0, 1, 2),
    "N_uv": (-24.0, 1, 2),
    "Y_ur": (5.22, 1, 2),
    "Z_uq": (-5.22, 1, 2),
    "M_uq": (-2.0, 2, 2),
    "N_ur": (-2.0, 2, 2),
}
REMUS_LENGTH = 1.33  # m, Prestero 2001 table 2-1 (1.33 m)
REMUS_DIAMETER = 0.191  # m

STATES = (
    ("x", "m"),
    ("y", "m"),
    ("z", "m"),
    ("phi", "rad"),
    ("theta", "rad"),
    ("psi", "rad"),
    ("u", "m/s"),
    ("v", "m/s"),
    ("w", "m/s"),
    ("p", "rad/s"),
    ("q", "rad/s"),
    ("r", "rad/s"),
)
INPUTS = (("thrust_port", "N"), ("thrust_stbd", "N"), ("thrust_bow", "N"), ("current_n", "m/s"), ("current_e", "m/s"))
DLIN_NAMES = ("X_u", "Y_v", "Z_w", "K_p", "M_q", "N_r")
DQUAD_NAMES = ("X_uu", "Y_vv", "Z_ww", "K_pp", "M_qq", "N_rr")
LIFT_NAMES = ("Y_uv", "Y_ur", "Z_uw", "Z_uq", "M_uw", "M_uq", "N_uv", "N_ur")
_DLIN_UNITS = ("N s/m", "N s/m", "N s/m", "N m s", "N m s", "N m s")
_DQUAD_UNITS = ("kg/m", "kg/m", "kg/m", "kg m^2", "kg m^2", "kg m^2")
_LIFT_UNITS = ("kg/m", "kg", "kg/m", "kg", "kg", "kg m", "kg", "kg m")

#: parameter layout (003 appendix A), generated from the declared names
LAYOUT = ParamLayout(
    [
        Param("W", "N", description="weight m g"),
        Param("B", "N", description="buoyancy"),
        Param("r_g", "m", 3, description="centre of gravity (body axes, from the CB)"),
        Param("r_b", "m", 3, description="centre of buoyancy"),
        Param("M_RB", "kg, kg m, kg m^2", 36, description="rigid-body mass matrix, row-major (A-7)"),
        Param("M_A", "kg, kg m, kg m^2", 36, description="added-mass matrix, row-major (A-9)"),
        Param("M_inv", "1/kg ...", 36, derived=True, description="(M_RB + M_A)^-1, row-major"),
        *[Param(k, u, description="linear damping (A-11)") for k, u in zip(DLIN_NAMES, _DLIN_UNITS)],
        *[Param(k, u, description="quadratic damping (A-12)") for k, u in zip(DQUAD_NAMES, _DQUAD_UNITS)],
        *[Param(k, u, description="body/fin lift (Prestero) times |u_r|") for k, u in zip(LIFT_NAMES, _LIFT_UNITS)],
        Param("stern_half", "m", description="half the stern thruster spacing"),
        Param("bow_x", "m", description="bow thruster position ahead of the CB"),
        Param("r_c", "m", 3, description="tow point (body axes)"),
    ]
)
P_W, P_B, P_RG, P_RB, P_MRB, P_MA, P_MINV = LAYOUT.indices("W", "B", "r_g", "r_b", "M_RB", "M_A", "M_inv")
P_DLIN = LAYOUT.index(DLIN_NAMES[0])  # the six linear terms, consecutive
P_DQUAD = LAYOUT.index(DQUAD_NAMES[0])  # the six quadratic terms
P_LIFT = LAYOUT.index(LIFT_NAMES[0])  # the eight lift terms
P_STERN_HALF, P_BOW_X, P_RC = LAYOUT.indices("stern_half", "bow_x", "r_c")
NP = LAYOUT.size


def scaled_coefficients(length: float, diameter: float) -> dict[str, float]:
    """Prestero's REMUS-100 coefficients carried to a vehicle of ``length`` x ``diameter`` (m)."""
    sl = length / REMUS_LENGTH
    sd = diameter / REMUS_DIAMETER
    return {k: v * sl**a * sd**b for k, (v, a, b) in REMUS_PRESTERO.items()}


class UUVConfig(StrictModel):
    """UUV parameters (003 ch. 2.2, table 2-5) and initial state."""

    length: float = Field(1.79, gt=0, le=20, description="hull length (003 table 2-5), m")
    diameter: float = Field(0.25, gt=0, le=5, description="hull diameter (003 table 2-5), m")
    mass: float = Field(30.0, gt=0, le=1e4, description="mass in air (003 table 2-5), kg")
    weight_in_water_kgf: float = Field(
        12.0, ge=-1e3, le=1e4, description="submerged weight W - B (003 table 2-5; > 0 sinks), kgf"
    )
    zg: float = Field(0.02, ge=0.0, le=1.0, description="centre of gravity below the centre of buoyancy, m")
    Ixx: float | None = Field(
        None, gt=0, le=1e4, description="roll inertia about the CG (default: uniform cylinder), kg m2"
    )
    Iyy: float | None = Field(
        None, gt=0, le=1e5, description="pitch inertia about the CG (default: uniform cylinder), kg m2"
    )
    Izz: float | None = Field(
        None, gt=0, le=1e5, description="yaw inertia about the CG (default: uniform cylinder), kg m2"
    )
    X_u: float = Field(-1.0, ge=-1e4, le=0, description="linear surge damping X_u, N s/m")
    Y_v: float = Field(-10.0, ge=-1e4, le=0, description="linear sway damping Y_v, N s/m")
    Z_w: float = Field(-10.0, ge=-1e4, le=0, description="linear heave damping Z_w, N s/m")
    K_p: float = Field(-0.5, ge=-1e4, le=0, description="linear roll damping K_p, N m s")
    M_q: float = Field(-5.0, ge=-1e4, le=0, description="linear pitch damping M_q, N m s")
    N_r: float = Field(-5.0, ge=-1e4, le=0, description="linear yaw damping N_r, N m s")
    appendage_drag_area: float = Field(
        0.03,
        ge=0.0,
        le=10.0,
        description="C_d A of the external thrusters and fittings, added to X_u|u| as -rho C_d A / 2, m2",
    )
    drag_scale: float = Field(
        1.0, ge=0.0, le=100.0, description="multiplier on the quadratic drag and lift coefficients, -"
    )
    damping_on: bool = Field(True, description="hydrodynamic damping and lift (off only for energy checks)")
    stern_spacing: float = Field(0.3, ge=0, le=5, description="lateral spacing of the two stern thrusters, m")
    bow_arm: float = Field(0.7, ge=0, le=10, description="bow thruster position ahead of the CB, B_f, m")
    max_thrust_kgf: float = Field(UUV_T_FWD_N / KGF, gt=0, le=100, description="forward thrust limit, kgf")
    max_reverse_kgf: float = Field(-UUV_T_REV_N / KGF, ge=0, le=100, description="reverse thrust limit, kgf")
    rho_water: float = Field(RHO_WATER, gt=900, le=1100, description="water density, kg/m3")
    x0: float = Field(0.0, ge=-1e6, le=1e6, description="initial north position of the CB, m")
    y0: float = Field(0.0, ge=-1e6, le=1e6, description="initial east position of the CB, m")
    z0: float = Field(3.0, ge=-1.0, le=1e4, description="initial depth of the CB (003 ch. 4: 3 m), m")
    psi0_deg: float = Field(0.0, ge=-360, le=360, description="initial heading, deg")
    u0: float = Field(0.0, ge=-5, le=10, description="initial surge speed, m/s")

    def inertias(self) -> tuple[float, float, float]:
        """(Ixx, Iyy, Izz) in kg m2: given, else those of a uniform solid cylinder."""
        r = 0.5 * self.diameter
        ixx = self.Ixx if self.Ixx is not None else 0.5 * self.mass * r * r
        iyy = self.Iyy if self.Iyy is not None else self.mass * (3 * r * r + self.length**2) / 12.0
        izz = self.Izz if self.Izz is not None else iyy
        return ixx, iyy, izz

    def coefficients(self) -> dict[str, float]:
        """Scaled Prestero coefficients (see :func:`scaled_coefficients`), rho-corrected."""
        c = scaled_coefficients(self.length, self.diameter)
        k = self.rho_water / 1030.0  # Prestero used rho = 1030 kg/m3
        return {n: v * k for n, v in c.items()}

    def mass_matrices(self):
        """(M_RB, M_A) 6x6 (003 A-7, A-9); the inertias are taken about the CG and moved to the CB
        (the origin) by the parallel-axis theorem, I_b = I_g - m S(r_g)^2."""
        m = self.mass
        zg = self.zg
        ixx, iyy, izz = self.inertias()
        mrb = np.diag([m, m, m, ixx + m * zg * zg, iyy + m * zg * zg, izz]).astype(float)
        mrb[0, 4] = mrb[4, 0] = m * zg
        mrb[1, 3] = mrb[3, 1] = -m * zg
        c = self.coefficients()
        ma = np.diag([-c["X_udot"], -c["Y_vdot"], -c["Z_wdot"], -c["K_pdot"], -c["M_qdot"], -c["N_rdot"]])
        # symmetric coupling (Prestero: Y_rdot = N_vdot, Z_qdot = M_wdot)
        ma[1, 5] = ma[5, 1] = -c["Y_rdot"]
        ma[2, 4] = ma[4, 2] = -c["Z_qdot"]
        return mrb, ma

    def lift_coefficients(self) -> dict[str, float]:
        """Body/fin lift terms: Prestero's totals minus the added-mass (Munk) parts already in C_A."""
        c = self.coefficients()
        return {
            "Y_uv": c["Y_uv"],
            "Z_uw": c["Z_uw"],
            "Y_ur": c["Y_ur"] - c["X_udot"],
            "Z_uq": c["Z_uq"] + c["X_udot"],
            "M_uw": c["M_uw"] - (c["X_udot"] - c["Z_wdot"]),
            "N_uv": c["N_uv"] - (c["Y_vdot"] - c["X_udot"]),
            "M_uq": c["M_uq"] + c["Z_qdot"],
            "N_ur": c["N_ur"] - c["Y_rdot"],
        }

    @property
    def X_uu_total(self) -> float:
        """Axial quadratic drag X_u|u| (kg/m): scaled Prestero hull value plus the appendages."""
        return self.coefficients()["X_uu"] - 0.5 * self.rho_water * self.appendage_drag_area

    @property
    def weight(self) -> float:
        """W = m g (N)."""
        return self.mass * G

    @property
    def buoyancy(self) -> float:
        """B = W - submerged weight (N)."""
        return self.mass * G - self.weight_in_water_kgf * KGF

    def params(self, tow_point=(0.0, 0.0, 0.0)) -> np.ndarray:
        """Flat parameter array (layout :data:`LAYOUT`); ``tow_point`` is r_c in body axes (m)."""
        mrb, ma = self.mass_matrices()
        on = 1.0 if self.damping_on else 0.0
        c = self.coefficients()
        sc = self.drag_scale * on
        lf = self.lift_coefficients()
        v = {
            "W": self.weight,
            "B": self.buoyancy,
            "r_g": (0.0, 0.0, self.zg),
            "r_b": (0.0, 0.0, 0.0),
            "M_RB": mrb,
            "M_A": ma,
            "M_inv": np.linalg.inv(mrb + ma),
            "stern_half": 0.5 * self.stern_spacing,
            "bow_x": self.bow_arm,
            "r_c": tow_point,
        }
        v.update({k: getattr(self, k) * on for k in DLIN_NAMES})
        v.update(
            {
                k: q * sc
                for k, q in zip(DQUAD_NAMES, (self.X_uu_total, c["Y_vv"], c["Z_ww"], c["K_pp"], c["M_qq"], c["N_rr"]))
            }
        )
        v.update({k: lf[k] * sc for k in LIFT_NAMES})
        return LAYOUT.pack(v)

    def initial_state(self) -> np.ndarray:
        """x0 (12 states)."""
        return np.array(
            [self.x0, self.y0, self.z0, 0.0, 0.0, math.radians(self.psi0_deg), self.u0, 0.0, 0.0, 0.0, 0.0, 0.0]
        )
