"""Cross-flow drag of a hull by strip theory, the ``[damping.crossflow]`` table of a vehicle file.

Fossen (2021) ch. 6, the cross-flow drag principle (his Otter model's ``crossFlowDrag``); Hoerner (1965) for
the 2-D drag coefficient. The sum itself is in the vehicle's compiled right-hand side
(:func:`oceangnc.models.vehicle.vehicle_deriv`); this module holds the table and its coefficients.
"""

from __future__ import annotations

from typing import Literal

import numpy as np
from pydantic import Field

from ..core.config import StrictModel

#: Hoerner's 2-D cross-flow drag coefficient of a rectangular section against B / (2 T): Hoerner (1965),
#: Fluid-Dynamic Drag, ch. 3 (blunt sections), the curve as digitised in Fossen (2021) and his Python Vehicle
#: Simulator (``Hoerner(B, T)``), published numbers, linear interpolation between them, clamped at the ends
HOERNER_B_2T = np.array(
    [0.0109, 0.1766, 0.3530, 0.4519, 0.4728, 0.4929, 0.4933, 0.5585, 0.6464, 0.8336,
     0.9880, 1.3081, 1.6392, 1.8600, 2.3129, 2.6000, 3.0088, 3.4508, 3.7379, 4.0031]
)  # fmt: skip
HOERNER_CD = np.array(
    [1.9661, 1.9657, 1.8976, 1.7872, 1.5837, 1.2786, 1.2108, 1.0836, 0.9986, 0.8796,
     0.8284, 0.7599, 0.6914, 0.6571, 0.6307, 0.5962, 0.5868, 0.5859, 0.5599, 0.5593]
)  # fmt: skip


def hoerner_cd(beam: float, draft: float) -> float:
    """2-D cross-flow drag coefficient of a section of beam B and draft T from Hoerner's curve at B / (2 T)
    (:data:`HOERNER_CD`; Hoerner 1965, as used by Fossen 2021 for the cross-flow drag integral)."""
    return float(np.interp(beam / (2.0 * draft), HOERNER_B_2T, HOERNER_CD))


class CrossFlow(StrictModel):
    """Cross-flow drag of a hull by strip theory (module docstring; Fossen 2021 ch. 6, Hoerner 1965)."""

    length: float = Field(gt=0, le=500, description="hull length L integrated over, m")
    beam: float = Field(gt=0, le=100, description="beam B of the section for Hoerner's curve (one hull), m")
    draft: float = Field(gt=0, le=50, description="draft T, the projected height per unit length, m")
    cd: float | None = Field(None, ge=0, le=5, description="2-D drag coefficient; default Hoerner's curve at B / (2 T)")
    x_center: float = Field(0.0, ge=-250, le=250, description="x of the hull's mid-length from CO, m")
    strips: int = Field(20, ge=1, le=200, description="number of strips n")
    rule: Literal["midpoint", "stations"] = Field(
        "midpoint",
        description="midpoint: n strips of width L / n (ours); stations: n + 1 stations from -L/2 to L/2 each "
        "weighted L / n (otter.py's crossFlowDrag)",
    )
    rho: float | None = Field(
        None, gt=900, le=1100, description="water density of the drag, kg/m^3 (default hydrostatics.rho)"
    )

    def coefficient(self, rho: float) -> float:
        """1/2 rho C_d T (kg/m^2): the drag per unit length of U|U|."""
        cd = hoerner_cd(self.beam, self.draft) if self.cd is None else self.cd
        return 0.5 * (self.rho or rho) * cd * self.draft

    def stations(self) -> tuple[float, float, int]:
        """x of the first station (m), spacing (m) and count of the sum, by :attr:`rule`."""
        dx = self.length / self.strips
        if self.rule == "stations":
            return self.x_center - 0.5 * self.length, dx, self.strips + 1
        return self.x_center - 0.5 * self.length + 0.5 * dx, dx, self.strips
