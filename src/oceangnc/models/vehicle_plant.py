"""The plant of a vehicle file (:mod:`oceangnc.models.vehicle`): it publishes the thrust each thruster gives.

A thruster with ``time_constant`` > 0 carries its thrust as a state (a first-order lag on the saturated
command), so the state ``thrust_<name>`` is what it gives. A thruster with ``time_constant = 0`` applies
the saturated command at once: :func:`~oceangnc.models.vehicle.vehicle_deriv` uses
``clip(cmd, -max_reverse, max_forward)`` and leaves the state at its initial 0, which is no thrust the
vehicle gets. This plant therefore publishes, for such a thruster, ``<name>.thrust_<thruster>`` = that
saturated command, the thrust applied over the step just integrated (the command is held over it), in the
Python clock (:meth:`VehiclePlant.publish`) and in the fused loop (:func:`vehicle_publish`) alike.
"""

from __future__ import annotations

import numpy as np
from numba import njit

from ..core.blocks import Plant, scatter
from ..core.fused import PlantForm, _kernel_ref, rk4_stepper_imports
from ..core.signals import CALM
from .vehicle import NT, P_NTHR, P_THR, T_FWD, T_REV, T_SHAFT, T_TAU


@njit(cache=True)
def vehicle_publish(x, u, p, sig, slots):
    """Every state into its slot, then for each thruster without a lag (``time_constant = 0``) the thrust it
    applies, ``clip(u_i, -max_reverse, max_forward)`` (N), in place of its unused state (module docstring)."""
    scatter(x, sig, slots)
    n = int(p[P_NTHR])
    for i in range(n):
        k = P_THR + NT * i
        if p[k + T_TAU] > 0.0 or p[k + T_SHAFT] > 0.0:  # a lagged thrust, or a shaft speed: the state itself
            continue
        c = u[i]
        if c > p[k + T_FWD]:
            c = p[k + T_FWD]
        elif c < -p[k + T_REV]:
            c = -p[k + T_REV]
        sig[slots[12 + i]] = c


class VehiclePlant(Plant):
    """A vehicle file's :class:`~oceangnc.core.model.Model` integrated by RK4, publishing ``<name>.<state>``
    with the thrust of lag-free thrusters taken from their saturated command (:func:`vehicle_publish`)."""

    def __init__(self, model, name: str, x0, input_signals):
        args = model.plant_args(name, x0, input_signals, declare=True)
        defaults = {k: v for k, v in CALM.items() if k in args["input_names"]}
        super().__init__(**args, input_defaults=defaults)
        self._keys = [f"{name}.{k}" for k in self.state_names]
        self._out = np.zeros(len(self._keys))
        self._slots = np.arange(len(self._keys), dtype=np.int64)

    def publish(self, bus: dict) -> None:
        """The states and the applied thrusts (:func:`vehicle_publish`), as the fused loop writes them."""
        vehicle_publish(self.x, self.u, self.p, self._out, self._slots)
        bus.update(zip(self._keys, self._out.tolist()))

    def compiled_form(self, slot_of) -> PlantForm:
        """The fused loop's form: read the inputs, the RK4 stepper of the model, then :func:`vehicle_publish`."""
        mod, fn = _kernel_ref(vehicle_publish)
        imports = [*rk4_stepper_imports(self.rhs), f"from {mod} import {fn} as _pub_{{adv}}"]
        uin = np.array([slot_of(k) for k in self.input_names], dtype=np.int64)
        args = {"x": self.x, "u": self.u, "p": self.p, "w": self.work, "bound": float(self.state_bound), "uin": uin}
        args["oslots"] = np.array([slot_of(k) for k in self._keys], dtype=np.int64)
        code = [
            "for j in range({uin}.size):",
            "    {u}[j] = sig[{uin}[j]]",
            "tn = {adv}(t, {x}, {u}, {p}, dt, n, {w}, {bound})",
            "_pub_{adv}({x}, {u}, {p}, sig, {oslots})",
        ]
        return PlantForm(imports, args, code)
