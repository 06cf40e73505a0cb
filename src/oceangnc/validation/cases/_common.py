"""Shared pieces of the validation cases: seed file names and the plot-series helpers.

Seed files: 000 = 000_709eacce50bfa23e.txt (first-order models, towed-UUV planning), 001 =
001_7b3de4f47de6bfb9.txt (joystick berthing), 002 = 002_05c842517d8c1175.txt (EKF coefficients),
003 = 003_486f48bcab6eec1d.txt (combined USV-cable-UUV).
"""

from __future__ import annotations

import numpy as np

from .. import Case, Measured

D003, D000, D001, D002 = (
    "003_486f48bcab6eec1d.txt",
    "000_709eacce50bfa23e.txt",
    "001_7b3de4f47de6bfb9.txt",
    "002_05c842517d8c1175.txt",
)


def ts(df, col, scale=1.0, label=None):
    """(label, t, column x scale): a time history of one log column for the plot."""
    return (label or col, df["t"].to_numpy(), df[col].to_numpy() * scale)


def track(df, body, label=None):
    """(label, east, north): the plan-view track of ``body`` (``usv``, ``uuv``) for the plot."""
    return (label or body.upper(), df[f"{body}.y"].to_numpy(), df[f"{body}.x"].to_numpy())


def wrap_deg(a):
    """Angle (deg) wrapped to (-180, 180] with the one angle wrap, :func:`oceangnc.core.rotations.wrap_array`."""
    from ...core.rotations import wrap_array

    return np.degrees(wrap_array(np.radians(a)))


def history(value, series, ylabel, ref_points=(), **kw) -> Measured:
    """A :class:`Measured` plotted against time (x axis ``t [s]``)."""
    return Measured(value, list(series), list(ref_points), xlabel="t [s]", ylabel=ylabel, **kw)


def plan(value, series, ref_points=(), **kw) -> Measured:
    """A :class:`Measured` plotted in plan view (east, north), without a tolerance band."""
    return Measured(value, list(series), list(ref_points), xlabel="east [m]", ylabel="north [m]", band=False, **kw)


def in_group(group: str, *cases: Case) -> list[Case]:
    """The cases, each with ``group`` set (the report's section)."""
    for c in cases:
        c.group = group
    return list(cases)
