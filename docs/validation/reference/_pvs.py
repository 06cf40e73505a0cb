"""What the PVS recipes (``pvs_otter.py``, ``pvs_remus100.py``) share: the run's header (program, commit,
dates), the constant-input simulation exactly as PVS's ``mainLoop.simulate`` steps it (``dynamics`` then
``attitudeEuler``, forward Euler at ``h``), and the least-squares circle through a track. PVS itself is
imported from the clone the recipe is given; nothing of it is copied here."""

from __future__ import annotations

import datetime
import math
import subprocess
import sys

import numpy as np


def header(pvs: str, program: str, h: float, t_end: float) -> dict:
    """The output's header: ``program``, the clone's commit and commit date, today's date, step and duration."""
    sys.path.insert(0, f"{pvs}/src")
    commit = subprocess.run(["git", "-C", pvs, "rev-parse", "HEAD"], capture_output=True, text=True).stdout.strip()
    date = subprocess.run(["git", "-C", pvs, "log", "-1", "--format=%cI"], capture_output=True, text=True).stdout
    return {"program": program, "repository": "https://github.com/cybergalactic/PythonVehicleSimulator",
            "commit": commit, "commit_date": date.strip(), "run_date": datetime.date.today().isoformat(),
            "h_s": h, "t_end_s": t_end, "cases": []}  # fmt: skip


def simulate(v, u_control: np.ndarray, h: float, t_end: float, dims: int):
    """From rest, ``u_control`` held: (eta, nu, track of the first ``dims`` position components)."""
    from python_vehicle_simulator.lib.gnc import attitudeEuler

    n_steps = int(round(t_end / h))
    eta, nu, u_actual = np.zeros(6), v.nu.copy(), v.u_actual.copy()
    track = np.zeros((n_steps + 1, dims))
    for i in range(n_steps):
        nu, u_actual = v.dynamics(eta, nu, u_actual, u_control, h)
        eta = attitudeEuler(eta, nu, h)
        track[i + 1] = eta[0:dims]
    return eta, nu, track


def circle_radius(x: np.ndarray, y: np.ndarray) -> float:
    """Least-squares circle (Kasa fit) through the points: its radius."""
    A = np.column_stack([x, y, np.ones_like(x)])
    c, *_ = np.linalg.lstsq(A, x**2 + y**2, rcond=None)
    return float(math.sqrt(c[2] + (c[0] / 2) ** 2 + (c[1] / 2) ** 2))
