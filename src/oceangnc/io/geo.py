"""Local NED <-> geodetic latitude / longitude about an origin (flat-earth, WGS-84 radii).

For the small areas a USV works in (a few km), the tangent-plane approximation

    lat = lat0 + n / R_M,        lon = lon0 + e / (R_N cos lat0)

with the WGS-84 meridian and prime-vertical radii of curvature at lat0,

    R_M = a (1 - e^2) / (1 - e^2 sin^2 lat0)^(3/2),    R_N = a / sqrt(1 - e^2 sin^2 lat0),

is exact to first order in n/R and e/R (error below 1 mm at 1 km). This is what ArduPilot's
``location_offset`` does (with a sphere) and what a ground station draws on its map.
"""

from __future__ import annotations

import math

A_WGS84 = 6378137.0  #: semi-major axis, m
E2_WGS84 = 6.69437999014e-3  #: first eccentricity squared


def radii(lat0_deg: float) -> tuple[float, float]:
    """(R_M, R_N): meridian and prime-vertical radii of curvature at ``lat0_deg`` (m)."""
    s = math.sin(math.radians(lat0_deg))
    w = 1.0 - E2_WGS84 * s * s
    return A_WGS84 * (1.0 - E2_WGS84) / w**1.5, A_WGS84 / math.sqrt(w)


def ned_to_latlon(n: float, e: float, lat0_deg: float, lon0_deg: float) -> tuple[float, float]:
    """Latitude and longitude (deg) of the point ``n`` m north and ``e`` m east of the origin."""
    rm, rn = radii(lat0_deg)
    lat = lat0_deg + math.degrees(n / rm)
    lon = lon0_deg + math.degrees(e / (rn * math.cos(math.radians(lat0_deg))))
    return lat, (lon + 180.0) % 360.0 - 180.0


def latlon_to_ned(lat_deg: float, lon_deg: float, lat0_deg: float, lon0_deg: float) -> tuple[float, float]:
    """North and east (m) of a point from the origin (inverse of :func:`ned_to_latlon`)."""
    rm, rn = radii(lat0_deg)
    dlon = (lon_deg - lon0_deg + 180.0) % 360.0 - 180.0
    return math.radians(lat_deg - lat0_deg) * rm, math.radians(dlon) * rn * math.cos(math.radians(lat0_deg))
