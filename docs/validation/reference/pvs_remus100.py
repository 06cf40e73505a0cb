"""Recipe: reference numbers for a REMUS 100 vehicle file from Fossen's Python Vehicle Simulator (PVS), run unmodified.

    git clone https://github.com/cybergalactic/PythonVehicleSimulator /tmp/pvs
    git -C /tmp/pvs checkout c717e073d7a839dcb5956cf20c595132f1fa249a
    python docs/validation/reference/pvs_remus100.py /tmp/pvs > docs/validation/reference/pvs_remus100.json

Nothing of PVS is copied here: this script imports its ``remus100`` class (Prestero 2001's REMUS 100 as Fossen
2021 section 8.4.2 has it) and ``attitudeEuler`` from the clone and steps them as its ``mainLoop.simulate`` does
(``dynamics`` then ``attitudeEuler``, forward Euler at h = 0.02 s), from rest at the surface's depth 0 with the
command u_control = [delta_r (rad), delta_s (rad), n (rpm)] held constant (the stern plane at 0). After 300 s it
reads the steady surge speed u, sway v, yaw rate r, the turning radius R = U / |r| (U = sqrt(u^2 + v^2), no
current; for a turn also the radius of the circle through the last 60 s of the track), roll, pitch and the depth.

Cases: three propeller speeds straight (500, 1000, 1525 rpm; 1525 rpm is the class's n_max, where Allen, Vorus
and Prestero (2000) give 2.5 m/s, the speed the drag coefficient was calibrated to) and two rudder angles (5 and
15 deg, 15 deg the class's saturation) at 1525 rpm.
"""

from __future__ import annotations

import json
import math
import sys

import _pvs  # the recipes' shared part (this folder)
import numpy as np

#: (rudder deg, stern plane deg, propeller rpm)
CASES = ((0.0, 0.0, 500.0), (0.0, 0.0, 1000.0), (0.0, 0.0, 1525.0), (5.0, 0.0, 1525.0), (15.0, 0.0, 1525.0))
H, T_END = 0.02, 300.0


def run(pvs: str) -> dict:
    out = _pvs.header(
        pvs, "Python Vehicle Simulator, vehicles/remus100.py, remus100() (stepInput class), unmodified", H, T_END
    )
    from python_vehicle_simulator.vehicles.remus100 import remus100

    for dr, ds, rpm in CASES:
        v = remus100()
        u_control = np.array([math.radians(dr), math.radians(ds), rpm], float)
        eta, nu, track = _pvs.simulate(v, u_control, H, T_END, 3)
        u, vv, r = float(nu[0]), float(nu[1]), float(nu[5])
        case = {"rudder_deg": dr, "stern_deg": ds, "rpm": rpm, "u": u, "v": vv, "w": float(nu[2]), "r": r,
                "speed": math.hypot(u, vv), "roll_deg": math.degrees(eta[3]), "pitch_deg": math.degrees(eta[4]),
                "depth_m": float(eta[2])}  # fmt: skip
        if dr != 0.0:
            case["radius"] = math.hypot(u, vv) / abs(r)
            tail = track[-int(60.0 / H) :]
            case["radius_track"] = _pvs.circle_radius(tail[:, 0], tail[:, 1])
        out["cases"].append(case)
    return out


if __name__ == "__main__":
    if len(sys.argv) != 2:
        print("usage: pvs_remus100.py PATH_TO_PVS_CLONE", file=sys.stderr)
        raise SystemExit(2)
    print(json.dumps(run(sys.argv[1]), indent=1))
