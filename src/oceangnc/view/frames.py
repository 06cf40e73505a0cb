"""Frame conversions of the viewers (docs/view.md, "Frames").

The simulation's earth frame is **NED** (x north, y east, z down, m) and a vehicle's body frame is
**FRD** (x forward, y starboard, z down), its attitude the ZYX Euler angles (psi yaw, theta pitch,
phi roll, rad): R_ned_frd = Rz(psi) Ry(theta) Rx(phi).

* **MCAP** (:func:`ned_to_enu`, :func:`enu_flu_quaternion`): Foxglove, Lichtblick, rviz and ROS 2
  follow REP 103: earth frame **ENU** (x east, y north, z up) and body frame **FLU** (x forward,
  y port, z up). The exported frame ``world`` is ENU with its origin at the NED origin:
  (x, y, z)_ENU = (e, n, -d); orientations are R_enu_flu = A R_ned_frd B, with A the NED->ENU
  swap (a half turn about (1, 1, 0)/sqrt 2) and B = diag(1, -1, -1) (a half turn about x).
* **three.js** (the replay page, ``nedToThree`` in static/replay.js): y up, right-handed:
  (x, y, z)_three = (e, -d, -n); :func:`ned_to_three` is the same map, for the tests.
"""

from __future__ import annotations

import numpy as np

_SQ = np.sqrt(0.5)
Q_ENU_NED = np.array([0.0, _SQ, _SQ, 0.0])  # (w, x, y, z): half turn about (1, 1, 0)/sqrt 2
Q_FRD_FLU = np.array([0.0, 1.0, 0.0, 0.0])  # half turn about x


def ned_to_enu(n, e, d):
    """NED coordinates -> ENU (x east, y north, z up): arrays (e, n, -d)."""
    return np.asarray(e, float), np.asarray(n, float), -np.asarray(d, float)


def ned_to_three(n, e, d):
    """NED coordinates -> three.js world (x, y, z) = (e, -d, -n) (y up); the page's ``nedToThree``."""
    return np.asarray(e, float), -np.asarray(d, float), -np.asarray(n, float)


def euler_quaternion(phi, theta, psi) -> np.ndarray:
    """Quaternions (w, x, y, z), shape (N, 4), of R_ned_frd = Rz(psi) Ry(theta) Rx(phi)."""
    hp, ht, hs = (np.asarray(a, float) / 2 for a in (phi, theta, psi))
    cp, sp, ct, st, cs, ss = np.cos(hp), np.sin(hp), np.cos(ht), np.sin(ht), np.cos(hs), np.sin(hs)
    return np.stack(
        [
            cp * ct * cs + sp * st * ss,
            sp * ct * cs - cp * st * ss,
            cp * st * cs + sp * ct * ss,
            cp * ct * ss - sp * st * cs,
        ],
        axis=-1,
    )


def qmul(a, b) -> np.ndarray:
    """Hamilton products a b of quaternions (w, x, y, z) (broadcast over leading axes)."""
    a, b = np.asarray(a, float), np.asarray(b, float)
    aw, ax, ay, az = np.moveaxis(a, -1, 0)
    bw, bx, by, bz = np.moveaxis(b, -1, 0)
    return np.stack(
        [
            aw * bw - ax * bx - ay * by - az * bz,
            aw * bx + ax * bw + ay * bz - az * by,
            aw * by - ax * bz + ay * bw + az * bx,
            aw * bz + ax * by - ay * bx + az * bw,
        ],
        axis=-1,
    )


def enu_flu_quaternion(phi, theta, psi) -> np.ndarray:
    """Orientation (w, x, y, z), shape (N, 4), of the FLU body frame in ENU, from the NED/FRD Euler
    angles: q_enu_flu = q_enu_ned q_ned_frd q_frd_flu (module docstring); w >= 0."""
    q = qmul(qmul(Q_ENU_NED, euler_quaternion(phi, theta, psi)), Q_FRD_FLU)
    return np.where(q[..., :1] < 0, -q, q)


def quat_matrix(q) -> np.ndarray:
    """Rotation matrices (N, 3, 3) of unit quaternions (w, x, y, z)."""
    w, x, y, z = np.moveaxis(np.asarray(q, float), -1, 0)
    return np.stack(
        [
            np.stack([1 - 2 * (y * y + z * z), 2 * (x * y - w * z), 2 * (x * z + w * y)], -1),
            np.stack([2 * (x * y + w * z), 1 - 2 * (x * x + z * z), 2 * (y * z - w * x)], -1),
            np.stack([2 * (x * z - w * y), 2 * (y * z + w * x), 1 - 2 * (x * x + y * y)], -1),
        ],
        -2,
    )
