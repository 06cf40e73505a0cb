"""Validity flags of a tow at sea: is the sea state inside the assumptions docs/sea-state.md states (issue 40)?

Each flag is 1 when the run stays inside the model, 0 when it leaves it; ``sea.in_model`` is 1 when all
hold. The operability table draws a sea state with any run outside as "outside model", never "pass".

* ``validity.usv_angles_ok``: the USV's significant roll and pitch amplitudes (2 standard deviations of
  ``usv.phi``, ``usv.theta``) within ``validity.max_angle_deg`` (10 deg: the linear seakeeping model is a
  small-rotation model, and its tow-point lever uses xi_4..6 x r). Only with the USV's motions on.
* ``validity.relative_motion_ok``: the relative vertical motion of the hull's bow, centre and stern
  against the local wave surface, r = z_point + eta(x_point, y_point, t) (m, + deeper; z_point = usv.z
  -+ L/2 sin(theta) at the ends): its significant amplitude (2 standard deviations, the worst of the
  three points) below the draught T (the floor stays in the water) and the freeboard (height - T: the
  deck stays dry): the linear model assumes the calm-water waterplane. Only with the USV's motions on
  (hull from its coefficient file).
* ``validity.cable_wet_ok``: the cable's first interior node stays below the local surface at every
  logged row (a node above it keeps its buoyancy in the model: docs/sea-state.md, limits of the loads).
* ``validity.steepness_ok``: the sea's steepness Hs / lambda_p (lambda_p from the dispersion relation at
  the peak period) within ``validity.max_steepness`` (1/14: half the breaking limit 1/7 of Airy waves;
  this project's choice).

The wave elevation at the logged positions is the field's own sum (the components drawn from the same
seed as the plant's), vectorised over the rows.
"""

from __future__ import annotations

import math

import numpy as np
from pydantic import Field

from ..io.config import StrictModel


class SeaValidity(StrictModel):
    max_angle_deg: float = Field(10.0, gt=0, le=90, description="USV roll/pitch significant amplitude limit, deg")
    max_steepness: float = Field(1.0 / 14.0, gt=0, le=1, description="Hs / peak wave length limit, 1")


def _eta(field, t, x, y):
    """Wave elevation (m, up) of ``field`` at times ``t`` (s) and positions ``x``, ``y`` (m, NED), rows."""
    c = field.comps
    a, om, k, th, eps = c[0], c[1], c[2], c[3], c[4]
    out = np.zeros(np.shape(t))
    for lo in range(0, len(t), 2048):  # blocks of rows: a bounded (rows x components) array
        sl = slice(lo, lo + 2048)
        ph = k * (x[sl, None] * np.cos(th) + y[sl, None] * np.sin(th)) - om * t[sl, None] + eps
        out[sl] = np.cos(ph) @ a
    return out


def validity(w, cfg) -> dict:
    """The flags of the module docstring for the logged rows ``w`` of a ``tow-sea-state`` run."""
    from ..environment.waves import wave_number

    v = cfg.validity
    wv = cfg.environment.waves
    out: dict = {}
    if wv.kind == "none":
        return {"validity.steepness": 0.0, "sea.in_model": 1}
    lam = 2.0 * math.pi / float(wave_number(np.array([2.0 * math.pi / wv.tp]), wv.depth)[0])
    out["validity.steepness"] = wv.hs / lam
    flags = {"validity.steepness_ok": wv.hs / lam <= v.max_steepness}
    field = cfg.environment.plant_kwargs(cfg.sim.seed)["waves"]
    t = w["t"].to_numpy()
    if "cable.x1" in w:
        x1, y1, z1 = (w[f"cable.{a}1"].to_numpy() for a in "xyz")
        flags["validity.cable_wet_ok"] = bool(np.all(z1 + _eta(field, t, x1, y1) > 0.0))
    if cfg.environment.usv_motions.enabled and "usv.theta" in w:
        from ..hydro.coefficients import load_coefficients

        hull = load_coefficients(cfg.environment.usv_motions.file).hull
        amp = 2.0 * math.degrees(max(float(np.std(w["usv.phi"].to_numpy())), float(np.std(w["usv.theta"].to_numpy()))))
        out["validity.usv_angle_amplitude_deg"] = amp
        flags["validity.usv_angles_ok"] = amp <= v.max_angle_deg
        x, y, z, psi, th = (w[k].to_numpy() for k in ("usv.x", "usv.y", "usv.z", "usv.psi", "usv.theta"))
        half, draught = 0.5 * float(hull["length"]), float(hull["draught"])
        rel = []
        for s in (-1.0, 0.0, 1.0):  # stern, centre, bow
            px, py = x + s * half * np.cos(psi), y + s * half * np.sin(psi)
            rel.append(z - s * half * np.sin(th) + _eta(field, t, px, py))
        amp_r = 2.0 * float(np.max(np.std(np.array(rel), axis=1)))  # significant amplitude, worst point
        out["validity.relative_motion_amplitude_m"] = amp_r
        flags["validity.relative_motion_ok"] = amp_r < min(draught, float(hull["height"]) - draught)
    out.update({k: int(bool(f)) for k, f in flags.items()})
    out["sea.in_model"] = int(all(flags.values()))
    return out
