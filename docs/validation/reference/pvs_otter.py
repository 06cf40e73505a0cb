"""Recipe: the reference numbers of the Otter cases from Fossen's Python Vehicle Simulator (PVS), run unmodified.

    git clone https://github.com/cybergalactic/PythonVehicleSimulator /tmp/pvs
    git -C /tmp/pvs checkout c717e073d7a839dcb5956cf20c595132f1fa249a
    python docs/validation/reference/pvs_otter.py /tmp/pvs > docs/validation/reference/pvs_otter.json

Nothing of PVS is copied here: this script imports its ``otter`` class and ``attitudeEuler`` from the clone
(numpy and matplotlib needed) and steps them exactly as its ``mainLoop.simulate`` does (``dynamics`` then
``attitudeEuler``, forward Euler at h = 0.02 s), from rest, with the shaft-speed command u_control = [n1, n2]
(rad/s; n1 the left = port propeller) held constant, a fraction of the class's own n_max. After 200 s it reads
the steady surge speed u, sway v, yaw rate r and the turning radius R = U / |r| (U = sqrt(u^2 + v^2), no
current) and, for a turn, checks R against the radius of the circle through the last 50 s of the track.
"""

from __future__ import annotations

import json
import math
import sys

import _pvs  # the recipes' shared part (this folder)
import numpy as np

CASES = ((0.5, 0.5), (0.75, 0.75), (1.0, 1.0), (1.0, 0.5), (1.0, 0.0))  #: (port, starboard) fractions of n_max
H, T_END = 0.02, 200.0


def run(pvs: str) -> dict:
    out = _pvs.header(pvs, "Python Vehicle Simulator, vehicles/otter.py, otter() (stepInput), unmodified", H, T_END)
    from python_vehicle_simulator.vehicles.otter import otter

    for fp, fs in CASES:
        v = otter()
        out["n_max_rad_s"] = v.n_max
        u_control = np.array([fp * v.n_max, fs * v.n_max], float)
        eta, nu, track = _pvs.simulate(v, u_control, H, T_END, 2)
        u, vv, r = float(nu[0]), float(nu[1]), float(nu[5])
        case = {"port": fp, "starboard": fs, "n_port_rad_s": u_control[0], "n_stbd_rad_s": u_control[1],
                "u": u, "v": vv, "r": r, "speed": math.hypot(u, vv)}  # fmt: skip
        if fp != fs:
            case["radius"] = math.hypot(u, vv) / abs(r)
            tail = track[-int(50.0 / H) :]
            case["radius_track"] = _pvs.circle_radius(tail[:, 0], tail[:, 1])
        out["cases"].append(case)
    return out


if __name__ == "__main__":
    if len(sys.argv) != 2:
        print("usage: pvs_otter.py PATH_TO_PVS_CLONE", file=sys.stderr)
        raise SystemExit(2)
    print(json.dumps(run(sys.argv[1]), indent=1))
