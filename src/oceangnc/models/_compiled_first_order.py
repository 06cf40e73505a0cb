"""Compiled plant outputs of the first-order USV (000) and its towed trailer, for the fused loop
(issue 19; see :class:`oceangnc.core.fused.PlantForm`).

Each function repeats its plant's Python ``read_inputs`` / ``publish`` operation for operation, so the
fused log equals the Python clock's; the equations themselves (the trailer's rates, 000 eq. 3-4)
have their one home in :mod:`oceangnc.models.towed_trailer`.
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit

from .towed_trailer import trailer_rates


@njit(cache=True)
def first_order_publish(x, sig, slots, cp):
    """:meth:`oceangnc.models.first_order.FirstOrderUSV.publish`.

    slots: x, y, psi, u, r, speed, schedule_clamped, u_op (-1: absent). cp: straight lo/hi, turn
    lo/hi (m/s), operating schedule (1/0), then set here: left a range (1/0), the speed then (m/s),
    for the plant's warning (:meth:`~oceangnc.models.first_order.FirstOrderUSV.after_fused`).
    """
    for i in range(5):
        sig[slots[i]] = x[i]
    sig[slots[2]] = (x[2] + math.pi) % (2 * math.pi) - math.pi
    sig[slots[5]] = abs(x[3])
    u = x[3]
    if cp[4] != 0.0 and slots[7] >= 0:
        u = sig[slots[7]]
    out = not (cp[0] <= u <= cp[1] and cp[2] <= u <= cp[3])
    sig[slots[6]] = 1.0 if out else 0.0
    if out and cp[5] == 0.0:
        cp[5] = 1.0
        cp[6] = u


@njit(cache=True)
def trailer_read(x, u, sig, islots):
    """:meth:`oceangnc.models.towed_trailer.TowedTrailer.read_inputs`: islots usv.u, usv.psi, usv.r."""
    u[0] = sig[islots[0]]
    psi = sig[islots[1]]
    u[1] = x[0] + ((psi - x[0] + math.pi) % (2 * math.pi) - math.pi)
    u[2] = sig[islots[2]]


@njit(cache=True)
def trailer_publish(x, sig, slots, L):
    """:meth:`oceangnc.models.towed_trailer.TowedTrailer.publish`.

    slots: usv.x, usv.y, usv.u, usv.r, usv.psi | uuv.x, uuv.y, uuv.psi, uuv.u, uuv.r, uuv.phi.
    """
    psi = x[0]
    xs = sig[slots[0]]
    ys = sig[slots[1]]
    us = sig[slots[2]]
    rs = sig[slots[3]]
    phi = (psi - sig[slots[4]] + math.pi) % (2 * math.pi) - math.pi
    uu, ru, _ = trailer_rates(us, rs, phi, L)
    sig[slots[5]] = xs - L * math.cos(psi)
    sig[slots[6]] = ys - L * math.sin(psi)
    sig[slots[7]] = (psi + math.pi) % (2 * math.pi) - math.pi
    sig[slots[8]] = uu
    sig[slots[9]] = ru
    sig[slots[10]] = phi


def _base_args(plant) -> dict:
    return {"x": plant.x, "u": plant.u, "p": plant.p, "w": plant.work, "bound": float(plant.state_bound)}


def first_order_form(plant, slot_of):
    """The :class:`~oceangnc.core.fused.PlantForm` of a :class:`~oceangnc.models.first_order.FirstOrderUSV`."""
    from ..core.fused import PlantForm, plant_bus_keys, rk4_stepper_imports

    c = plant.cfg
    n = plant.name
    args = _base_args(plant)
    args["uin"] = np.array([slot_of(k) for k in plant.input_names], dtype=np.int64)
    uop = f"{n}.u_op"
    has_uop = uop in plant_bus_keys(slot_of)
    names = [f"{n}.{k}" for k in ("x", "y", "psi", "u", "r", "speed", "schedule_clamped")]
    args["oslots"] = np.array([slot_of(k) for k in names] + [slot_of(uop) if has_uop else -1], dtype=np.int64)
    oper = 1.0 if c.schedule == "operating" else 0.0
    args["cp"] = np.array([c.straight_lo_mps, c.straight_hi_mps, c.turn_lo_mps, c.turn_hi_mps, oper, 0.0, 0.0])
    plant._fused_cp = args["cp"]
    imports = [
        *rk4_stepper_imports(plant.rhs),
        "from oceangnc.models._compiled_first_order import first_order_publish as _pub_{adv}",
    ]
    code = [
        "for j in range({uin}.size):",
        "    {u}[j] = sig[{uin}[j]]",
        "tn = {adv}(t, {x}, {u}, {p}, dt, n, {w}, {bound})",
        "_pub_{adv}({x}, sig, {oslots}, {cp})",
    ]
    return PlantForm(imports, args, code)


def trailer_form(plant, slot_of):
    """The :class:`~oceangnc.core.fused.PlantForm` of a :class:`~oceangnc.models.towed_trailer.TowedTrailer`."""
    from ..core.fused import PlantForm, rk4_stepper_imports

    s, n = plant.usv, plant.name
    args = _base_args(plant)
    args["islots"] = np.array([slot_of(f"{s}.{k}") for k in ("u", "psi", "r")], dtype=np.int64)
    outs = [f"{s}.{k}" for k in ("x", "y", "u", "r", "psi")] + [f"{n}.{k}" for k in ("x", "y", "psi", "u", "r", "phi")]
    args["oslots"] = np.array([slot_of(k) for k in outs], dtype=np.int64)
    args["L"] = float(plant.L)
    imports = [
        *rk4_stepper_imports(plant.rhs),
        "from oceangnc.models._compiled_first_order import trailer_read as _rd_{adv}",
        "from oceangnc.models._compiled_first_order import trailer_publish as _pub_{adv}",
    ]
    code = [
        "_rd_{adv}({x}, {u}, sig, {islots})",
        "{u}[3] = t + n * dt",
        "tn = {adv}(t, {x}, {u}, {p}, dt, n, {w}, {bound})",
        "_pub_{adv}({x}, sig, {oslots}, {L})",
    ]
    return PlantForm(imports, args, code)
