"""Seabed: a plane at a configurable depth and slope, with penalty contact and friction (issue 16).

The seabed is the plane z_b(x, y) = D + tan(slope) (x cos(chi) + y sin(chi)) (NED, z down, m), chi the
direction (deg from north) in which it deepens. It is static, so it is not a block: the plant that
meets it (:class:`oceangnc.models.combined.CombinedPlant`) takes this config and applies, to every cable
node and to the UUV (a sphere of the hull's radius around its centre of buoyancy), a penalty contact
along the plane's normal, N = m (w^2 d + 2 zeta w v_in) for a penetration d > 0 (clipped >= 0: the bed
only pushes), and a regularised Coulomb friction -mu N v_t / sqrt(|v_t|^2 + (0.01 m/s)^2) against the
velocity along the bed. With w = 30 rad/s the static penetration of a resting node is g' / w^2 (about
7 mm for the table 2-6 cable). The UUV's altitude z_b(x, y) - z (m, vertical, from its centre) is
published as ``uuv.altitude``. A seabed above the cable's attachment point under the USV is refused.
"""

from __future__ import annotations

from pydantic import Field

from ..io.config import StrictModel


class SeabedConfig(StrictModel):
    """Plane seabed; ``depth = None`` (default): no seabed."""

    depth: float | None = Field(None, gt=0, le=1.1e4, description="seabed depth at the origin (north 0, east 0), m")
    slope_deg: float = Field(0.0, ge=0, le=45, description="seabed slope, deg")
    slope_direction_deg: float = Field(
        0.0, ge=-360, le=360, description="direction in which the seabed deepens, deg from north"
    )
    friction: float = Field(0.5, ge=0, le=2, description="Coulomb friction coefficient mu, -")
    contact_frequency: float = Field(
        30.0, gt=0, le=1e3, description="natural frequency w of the penalty contact (per unit mass), rad/s"
    )
    contact_damping_ratio: float = Field(1.0, ge=0, le=10, description="damping ratio zeta of the contact, -")
