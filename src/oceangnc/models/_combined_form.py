"""Fused-loop forms of a :class:`~oceangnc.models.combined.CombinedPlant` (its ``compiled_form``).

:func:`combined_plant_form`: a fixed node count, advanced by the plant's integrator, then the
outputs filled by :func:`~oceangnc.models._combined_outputs._fill_outputs` and copied to their slots.

:func:`var_plant_form`: a variable node count (a winch and/or a seabed; issue 19).

The winch inserts and removes cable nodes while it runs (:func:`oceangnc.models.combined.remesh`,
called inside the stepper), so the number of active nodes ``p[H_N]`` changes during a compiled
call. Nothing about that needs Python: the state vector, the parameter vector (which holds the
active count) and the output buffer are sized for the drum's capacity (``n_max``) once, when the
plant is built, and the stepper and :func:`~oceangnc.models.combined._fill_outputs_var` read the
active count from ``p`` each time. The plant form therefore only wires those arrays into the
generated driver (:mod:`oceangnc.core.fused`):

1. read the inputs (thrusts, current, wind, ``winch.speed_cmd``) from the signal array;
2. advance with the plant's integrator (``imex``, which a winch requires, ``rk4-split`` or ``rk4``);
3. fill the full output vector (node columns for ``n_max + 1`` nodes, the inactive ones collapsed
   onto the tow point, then ``cable.length``, ``cable.nodes``, ``cable.mass``, the winch outputs
   and the seabed ones) and copy the published subset into its slots -- the same values, in the
   same order, as :meth:`CombinedPlant.publish`, so the log columns are those of the Python path.
"""

from __future__ import annotations

import numpy as np

from ..core.fused import PlantForm, _kernel_ref, rk4_stepper_imports
from ._combined_sea import sea_update


def combined_advance_imports(plant) -> list[str]:
    """Generated-code lines binding ``{adv}`` to the plant's compiled advance for its integrator:
    the IMEX or split-RK4 stepper, or the RK4 stepper of its rhs."""
    if plant.integrator in ("imex", "rk4-split"):
        mod, name = _kernel_ref(plant._kernels["imex_advance" if plant.integrator == "imex" else "split_advance"])
        return [f"from {mod} import {name} as {{adv}}"]
    return rk4_stepper_imports(plant.rhs)


def _sea_lines(plant, imports: list[str]) -> list[str]:
    """At sea, the line refreshing the wave expansions before the integrator (and its import); none in
    calm water (the generated loop is then the calm-water one)."""
    if not getattr(plant, "_sea", False):
        return []
    mod, name = _kernel_ref(sea_update)
    imports.append(f"from {mod} import {name} as _sea_update")
    return ["_sea_update(t, {x}, {p}, n * dt)"]


def _wf_lines(plant, slot_of, args: dict) -> list[str]:
    """With the USV's wave-frequency motions: the lines publishing its heave, roll and pitch from the
    state (as :meth:`CombinedPlant.publish`); none otherwise."""
    if not getattr(plant, "_wf", False):
        return []
    from ._usv_waves import WF_OUTPUTS

    args["wfidx"] = plant._wf_idx
    args["wfslots"] = np.array([slot_of(k) for k, _ in WF_OUTPUTS], dtype=np.int64)
    return ["for j in range({wfslots}.size):", "    sig[{wfslots}[j]] = {x}[{wfidx}[j]]"]


def _ev_lines(plant, slot_of, args: dict) -> list[str]:
    """With in-step event tracking: the lines publishing its counters and extremes from ``p`` (as
    :meth:`CombinedPlant.publish`); none otherwise."""
    idx = getattr(plant, "_ev_idx", np.zeros(0, dtype=np.int64))
    if not idx.size:
        return []
    from ._combined_events import EVENT_KEYS

    args["evidx"] = idx
    args["evslots"] = np.array([slot_of(k) for k in EVENT_KEYS], dtype=np.int64)
    return ["for j in range({evslots}.size):", "    sig[{evslots}[j]] = {p}[{evidx}[j]]"]


def combined_plant_form(plant, slot_of) -> PlantForm | None:
    """The :class:`~oceangnc.core.fused.PlantForm` of a ``CombinedPlant``: :func:`var_plant_form`
    with a winch or a seabed, else the fixed-node form (module docstring)."""
    if plant._var:
        return var_plant_form(plant, slot_of)
    if plant.integrator not in ("rk4", "rk4-split", "imex"):
        return None
    uin = np.array([slot_of(k) for k in plant.input_names], dtype=np.int64)
    args = {"x": plant.x, "u": plant.u, "p": plant.p, "w": plant.work, "bound": float(plant.state_bound), "uin": uin}
    args.update(
        {
            "o_uuv": int(plant.o_uuv),
            "nodes": plant._nodes,
            "ends": plant._ends,
            "out": plant._out,
            "oslots": np.array([slot_of(k) for k in plant._out_keys], dtype=np.int64),
        }
    )
    mod, name = _kernel_ref(plant._kernels["_fill_outputs"])
    imports = [*combined_advance_imports(plant), f"from {mod} import {name} as _fill_outputs"]
    code = [
        "for j in range({uin}.size):",
        "    {u}[j] = sig[{uin}[j]]",
        *_sea_lines(plant, imports),
        "tn = {adv}(t, {x}, {u}, {p}, dt, n, {w}, {bound})",
        "{ends}[6] = {u}[2]",
        "{ends}[7] = {u}[3]",
        "_fill_outputs({x}, {p}, {o_uuv}, {nodes}, {ends}, {out})",
        "for j in range({oslots}.size):",
        "    sig[{oslots}[j]] = {out}[j]",
        *_wf_lines(plant, slot_of, args),
        *_ev_lines(plant, slot_of, args),
    ]
    return PlantForm(imports, args, code)


def var_plant_form(plant, slot_of) -> PlantForm | None:
    """The :class:`~oceangnc.core.fused.PlantForm` of a winch/seabed ``CombinedPlant``, or None when
    an input the bus does not carry has a non-zero default (the signal array starts at 0)."""
    bus_names = getattr(slot_of, "names", {})
    for k in plant.input_names:
        if k not in bus_names and float(plant.input_defaults.get(k, 0.0)) != 0.0:
            return None
    uin = np.array([slot_of(k) for k in plant.input_names], dtype=np.int64)
    oslots = np.array([slot_of(k) for k in plant._out_keys], dtype=np.int64)
    args = {
        "x": plant.x,
        "u": plant.u,
        "p": plant.p,
        "w": plant.work,
        "bound": float(plant.state_bound),
        "uin": uin,
        "o_uuv": int(plant.o_uuv),
        "nmax": int(plant.n_max),
        "nodes": plant._nodes,
        "ends": plant._ends,
        "full": plant._out_full,
        "oidx": np.ascontiguousarray(plant._out_idx, dtype=np.int64),
        "oslots": oslots,
    }
    # import lines from where the kernels live (robust to their moving between modules)
    imports = combined_advance_imports(plant)
    mod, name = _kernel_ref(plant._kernels["_fill_outputs_var"])
    imports.append(f"from {mod} import {name} as _fill_outputs_var")
    code = [
        "for j in range({uin}.size):",
        "    {u}[j] = sig[{uin}[j]]",
        *_sea_lines(plant, imports),
        "tn = {adv}(t, {x}, {u}, {p}, dt, n, {w}, {bound})",
        "{ends}[6] = {u}[2]",
        "{ends}[7] = {u}[3]",
        "_fill_outputs_var({x}, {p}, {o_uuv}, {nodes}, {ends}, {full}, {u}, {nmax})",
        "for j in range({oslots}.size):",
        "    sig[{oslots}[j]] = {full}[{oidx}[j]]",
        *_wf_lines(plant, slot_of, args),
        *_ev_lines(plant, slot_of, args),
    ]
    return PlantForm(imports, args, code)
