"""Winch at the USV's attachment point: pays the cable out and hauls it in during a run (issue 16).

The winch is part of :class:`oceangnc.models.combined.CombinedPlant` (its states are integrated with the
cable's, in the same compiled step); this module holds its configuration and documents the model.

* **States**: the paid-out unstretched length L (m) and the drum (line) speed s (m/s, + paying out).
  dL/dt = s; ds/dt = (s_c - s) / tau clipped to +-a_max (a first-order speed loop with an acceleration
  limit).
* **Command** (bus ``winch.speed_cmd``, m/s): saturated to +-v_max (``winch.speed_cmd_sat``,
  ``winch.cmd_saturated`` logged); replaced by +v_max while the top tension exceeds ``tension_max`` (the
  winch renders: it pays out rather than exceed the limit, ``winch.rendering``); zero at the drum's
  capacity while paying out (``winch.at_capacity``: the warning signal in the log) and at the minimum
  length while hauling in.
* **Cable**: the top segment (between the sheave, node 0, and node 1) has the variable unstretched
  length l_top = L - (n - 1) l0; its stiffness EA / l_top, mass, added mass, weight and drag follow it,
  so the mass of cable in the water is rho_c A L at every instant. When l_top leaves the band
  [0.5 l0, 1.5 l0] a node is inserted (l_top > 1.5 l0: a node on the top segment's chord at l_top - l0
  from the sheave, velocity interpolated linearly between its ends: this conserves momentum, the strain
  and potential energies, and cannot raise the kinetic energy) or removed (l_top < 0.5 l0: node 1
  leaves; the share of its mass that joins node 2 brings its momentum, the rest goes to the sheave). The
  plant is preallocated for the largest node count (capacity / l0 + 2); the active count lives in the
  parameter array, so nothing is reallocated in the hot path (see docs/towing.md).
"""

from __future__ import annotations

from pydantic import Field

from ..io.config import StrictModel


class WinchConfig(StrictModel):
    """Winch (drum) limits. ``enabled = false``: fixed cable length (no winch states)."""

    enabled: bool = Field(False, description="winch at the USV's attachment point (needs cable.integrator = 'imex')")
    speed_max: float = Field(0.5, gt=0, le=5, description="largest drum (line) speed, m/s")
    accel_max: float = Field(0.5, gt=0, le=10, description="largest drum acceleration, m/s2")
    tension_max: float = Field(
        2000.0, gt=0, le=1e6, description="tension limit: above it the winch pays out at speed_max, N"
    )
    capacity: float = Field(100.0, gt=0, le=1e4, description="cable length on the drum (largest payout), m")
    min_length: float = Field(0.5, gt=0, le=1e3, description="shortest paid-out length (haul-in stops), m")
    time_constant: float = Field(0.2, ge=0.01, le=10, description="drum speed loop time constant tau, s")
