"""Validation cases of the vehicles defined by a file (issue 30; :mod:`oceangnc.models.vehicle`).

Each says what kind of evidence it is. The Otter's top speed is a calibration target (its linear surge
damping is defined from it); the 003 UUV's file against the dedicated model is a round trip of the
form; the conservation of kinetic energy is a physical law of the Coriolis form.
"""

from __future__ import annotations

import numpy as np

from .. import Case
from ._common import history, in_group

FOSSEN_OTTER = "Fossen (2021), Handbook of Marine Craft Hydrodynamics and Motion Control, 2nd ed.: the Otter USV model"


def otter_top_speed(r):
    """Steady surge speed (m/s) of the Otter's file at full forward thrust on both propellers."""
    from ...models.vehicle import vehicle_model

    m = vehicle_model("otter")
    t = np.arange(0.0, 120.0, 0.1)
    fwd = m.p[m.layout.index("left.max_forward")]
    U = np.zeros((t.size, m.nu))
    U[:, :2] = fwd
    X = m.simulate(t, U, np.zeros(m.nx), substeps=5)
    return history(float(X[-1, 6]), [("Otter, both propellers at full thrust", t, X[:, 6])], "u [m/s]")


def uuv003_form(r):
    """Largest relative difference of the 12 states between the 003 UUV's file and its dedicated model."""
    from ...models.uuv import uuv_model
    from ...models.vehicle import vehicle_model

    ref, gen = uuv_model(), vehicle_model("uuv-003")
    t = np.linspace(0.0, 30.0, 301)
    U = np.tile([40.0, 10.0, 5.0, 0.2, -0.1], (t.size, 1))
    x0 = np.zeros(12)
    x0[2], x0[6] = 3.0, 0.5
    a = ref.simulate(t, U, x0, substeps=20)
    b = gen.simulate(t, U, np.r_[x0, np.zeros(3)], substeps=20)[:, :12]
    err = np.max(np.abs(a - b) / np.maximum(np.abs(a).max(axis=0), 1e-3), axis=1)
    return history(float(err.max()), [("max relative state difference", t, np.maximum(err, 1e-18))], "difference")


CASES: list[Case] = in_group(
    "vehicles of a file",
    Case(
        "vehicle-otter-top-speed",
        "Otter USV (file otter.toml), both propellers at full forward thrust",
        FOSSEN_OTTER,
        "steady surge speed",
        "m/s",
        6 * 0.5144,
        "U_max = 6 knots",
        ("rel", 0.01),
        "the linear surge damping is defined so that full thrust gives U_max: only the generic form's "
        "surge balance (thrust limits, saturation, lag) is checked",
        otter_top_speed,
        kind="calibration",
        basis="D_L[0] = 24.4 g / U_max (Fossen's X_u for the Otter)",
    ),
    Case(
        "vehicle-uuv003-generic-form",
        "003 UUV as a vehicle file against its dedicated model, turning with a bow thrust in a current",
        "003_486f48bcab6eec1d.txt ch. 2.2, appendix A",
        "largest relative state difference over 30 s",
        "1",
        0.0,
        "the same model",
        ("abs", 1e-9),
        "the same numbers summed in another order: rounding only",
        uuv003_form,
        kind="round-trip",
        basis="oceangnc.models.uuv (the dedicated 003 model) wrote the file's numbers",
    ),
)
