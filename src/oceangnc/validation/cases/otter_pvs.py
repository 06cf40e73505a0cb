"""The Otter against Fossen's current program (class *reference implementation*, issue 38).

``otter.toml`` takes every term from one revision of Fossen's Python Vehicle Simulator, ``otter.py`` at c717e07,
and keeps three departures of ours as named options. With the three set to otter.py's (:func:`pvs_form`) the
file must reproduce his program, run unmodified at the same constant shaft speeds (:mod:`._pvs_otter`): steady
speed at 50, 75 and 100 % of n_max on both shafts, steady yaw rate and turning radius at 100/50 and 100/0 %
(port/starboard). This is a comparison with another program running the same model equations: it shows that
the file and the generic form implement his model, not that the model is the boat (no trial of the Otter is
published). The departures' effects, term by term, are in docs/vehicles.md.
"""

from __future__ import annotations

import json
import math

import numpy as np

from .. import Case
from . import _pvs_otter as pvs
from ._common import history, in_group

PVS = f"Fossen (2025), Python Vehicle Simulator, otter.py at commit {pvs.COMMIT} (2025-05-13), run unmodified"
_WHY = (
    "another program's output for the same equations: his forward Euler at h = 0.02 s and our RK4 share the steady "
    "state; 1 % is the issue's bound, the residual is 0.01 % (his g = 9.81 against 9.80665 in the payload force)"
)
_BASIS = (
    "the file's three departures set to otter.py's (rigid_body.parallel_axis = 'otter.py', "
    "hydrostatics.body_axis_weight.apply = true, damping.crossflow.rule = 'stations'); nothing fitted"
)


def pvs_form(vf):
    """The vehicle file with its departures from ``otter.py`` switched off: otter.py's inertia sum, its
    body-axis payload force and its 21-station cross-flow sum (a new, checked VehicleFile)."""
    from ...models.vehicle import VehicleFile, _check

    d = vf.model_dump(exclude_none=True)
    d["rigid_body"]["parallel_axis"] = "otter.py"
    if "body_axis_weight" in d["hydrostatics"]:
        d["hydrostatics"]["body_axis_weight"]["apply"] = True
    if "crossflow" in d["damping"]:
        d["damping"]["crossflow"]["rule"] = "stations"
    out = VehicleFile.model_validate(d)
    _check(out, f"vehicle '{vf.name}' in otter.py's form")
    return out


def steady_run(r, port: float, stbd: float, departures: bool = False):
    """(t, states) of the Otter's file (departures on, or off: :func:`pvs_form`) from rest with the shaft speeds
    ``port``, ``stbd`` (fractions of n_max) held for 200 s, shared between cases through the runner's cache."""
    from ...models._shaft import shaft_command
    from ...models.vehicle import load_vehicle, vehicle_model

    over = r.section("otter")
    key = "otter-pvs:" + json.dumps([port, stbd, departures, over], sort_keys=True)
    if key not in r._cache:
        vf = load_vehicle("otter")
        vf = vf if departures else pvs_form(vf)
        m = vehicle_model(vf).with_params(**over)
        sh = vf.thrusters[0].shaft
        t = np.arange(0.0, 200.0 + 1e-9, 0.1)
        u = [shaft_command(sh, port * pvs.N_MAX), shaft_command(sh, stbd * pvs.N_MAX), 0.0, 0.0]
        r._cache[key] = (t, m.simulate(t, np.tile(u, (t.size, 1)), np.zeros(m.nx), substeps=5))
    return r._cache[key]


def _speed(port, stbd):
    def measure(r):
        t, X = steady_run(r, port, stbd)
        U = np.hypot(X[:, 6], X[:, 7])
        return history(float(U[-1]), [("otter.toml in otter.py's form", t, U)], "U [m/s]")

    measure.__doc__ = f"Steady speed (m/s) at {port:.0%}/{stbd:.0%} of n_max, departures off."
    return measure


def _turn(port, stbd, what):
    def measure(r):
        t, X = steady_run(r, port, stbd)
        rr = X[:, 11]
        if what == "r":
            return history(math.degrees(rr[-1]), [("otter.toml in otter.py's form", t, np.degrees(rr))], "r [deg/s]")
        R = np.hypot(X[:, 6], X[:, 7]) / np.maximum(np.abs(rr), 1e-9)
        note = f"steady u = {X[-1, 6]:.4f} m/s, v = {X[-1, 7]:.4f} m/s, r = {math.degrees(rr[-1]):.3f} deg/s"
        return history(float(R[-1]), [("U / |r|", t[t > 20], R[t > 20])], "R [m]", note=note)

    measure.__doc__ = (
        f"Steady {'yaw rate (deg/s)' if what == 'r' else 'turning radius U / |r| (m)'} at {port:.0%}/{stbd:.0%}."
    )
    return measure


def _cases() -> list[Case]:
    out = []
    for (fp, fs), (_, _, r, U, R) in pvs.STEADY.items():
        tag = f"{round(100 * fp)}-{round(100 * fs)}"
        title = f"Otter (otter.toml, departures off), shaft speeds {fp:.0%} / {fs:.0%} of n_max (port / starboard)"
        common = dict(kind="reference", basis=_BASIS)
        if R is None:
            out.append(
                Case(f"vehicle-otter-pvs-speed-{tag}", title, f"{PVS}; {pvs.RUN}", "steady speed", "m/s", U,
                     f"{U:.4f} m/s (his program's output)", ("rel", 0.01), _WHY, _speed(fp, fs), **common)
            )  # fmt: skip
            continue
        out.append(
            Case(f"vehicle-otter-pvs-yaw-rate-{tag}", title, f"{PVS}; {pvs.RUN}", "steady yaw rate", "deg/s",
                 math.degrees(r), f"{math.degrees(r):.3f} deg/s (his program's output)", ("rel", 0.01), _WHY,
                 _turn(fp, fs, "r"), **common)
        )  # fmt: skip
        out.append(
            Case(f"vehicle-otter-pvs-radius-{tag}", title, f"{PVS}; {pvs.RUN}", "steady turning radius U / |r|", "m",
                 R, f"{R:.3f} m (his program's output)", ("rel", 0.01), _WHY, _turn(fp, fs, "R"), **common)
        )  # fmt: skip
    return out


CASES: list[Case] = in_group("vehicles of a file", *_cases())
