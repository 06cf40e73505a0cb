r"""The hydrodynamic coefficient file of a hull and its response amplitude operators (RAO).

A :class:`HydroCoefficients` holds, for one hull at zero forward speed (linear potential flow, from
:mod:`oceangnc.hydro.bem` or read from a file):

* ``omega`` (nw,) wave frequencies (rad/s); ``headings`` (nb,) wave directions relative to the bow (rad):
  the direction the waves travel *toward*, measured from the bow to starboard (0 following seas,
  pi/2 waves travelling to starboard, i.e. beam seas from port, pi head seas) - the convention of
  ``environment.waves.direction_deg - heading``;
* ``A`` (nw, 6, 6) added mass, ``B`` (nw, 6, 6) radiation damping, ``A_inf`` (6, 6) the infinite-frequency
  added mass, ``C`` (6, 6) hydrostatic stiffness, ``M`` (6, 6) rigid-body mass matrix;
* ``X`` (nw, nb, 6) complex excitation force per metre of wave amplitude (Froude-Krylov + diffraction):
  a wave eta = a cos(k (x cos mu + y sin mu) - w t + eps) gives the force
  F_i(t) = a |X_i| cos(k (x_0 cos mu + y_0 sin mu) - w t + eps + arg X_i) on a hull whose reference point
  is at (x_0, y_0);
* ``drift`` (nw, nb, 3) or None: the mean wave drift force (surge, sway N/m^2; yaw N m/m^2) per square
  metre of wave amplitude.

Units SI; frame: the USV's body axes (x forward, y starboard, z down), SNAME order (surge, sway, heave,
roll, pitch, yaw), rotations about the reference point (the waterline, amidships).

The RAO (:meth:`HydroCoefficients.rao`) is the frequency-domain solution of the linear equations of
motion (e.g. Newman 1977, *Marine Hydrodynamics*, sec. 6.18; Fossen 2021, *Handbook of Marine Craft
Hydrodynamics and Motion Control*, 2nd ed., ch. 5):

    [-w^2 (M + A(w)) - i w (B(w) + B_v) + C] xi = X(w, mu)      (time factor exp(-i w t))

with B_v an optional viscous damping (the roll damping that potential flow lacks, :meth:`roll_damping`).
"""

from __future__ import annotations

import hashlib
import json
import math
from dataclasses import dataclass, field
from importlib import resources
from pathlib import Path

import numpy as np

from ..errors import InputError

#: version of the file layout (a file of another version is refused, not misread)
FILE_VERSION = 1
DOF_NAMES = ("surge", "sway", "heave", "roll", "pitch", "yaw")
#: the committed coefficient file of 003's USV (package data, computed by ``oceangnc hydro --save``)
DEFAULT_FILE = "usv003.npz"
#: period (s) of the weak tie of the wave-frequency surge, sway and yaw (:meth:`HydroCoefficients.horizontal_tie`)
TIE_PERIOD = 60.0


@dataclass
class HydroCoefficients:
    """Frequency-domain coefficients of a hull (module docstring for the frame, units and conventions)."""

    omega: np.ndarray
    headings: np.ndarray
    A: np.ndarray
    B: np.ndarray
    A_inf: np.ndarray
    C: np.ndarray
    M: np.ndarray
    X: np.ndarray
    rho: float = 1025.0
    g: float = 9.81
    depth: float = math.inf
    drift: np.ndarray | None = None
    hull: dict = field(default_factory=dict)
    inputs_hash: str = ""
    version: int = FILE_VERSION

    # -- file ------------------------------------------------------------------------------------
    def save(self, path: str | Path) -> Path:
        """Write the coefficients to ``path`` (compressed npz; the hull's description as JSON)."""
        path = Path(path)
        path.parent.mkdir(parents=True, exist_ok=True)
        arrays = {
            "version": np.array(self.version),
            "inputs_hash": np.array(self.inputs_hash),
            "hull": np.array(json.dumps(self.hull, sort_keys=True)),
            "omega": self.omega,
            "headings": self.headings,
            "A": self.A,
            "B": self.B,
            "A_inf": self.A_inf,
            "C": self.C,
            "M": self.M,
            "X": self.X,
            "scalars": np.array([self.rho, self.g, self.depth]),
        }
        if self.drift is not None:
            arrays["drift"] = self.drift
        tmp = path.with_name(path.name + ".part.npz")
        np.savez_compressed(tmp, **arrays)  # type: ignore[arg-type]
        tmp.replace(path)
        return path

    @classmethod
    def load(cls, path: str | Path) -> HydroCoefficients:
        """Read a file written by :meth:`save`; a missing, foreign or other-version file is an
        :class:`~oceangnc.errors.InputError` (one line)."""
        path = Path(path)
        try:
            with np.load(path, allow_pickle=False) as z:
                d = {k: z[k] for k in z.files}
        except FileNotFoundError:
            raise InputError(f"hydrodynamic coefficient file {path}: not found") from None
        except (OSError, ValueError) as e:
            raise InputError(f"hydrodynamic coefficient file {path}: not an npz file ({e})") from None
        need = ("version", "omega", "headings", "A", "B", "A_inf", "C", "M", "X", "scalars")
        missing = [k for k in need if k not in d]
        if missing:
            raise InputError(f"hydrodynamic coefficient file {path}: missing {', '.join(missing)}")
        if int(d["version"]) != FILE_VERSION:
            raise InputError(
                f"hydrodynamic coefficient file {path}: version {int(d['version'])}, this oceangnc reads "
                f"version {FILE_VERSION} (recompute it with oceangnc hydro --save)"
            )
        rho, g, depth = (float(v) for v in d["scalars"])
        c = cls(
            omega=d["omega"],
            headings=d["headings"],
            A=d["A"],
            B=d["B"],
            A_inf=d["A_inf"],
            C=d["C"],
            M=d["M"],
            X=d["X"],
            rho=rho,
            g=g,
            depth=depth,
            drift=d.get("drift"),
            hull=json.loads(str(d.get("hull", "{}"))),
            inputs_hash=str(d.get("inputs_hash", "")),
            version=int(d["version"]),
        )
        c.check(str(path))
        return c

    def check(self, where: str = "coefficients") -> None:
        """Shapes and finiteness; an :class:`~oceangnc.errors.InputError` naming the array otherwise."""
        nw, nb = self.omega.size, self.headings.size
        shapes = {
            "A": (nw, 6, 6),
            "B": (nw, 6, 6),
            "A_inf": (6, 6),
            "C": (6, 6),
            "M": (6, 6),
            "X": (nw, nb, 6),
        }
        if self.drift is not None:
            shapes["drift"] = (nw, nb, 3)
        for k, s in shapes.items():
            a = getattr(self, k)
            if a.shape != s:
                raise InputError(f"{where}: {k} has shape {a.shape}, expected {s}")
            if not np.all(np.isfinite(a)):
                raise InputError(f"{where}: {k} has non-finite entries")
        if nw < 4 or np.any(np.diff(self.omega) <= 0) or self.omega[0] <= 0:
            raise InputError(f"{where}: omega must be >= 4 increasing positive frequencies")
        if nb < 1 or np.any(np.diff(self.headings) <= 0):
            raise InputError(f"{where}: headings must be increasing")

    # -- derived -----------------------------------------------------------------------------------
    def heading_index(self, mu: float) -> int:
        """Index of the heading ``mu`` (rad, wrapped) in :attr:`headings` (to 1e-6 rad), else an InputError."""
        d = np.angle(np.exp(1j * (self.headings - mu)))
        i = int(np.argmin(np.abs(d)))
        if abs(d[i]) > 1e-6:
            raise InputError(
                f"heading {math.degrees(mu):g} deg is not one of the file's headings "
                f"({', '.join(f'{math.degrees(h):g}' for h in self.headings)} deg)"
            )
        return i

    def interp_omega(self, name: str, w: np.ndarray) -> np.ndarray:
        """``A``, ``B``, ``X`` or ``drift`` linearly interpolated to the frequencies ``w`` (rad/s),
        held at the end values outside the computed band."""
        a = getattr(self, name)
        w = np.clip(np.asarray(w, dtype=float), self.omega[0], self.omega[-1])
        j = np.clip(np.searchsorted(self.omega, w) - 1, 0, self.omega.size - 2)
        f = (w - self.omega[j]) / (self.omega[j + 1] - self.omega[j])
        f = f.reshape(f.shape + (1,) * (a.ndim - 1))
        return (1.0 - f) * a[j] + f * a[j + 1]

    def roll_natural_frequency(self) -> float:
        """Undamped roll natural frequency (rad/s): w^2 = C44 / (M44 + A44(w)), by fixed-point iteration
        (A44 held at the band's end values outside it)."""
        w = math.sqrt(max(self.C[3, 3], 1e-9) / (self.M[3, 3] + self.A_inf[3, 3]))
        for _ in range(50):
            a44 = float(self.interp_omega("A", np.array([w]))[0, 3, 3])
            w = math.sqrt(max(self.C[3, 3], 1e-9) / (self.M[3, 3] + a44))
        return w

    def roll_damping(self, ratio: float) -> np.ndarray:
        """A linear viscous roll damping (6, 6) (only entry [3, 3]): ``ratio`` of the critical damping
        2 sqrt(C44 (M44 + A44(w_n))) at the roll natural frequency w_n. Potential flow gives a slender or
        flat hull little roll damping; the viscous part (eddies, skin friction, bilge keels) is usually
        stated this way, e.g. Himeno (1981), *Prediction of ship roll damping*, Univ. Michigan rep. 239."""
        Bv = np.zeros((6, 6))
        if ratio > 0:
            w = self.roll_natural_frequency()
            a44 = float(self.interp_omega("A", np.array([w]))[0, 3, 3])
            Bv[3, 3] = 2.0 * ratio * math.sqrt(self.C[3, 3] * (self.M[3, 3] + a44))
        return Bv

    def horizontal_tie(self, period: float = TIE_PERIOD, ratio: float = 1.0) -> tuple[np.ndarray, np.ndarray]:
        """(damping, stiffness) (6, 6) of a weak spring-damper on surge, sway and yaw: natural period
        ``period`` (s) with the infinite-frequency mass, damping ``ratio`` of critical. These modes have no
        hydrostatic restoring, so a wave-frequency model left free drifts away on any low-frequency
        error; the slow motion belongs to the manoeuvring model (two time scales), so the wave-frequency
        one is tied to it with a period far above the waves' (60 s against 2-15 s: the RAO changes by
        (T_wave / period)^2 and 2 ratio T_wave / period, under 2 % above 1 rad/s)."""
        ws = 2.0 * math.pi / period
        Bt = np.zeros((6, 6))
        Ct = np.zeros((6, 6))
        for k in (0, 1, 5):
            m = self.M[k, k] + self.A_inf[k, k]
            Ct[k, k] = m * ws * ws
            Bt[k, k] = 2.0 * ratio * m * ws
        return Bt, Ct

    def time_domain_extras(self, roll_damping_ratio: float) -> tuple[np.ndarray, np.ndarray]:
        """(damping, stiffness) (6, 6) that the time-domain model adds to the coefficients: the viscous
        roll damping (:meth:`roll_damping`) and the horizontal tie (:meth:`horizontal_tie`)."""
        Bt, Ct = self.horizontal_tie()
        return Bt + self.roll_damping(roll_damping_ratio), Ct

    def rao(
        self, iw: int, ib: int, extra_damping: np.ndarray | None = None, extra_stiffness: np.ndarray | None = None
    ) -> np.ndarray:
        """Complex motion RAO (6,) per metre of wave amplitude at the file's frequency ``omega[iw]`` and
        heading ``headings[ib]`` (m/m for surge-heave, rad/m for roll-yaw; module docstring)."""
        w = self.omega[iw]
        Bt = self.B[iw] + (extra_damping if extra_damping is not None else 0.0)
        Ct = self.C + (extra_stiffness if extra_stiffness is not None else 0.0)
        H = -(w**2) * (self.M + self.A[iw]) - 1j * w * Bt + Ct
        return np.linalg.solve(H, self.X[iw, ib])

    def raos(self, extra_damping: np.ndarray | None = None, extra_stiffness: np.ndarray | None = None) -> np.ndarray:
        """Every RAO: (nw, nb, 6) complex."""
        out = np.zeros((self.omega.size, self.headings.size, 6), complex)
        for i in range(self.omega.size):
            for j in range(self.headings.size):
                out[i, j] = self.rao(i, j, extra_damping, extra_stiffness)
        return out


def inputs_hash(hull: dict, mesh_bytes: bytes | None = None) -> str:
    """Hash of what a coefficient file depends on: the hull's description (its JSON), the mesh file's
    content and the file version (a cached file is reused only when all three match)."""
    h = hashlib.sha256(json.dumps(hull, sort_keys=True).encode())
    if mesh_bytes is not None:
        h.update(mesh_bytes)
    h.update(str(FILE_VERSION).encode())
    return h.hexdigest()[:16]


def load_coefficients(path: str | Path | None = None) -> HydroCoefficients:
    """The coefficients in ``path``, or (None) the committed file of 003's USV (no capytaine needed)."""
    if path is None:
        return default_usv_coefficients()
    return HydroCoefficients.load(path)


def default_usv_coefficients() -> HydroCoefficients:
    """The committed coefficients of 003's USV (package data ``oceangnc/hydro/data/usv003.npz``; the
    hull: :func:`oceangnc.hydro.bem.usv003_hull`)."""
    ref = resources.files("oceangnc.hydro") / "data" / DEFAULT_FILE
    with resources.as_file(ref) as p:
        return HydroCoefficients.load(p)
