"""A rigid body given as parts (hull, payload, ...): total mass, centre of gravity and inertia about it.

``[[rigid_body.parts]]`` lists each part's mass m_i, the position r_i of its own CG from CO and its inertia
I_i about that CG (radii of gyration, 3 values or 3 x 3; a part without them is a point mass). The file's
``rigid_body.parallel_axis`` says how they are summed:

* ``"exact"`` (ours): the parallel-axis theorem (Steiner; Fossen 2021 eq. 3.37) about the combined CG
  r_g = sum m_i r_i / m,

      I_g = sum_i [ I_i - m_i S(d_i)^2 ],   d_i = r_i - r_g,   -S(d)^2 = |d|^2 I - d d^T

  which M_RB = H(r_g)^T diag(m I, I_g) H(r_g) (Fossen eq. 3.44) then takes to CO once.
* ``"otter.py"``: the sum of Fossen's Otter model (Python Vehicle Simulator ``otter.py``, 2021-2025,
  ``Ig = Ig_CG - m S(rg)^2 - mp S(rp)^2``): the first part's own inertia, its mass transported by the combined
  r_g and every other part's mass by its position r_i from CO. That is close to an inertia about CO, which
  M_RB = H^T M_CG H then transports by r_g a second time. For the Otter its I_g is (16.68, 21.52, 15.10) kg m^2
  with I_xz = 2.52 against the exact (10.65, 14.52, 14.14) with I_xz = -0.39: +57 %, +48 %, +7 %.
"""

from __future__ import annotations

from typing import Literal

import numpy as np
from pydantic import Field, model_validator

from ..core.config import StrictModel

Vec3 = tuple[float, float, float]


class Part(StrictModel):
    """One mass of the rigid body: mass, CG position from CO, inertia about its own CG."""

    name: str = Field(min_length=1, max_length=40)
    mass: float = Field(gt=0, le=1e8, description="mass, kg")
    r: Vec3 = Field(description="the part's CG from CO (body axes), m")
    radii: Vec3 | None = Field(None, description="radii of gyration about the part's CG, m (inertia m R^2)")
    inertia: Vec3 | tuple[Vec3, Vec3, Vec3] | None = Field(
        None, description="inertia about the part's CG, kg m^2 (3 values or 3 x 3); none: a point mass"
    )

    def own_inertia(self) -> np.ndarray:
        """The part's inertia about its own CG (3 x 3, kg m^2)."""
        if self.radii is not None:
            return self.mass * np.diag(np.square(self.radii))
        if self.inertia is None:
            return np.zeros((3, 3))
        return np.diag(self.inertia) if np.ndim(self.inertia[0]) == 0 else np.asarray(self.inertia, float)


def _skew2(a) -> np.ndarray:
    """S(a)^2 = a a^T - |a|^2 I."""
    a = np.asarray(a, float)
    return np.outer(a, a) - a @ a * np.eye(3)


def combine_parts(parts: list[Part], rule: str) -> tuple[float, np.ndarray, np.ndarray]:
    """Mass (kg), CG from CO (m) and the inertia (3 x 3, kg m^2) the file's ``rigid_body.inertia`` takes (about
    the CG), by ``rule`` ``"exact"`` or ``"otter.py"`` (module docstring)."""
    m = sum(p.mass for p in parts)
    r_g = sum(p.mass * np.asarray(p.r, float) for p in parts) / m
    if rule == "exact":
        ig = sum(p.own_inertia() - p.mass * _skew2(np.asarray(p.r) - r_g) for p in parts)
    else:
        ig = parts[0].own_inertia() - parts[0].mass * _skew2(r_g)
        ig = ig - sum(p.mass * _skew2(p.r) for p in parts[1:])
    return float(m), r_g, np.asarray(ig, float)


class RigidBody(StrictModel):
    mass: float | None = Field(None, gt=0, le=1e8, description="mass in air, kg (or parts)")
    inertia: Vec3 | tuple[Vec3, Vec3, Vec3] | None = Field(
        None, description="inertia about the CG, kg m^2: [I_x, I_y, I_z] or a 3 x 3 matrix (or parts)"
    )
    r_g: Vec3 | None = Field(None, description="centre of gravity from the origin CO (body axes), m (default 0)")
    parts: list[Part] | None = Field(None, max_length=16, description="the body as parts (models._mass_parts)")
    parallel_axis: Literal["exact", "otter.py"] = Field(
        "exact", description="how parts are summed: exact parallel-axis sum about the CG, or otter.py's (ours: exact)"
    )

    @model_validator(mode="after")
    def _one_way(self):
        given = [k for k in ("mass", "inertia", "r_g") if getattr(self, k) is not None]
        if (self.parts is None and (self.mass is None or self.inertia is None)) or (self.parts is not None and given):
            raise ValueError("give either mass and inertia (and r_g) or parts, not both")
        return self

    def resolved(self) -> tuple[float, np.ndarray, np.ndarray]:
        """Mass (kg), inertia about the CG (3 x 3, kg m^2) and CG from CO (m), from the values or the parts."""
        if self.parts is not None:
            m, r_g, ig = combine_parts(self.parts, self.parallel_axis)
            return m, ig, r_g
        ig = np.diag(self.inertia) if np.ndim(self.inertia[0]) == 0 else np.asarray(self.inertia, float)
        return float(self.mass), ig, np.asarray(self.r_g if self.r_g is not None else (0.0, 0.0, 0.0), float)
