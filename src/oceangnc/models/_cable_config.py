"""The cable's configuration (003 table 2-6): geometry, material, hydrodynamic coefficients, drag law,
integrator and the derived per-segment quantities. Re-exported by :mod:`oceangnc.models.cable`.
"""

from __future__ import annotations
import math
from typing import Literal
from pydantic import Field, model_serializer, model_validator
from ..errors import ConfigError
from ..io.config import StrictModel
from ..units import G, RHO_WATER


class BridleConfig(StrictModel):
    """The three-point bridle of 003 fig. 5-6 ("steel wire was used to connect three points before and
    after the hull"): three tension-only wires from the cable's end (the junction) to a fore, a mid and
    an aft hull point of the UUV. 003 prints no dimension. Chosen: the hull points on the hull's top line
    (z = -d/2 = -0.125 m for table 2-5's 0.25 m hull), 0.6 m fore and aft of the centre of buoyancy (a
    third of the 1.79 m hull); the wires rigged to meet at an apex on the centre of buoyancy's vertical,
    so that the hull hangs level in still water (the usual rule for a sling), 1.0 m above the centre of
    buoyancy by default (a round rig height). The vehicle as built (``field-test``) uses 1.25 m, fitted with
    its formation target to 003's pitch, depth and distance (docs/validation/bridle_fit.py, a calibration:
    docs/combined-vehicle.md 'The three-point bridle')."""

    fore_x: float = Field(0.6, ge=-10, le=10, description="fore hull point, body x (ahead of the CB), m")
    fore_y: float = Field(0.0, ge=-5, le=5, description="fore hull point, body y (starboard), m")
    fore_z: float = Field(-0.125, ge=-5, le=5, description="fore hull point, body z (negative: above the CB), m")
    mid_x: float = Field(0.0, ge=-10, le=10, description="mid hull point, body x, m")
    mid_y: float = Field(0.0, ge=-5, le=5, description="mid hull point, body y, m")
    mid_z: float = Field(-0.125, ge=-5, le=5, description="mid hull point, body z, m")
    aft_x: float = Field(-0.6, ge=-10, le=10, description="aft hull point, body x, m")
    aft_y: float = Field(0.0, ge=-5, le=5, description="aft hull point, body y, m")
    aft_z: float = Field(-0.125, ge=-5, le=5, description="aft hull point, body z, m")
    apex_x: float = Field(
        0.0, ge=-10, le=10, description="rigged apex, body x: the wires' default lengths reach it just taut, m"
    )
    apex_y: float = Field(0.0, ge=-5, le=5, description="rigged apex, body y, m")
    apex_z: float = Field(-1.0, ge=-20, le=5, description="rigged apex, body z (negative: above the CB), m")
    length_fore: float | None = Field(
        None, gt=0, le=20, description="unstretched length of the fore wire (default: to the rigged apex), m"
    )
    length_mid: float | None = Field(
        None, gt=0, le=20, description="unstretched length of the mid wire (default: to the rigged apex), m"
    )
    length_aft: float | None = Field(
        None, gt=0, le=20, description="unstretched length of the aft wire (default: to the rigged apex), m"
    )
    wire_diameter: float = Field(0.003, gt=0, le=0.1, description="wire diameter (chosen: 3 mm), m")
    wire_E: float = Field(
        1.0e11, gt=0, le=3e11, description="effective modulus of the wire rope (steel rope ~ 1e11 Pa), Pa"
    )

    def points(self) -> list[tuple[float, float, float]]:
        """The three hull points (fore, mid, aft), body frame (m)."""
        return [(self.fore_x, self.fore_y, self.fore_z), (self.mid_x, self.mid_y, self.mid_z),
                (self.aft_x, self.aft_y, self.aft_z)]  # fmt: skip

    def lengths(self) -> list[float]:
        """Unstretched wire lengths (fore, mid, aft), m: the keys, or the distance to the rigged apex."""
        apex = (self.apex_x, self.apex_y, self.apex_z)
        given = (self.length_fore, self.length_mid, self.length_aft)
        return [float(g) if g is not None else math.dist(h, apex) for g, h in zip(given, self.points(), strict=True)]

    @property
    def EA(self) -> float:
        """Axial stiffness EA of one wire (N)."""
        return self.wire_E * math.pi * self.wire_diameter**2 / 4.0


class CableConfig(StrictModel):
    """Cable parameters (003 table 2-6) and its attachment points."""

    segments: int | None = Field(
        None,
        ge=1,
        le=1000,
        description="number of segments n (003 ch. 4: 20); default from the length: "
        "max(20, ceil(L / 2 m)), or from cable.segment_length, -",
    )
    segment_length: float | None = Field(
        None,
        gt=0,
        le=1e3,
        description="nominal segment length, alternative to cable.segments: n = max(1, round(L / segment_length)), m",
    )
    length: float = Field(3.0, gt=0, le=1e4, description="unstretched length L (003 table 2-6), m")
    diameter: float = Field(0.025, gt=0, le=1.0, description="diameter d_c (003 table 2-6), m")
    density: float = Field(3121.0, gt=0, le=2e4, description="cable density rho_c (003 table 2-6), kg/m3")
    cd: float = Field(2.5, ge=0, le=10, description="drag coefficient C_d (003 table 2-6), -")
    drag_law: Literal["loading-functions", "normal-tangential"] = Field(
        "loading-functions",
        description="loading-functions: 003 eq. 2.24-2.25 with C_d; normal-tangential: "
        "1/2 rho C_dn d |V_n| V_n + 1/2 rho C_dt pi d |v_t| v_t per unit length",
    )
    cd_normal: float | None = Field(
        None, ge=0, le=10, description="normal drag coefficient C_dn (normal-tangential law; default: cable.cd), -"
    )
    cd_tangential: float | None = Field(
        None,
        ge=0,
        le=1,
        description="tangential drag coefficient C_dt on the wetted perimeter pi d "
        "(normal-tangential law; default 0.02 C_d / pi, eq. 2.25's "
        "f_q(0)), -",
    )
    damping: float = Field(100.0, ge=0, le=1e6, description="axial damping coefficient C_v (003 eq. 2.23), N s/m")
    E: float = Field(
        7.5e6, gt=0, le=1e12, description="effective modulus of elasticity (003 table 2-6, read as E in Pa), Pa"
    )
    added_mass_coeff: float = Field(1.0, ge=0, le=5, description="normal added-mass coefficient C_a (003 eq. 2.27), -")
    integrator: Literal["rk4", "rk4-split", "imex"] = Field(
        "rk4-split",
        description="rk4-split: axial damping implicit, the rest RK4 (Strang split, 2.2x larger "
        "stable step); rk4: classical RK4 on everything; imex: ROS2 W-method with the "
        "axial stiffness and damping implicit (no axial step limit, O(n) solve)",
    )
    drag_on: bool = Field(True, description="hydrodynamic drag on the cable (off only for energy checks)")
    rho_water: float = Field(RHO_WATER, gt=900, le=1100, description="water density, kg/m3")
    top_x: float = Field(0.0, ge=-50, le=50, description="USV attachment point, body x (forward of the CG), m")
    top_y: float = Field(0.0, ge=-50, le=50, description="USV attachment point, body y (starboard), m")
    top_z: float = Field(0.0, ge=-10, le=10, description="USV attachment point depth below the waterline, m")
    tow_x: float = Field(0.0, ge=-10, le=10, description="UUV tow point r_c, body x (ahead of the CB), m")
    tow_y: float = Field(0.0, ge=-10, le=10, description="UUV tow point r_c, body y, m")
    tow_z: float = Field(-0.125, ge=-10, le=10, description="UUV tow point r_c, body z (negative: above the CB), m")
    attachment: Literal["single", "bridle"] = Field(
        "single",
        description="single: the cable's end on the tow point r_c (003 eq. 2.30-2.33); bridle: three wires "
        "from the cable's end to fore, mid and aft hull points (003 fig. 5-6, cable.bridle)",
    )
    bridle: BridleConfig = Field(BridleConfig(), description="the three-point bridle (cable.attachment = bridle)")

    @model_validator(mode="after")
    def _resolve_segments(self):
        """Segment count: explicit ``segments``, else from ``segment_length``, else max(20, ceil(L / 2 m))."""
        if self.segment_length is not None:
            if "segments" in self.model_fields_set and self.segments is not None:
                raise ConfigError("cable.segments and cable.segment_length are alternatives: set only one")
            n = max(1, int(round(self.length / self.segment_length)))
            if n > 1000:
                raise ConfigError(
                    f"cable.segment_length = {self.segment_length:g}: gives {n} segments for "
                    f"{self.length:g} m; allowed range: at most 1000 segments"
                )
            self.__dict__["segments"] = n
        elif self.segments is None:
            self.__dict__["segments"] = max(20, math.ceil(self.length / 2.0 - 1e-9))
        if self.attachment == "bridle":
            for name, h, ln in zip(("fore", "mid", "aft"), self.bridle.points(), self.bridle.lengths(), strict=True):
                if ln < 1e-3:
                    raise ConfigError(
                        f"cable.bridle.length_{name} = {ln:.3g} m (hull point {h} to the apex): allowed range >= 0.001 m"
                    )
        return self

    @model_serializer(mode="wrap")
    def _dump(self, handler):
        """Written without the segment count derived from ``segment_length`` (the two are alternatives:
        a run's config.toml must load back, issue 26)."""
        d = handler(self)
        if self.segment_length is not None and isinstance(d, dict):
            d.pop("segments", None)
        return d

    @property
    def cd_n(self) -> float:
        """Normal drag coefficient of the normal-tangential law (-)."""
        return self.cd if self.cd_normal is None else self.cd_normal

    @property
    def cd_t(self) -> float:
        """Tangential drag coefficient of the normal-tangential law, on the perimeter pi d (-)."""
        return 0.02 * self.cd / math.pi if self.cd_tangential is None else self.cd_tangential

    @property
    def area(self) -> float:
        """Cross-section A = pi d^2 / 4 (m2)."""
        return math.pi * self.diameter**2 / 4.0

    @property
    def EA(self) -> float:
        """Axial stiffness EA (N)."""
        return self.E * self.area

    @property
    def l0(self) -> float:
        """Unstretched segment length (m)."""
        return self.length / self.segments

    @property
    def segment_mass(self) -> float:
        """m_c = rho_c A l0 (kg)."""
        return self.density * self.area * self.l0

    @property
    def segment_added_mass(self) -> float:
        """m_a = C_a rho_w A l0 (kg), normal directions only."""
        return self.added_mass_coeff * self.rho_water * self.area * self.l0

    @property
    def weight_per_length(self) -> float:
        """Submerged weight per unit length (rho_c - rho_w) g A (N/m)."""
        return (self.density - self.rho_water) * G * self.area

    @property
    def tow_point(self) -> tuple[float, float, float]:
        return (self.tow_x, self.tow_y, self.tow_z)

    @property
    def top_point(self) -> tuple[float, float, float]:
        return (self.top_x, self.top_y, self.top_z)
