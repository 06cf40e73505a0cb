r"""Hydrodynamic coefficients of a hull with capytaine (the optional extra ``oceangnc[hydro]``).

capytaine (Ancellin & Dias 2019, *Capytaine: a Python-based linear potential flow solver*, JOSS 4(36)
1341) solves the radiation and diffraction problems of linear potential flow with a boundary element
method (Delhommeau's Green function). :func:`compute` runs it for a :class:`HullSpec` - a parametric
barge or a mesh file - at ``n_omega`` frequencies and ``n_headings`` wave headings, and returns a
:class:`~oceangnc.hydro.coefficients.HydroCoefficients` in the USV's body frame (x forward, y
starboard, z down; capytaine's frame has y to port and z up, so the sway, heave, pitch and yaw rows
and columns change sign, and a capytaine wave direction beta is the heading mu = -beta).
:func:`cached` keeps the result in ``<cache root>/hydro/<hash>.npz``, keyed by the hull's inputs.

**003's USV** (:func:`usv003_hull`). 003 ch. 5 builds it on a commercial rubber boat: L x W x H 3.00 x
1.62 x 0.47 m (table 5-1), Lpp 2.5 m and 200 kg (table 2-2; table 2-2 prints the beam as 1.82 m,
SPEC.md). A rubber boat is a mono-hull - a flat floor between two buoyancy tubes - and at 200 kg it
floats on its floor: the displaced volume 0.195 m^3 over the 2.5 x 1.62 m floor is a 4.8 cm draught, and
the tubes stay mostly dry. It is modelled as a rectangular barge of the waterline length Lpp = 2.5 m,
the beam 1.62 m of the built vehicle (table 5-1) and the draught that floats 200 kg; the mass is
that of a uniform box of L x W x H (3.0 x 1.62 x 0.47 m) for the radii of gyration (the yaw inertia is
the manoeuvring model's choice, :class:`~oceangnc.models.usv.USVConfig`), the centre of gravity at
half its height. A barge overestimates the waterplane's fullness of a boat with a pointed bow (block
coefficient 1 instead of about 0.6-0.8) and so its heave and pitch stiffness at the ends: a stated
simplification (docs/sea-state.md).
"""

from __future__ import annotations

import logging
import math
import os
from pathlib import Path
from typing import Literal

import numpy as np
from pydantic import Field

from ..errors import ConfigError, InputError
from ..io.config import StrictModel
from .coefficients import FILE_VERSION, HydroCoefficients, inputs_hash

HYDRO_HINT = "capytaine is not installed: install the extra with pip install 'oceangnc[hydro]'"
#: capytaine frame (y port, z up) <-> body frame (y starboard, z down): diag(T)
T_FLIP = np.array([1.0, -1.0, -1.0, 1.0, -1.0, -1.0])


class MissingCapytaine(ConfigError):
    """capytaine is needed and absent (a one-line error naming the extra)."""


class HullSpec(StrictModel):
    """A hull for :func:`compute`: a parametric barge (``kind = "barge"``) or a mesh file (``"mesh"``)."""

    kind: Literal["barge", "mesh"] = Field("barge", description="parametric barge or a mesh file")
    mesh: str | None = Field(None, description="mesh file (any format capytaine reads; kind = mesh), z up, m")
    length: float = Field(2.5, gt=0, le=500, description="waterline length (003 table 2-2: Lpp), m")
    beam: float = Field(1.62, gt=0, le=100, description="waterline beam (003 table 5-1), m")
    draught: float | None = Field(None, gt=0, le=50, description="draught (default: the one that floats mass), m")
    mass: float = Field(200.0, gt=0, le=1e8, description="mass (003 table 2-2), kg")
    length_oa: float = Field(3.0, gt=0, le=500, description="length of the box whose inertia the mass has, m")
    height: float = Field(0.47, gt=0, le=100, description="height of that box (003 table 5-1), m")
    cog_above_wl: float | None = Field(
        None, ge=-50, le=50, description="centre of gravity above the waterline (default: half the height), m"
    )
    panel: float = Field(0.1, gt=0.005, le=10, description="largest panel size, m")
    omega_min: float = Field(0.25, gt=0, le=50, description="lowest wave frequency, rad/s")
    omega_max: float = Field(10.0, gt=0, le=100, description="highest wave frequency, rad/s")
    n_omega: int = Field(36, ge=4, le=400, description="number of frequencies")
    n_headings: int = Field(12, ge=1, le=72, description="number of wave headings over 360 deg")
    roll_damping_ratio: float = Field(
        0.1, ge=0, le=1, description="viscous roll damping, fraction of critical (in the RAO and the drift)"
    )
    drift: bool = Field(True, description="compute the mean drift force (far-field, Kochin functions)")
    rho: float = Field(1025.0, gt=900, le=1100, description="water density, kg/m3")
    g: float = Field(9.81, gt=9, le=10.5, description="gravity, m/s2")

    def checked(self) -> HullSpec:
        if self.omega_max <= self.omega_min:
            raise ConfigError(f"omega_max = {self.omega_max:g}: must be above omega_min = {self.omega_min:g} rad/s")
        if self.kind == "mesh" and not self.mesh:
            raise ConfigError("mesh: a mesh file is needed for kind = 'mesh'")
        if self.kind == "mesh" and not Path(str(self.mesh)).is_file():
            raise InputError(f"mesh file {self.mesh}: not found")
        return self

    def barge_draught(self) -> float:
        """The draught (m): given, or the one that floats the mass, m / (rho L B)."""
        return self.draught if self.draught is not None else self.mass / (self.rho * self.length * self.beam)

    def omegas(self) -> np.ndarray:
        return np.linspace(self.omega_min, self.omega_max, self.n_omega)

    def headings(self) -> np.ndarray:
        """Wave headings mu (rad) in [0, 2 pi): the direction of travel relative to the bow, to starboard."""
        return np.arange(self.n_headings) * (2.0 * math.pi / self.n_headings)


def usv003_hull() -> HullSpec:
    """The hull of 003's USV (module docstring): the committed file's inputs."""
    return HullSpec()


def require_capytaine():
    """Import capytaine or raise :class:`MissingCapytaine` (one line naming the extra)."""
    try:
        import capytaine as cpt
    except ImportError:
        raise MissingCapytaine(HYDRO_HINT) from None
    return cpt


def rigid_body_mass(mass: float, gyration: tuple[float, float, float], r_g: tuple[float, float, float]) -> np.ndarray:
    """6x6 rigid-body mass matrix about the reference point of a body of ``mass`` (kg) with radii of
    gyration (m) about its centre of gravity at ``r_g`` (m, body frame): M = [[m I, -m S(r_g)],
    [m S(r_g), I_g - m S(r_g)^2]] (Fossen 2021, eq. 3.44-3.45, S the cross-product matrix)."""
    x, y, z = r_g
    S = np.array([[0.0, -z, y], [z, 0.0, -x], [-y, x, 0.0]])
    Ig = mass * np.diag(np.square(gyration))
    M = np.zeros((6, 6))
    M[:3, :3] = mass * np.eye(3)
    M[:3, 3:] = -mass * S
    M[3:, :3] = mass * S
    M[3:, 3:] = Ig - mass * S @ S
    return M


def _body(spec: HullSpec, cpt):
    """(capytaine FloatingBody, body-frame rigid-body mass matrix, description dict)."""
    if spec.kind == "barge":
        T = spec.barge_draught()
        nx = max(2, math.ceil(spec.length / spec.panel))
        ny = max(2, math.ceil(spec.beam / spec.panel))
        nz = max(1, math.ceil(T / spec.panel))
        mesh = cpt.mesh_parallelepiped(
            size=(spec.length, spec.beam, T), center=(0.0, 0.0, -T / 2.0), resolution=(nx, ny, nz),
            missing_sides={"top"},
        )  # fmt: skip
        mass = spec.rho * spec.length * spec.beam * T
        zg_up = spec.cog_above_wl if spec.cog_above_wl is not None else spec.height / 2.0 - T
        L, B, H = spec.length_oa, spec.beam, spec.height
        gyr = (math.sqrt((B * B + H * H) / 12.0), math.sqrt((L * L + H * H) / 12.0), math.sqrt((L * L + B * B) / 12.0))
        cog = (0.0, 0.0, zg_up)
        desc: dict = {"draught": T}
    else:
        try:
            mesh = cpt.load_mesh(spec.mesh)
        except Exception as e:  # capytaine raises several kinds for an unreadable file
            raise InputError(f"mesh file {spec.mesh}: capytaine cannot read it ({type(e).__name__}: {e})") from None
        mesh = mesh.immersed_part()
        vol = float(mesh.volume)
        if not (vol > 0):
            raise InputError(f"mesh file {spec.mesh}: no immersed volume below z = 0")
        mass = spec.rho * vol
        cb = np.asarray(mesh.center_of_buoyancy if hasattr(mesh, "center_of_buoyancy") else (0, 0, 0), float)
        zg_up = spec.cog_above_wl if spec.cog_above_wl is not None else 0.0
        lx = float(np.ptp(mesh.vertices[:, 0]))
        ly = float(np.ptp(mesh.vertices[:, 1]))
        H = spec.height
        gyr = (math.sqrt((ly**2 + H * H) / 12.0), math.sqrt((lx**2 + H * H) / 12.0), math.sqrt((lx**2 + ly**2) / 12.0))
        cog = (float(cb[0]), float(cb[1]), zg_up)
        desc = {"volume": vol}
    body = cpt.FloatingBody(
        mesh=mesh, dofs=cpt.rigid_body_dofs(rotation_center=(0.0, 0.0, 0.0)), center_of_mass=cog, mass=mass
    )
    M = rigid_body_mass(mass, gyr, (cog[0], -cog[1], -cog[2]))  # body frame: y, z flipped
    desc.update({"mass": mass, "cog_body": [cog[0], -cog[1], -cog[2]], "gyration": list(gyr), "panels": mesh.nb_faces})
    return body, M, desc


def compute(spec: HullSpec, progress: bool = False) -> HydroCoefficients:
    """Run capytaine for ``spec`` (module docstring); a few seconds to minutes with the panel count."""
    spec = spec.checked()
    cpt = require_capytaine()
    import xarray as xr

    if not progress:
        cpt.set_logging("ERROR")
        logging.getLogger("capytaine").setLevel(logging.ERROR)
    body, M, desc = _body(spec, cpt)
    w = spec.omegas()
    mu = spec.headings()
    beta = np.mod(-mu, 2.0 * math.pi)  # capytaine's wave directions
    order = np.argsort(beta)
    dofs = list(body.dofs)
    coords = {
        "omega": w,
        "wave_direction": beta[order],
        "radiating_dof": dofs,
        "influenced_dof": dofs,
        "rho": spec.rho,
        "g": spec.g,
        "water_depth": np.inf,
    }
    if spec.drift:
        coords["theta"] = np.linspace(-0.3, 2.0 * math.pi + 0.3, 121)
    inf = {"omega": [np.inf], "radiating_dof": dofs, "influenced_dof": dofs, "rho": spec.rho, "g": spec.g}
    solver = cpt.BEMSolver()
    kw = {"progress_bar": bool(progress)}
    ds = solver.fill_dataset(xr.Dataset(coords=coords), body, **kw)
    ds_inf = solver.fill_dataset(xr.Dataset(coords=inf), body, **kw)
    fin = ds
    inv = np.argsort(order)  # back to the order of mu
    t = T_FLIP
    A = fin["added_mass"].values * t[None, :, None] * t[None, None, :]
    B = fin["radiation_damping"].values * t[None, :, None] * t[None, None, :]
    A_inf = ds_inf["added_mass"].isel(omega=0).values * t[:, None] * t[None, :]
    X = (
        fin["excitation_force"].transpose("omega", "wave_direction", "influenced_dof").values[:, inv, :]
        * t[None, None, :]
    )
    C = ds["hydrostatic_stiffness"].values * t[:, None] * t[None, :]
    hull = {**spec.model_dump(), **desc, "capytaine": getattr(cpt, "__version__", "?")}
    coeffs = HydroCoefficients(
        omega=w, headings=mu, A=A, B=B, A_inf=A_inf, C=C, M=M, X=X, rho=spec.rho, g=spec.g, hull=hull,
        inputs_hash=spec_hash(spec),
    )  # fmt: skip
    if spec.drift:
        coeffs.drift = _drift(coeffs, ds, fin, order, inv, spec, cpt)
    coeffs.check("capytaine result")
    return coeffs


def _drift(coeffs: HydroCoefficients, ds, fin, order, inv, spec: HullSpec, cpt) -> np.ndarray:
    """Mean drift (nw, nb, 3) per a^2 in the body frame: capytaine's far-field (Maruo 1960) surge and sway
    forces and yaw moment with the motions of the RAO (viscous roll damping included)."""
    import xarray as xr

    Bv = coeffs.roll_damping(spec.roll_damping_ratio)
    rao = coeffs.raos(Bv)[:, order, :] * T_FLIP[None, None, :]  # back to capytaine's frame and order
    dims = ("omega", "wave_direction", "radiating_dof")
    coords = {k: fin[k].values for k in dims}
    X = xr.DataArray(rao, dims=dims, coords=coords)
    d = cpt.post_pro.far_field_mean_drift_force(X, fin)
    nb = coeffs.headings.size
    out = np.zeros((coeffs.omega.size, nb, 3))
    for k, (name, sign) in enumerate(
        (("drift_force_surge", 1.0), ("drift_force_sway", -1.0), ("drift_force_yaw", -1.0))
    ):
        diag = np.real(np.stack([d[name].values[:, j, j] for j in range(nb)], axis=1))
        out[:, :, k] = sign * diag[:, inv]
    return out


def spec_hash(spec: HullSpec) -> str:
    """:func:`~oceangnc.hydro.coefficients.inputs_hash` of a spec (with its mesh file's bytes)."""
    mesh_bytes = Path(spec.mesh).read_bytes() if spec.kind == "mesh" and spec.mesh else None
    d = spec.model_dump()
    d["mesh"] = None  # the content counts, not the path
    return inputs_hash(d, mesh_bytes)


def cache_path(spec: HullSpec) -> Path:
    """Where :func:`cached` keeps the coefficients of ``spec``."""
    from ..core.caches import cache_root

    return cache_root() / "hydro" / f"hull-v{FILE_VERSION}-{spec_hash(spec)}.npz"


def cached(spec: HullSpec, progress: bool = False) -> tuple[HydroCoefficients, bool]:
    """(coefficients of ``spec``, True when read from the cache): computed once per set of inputs."""
    spec = spec.checked()
    path = cache_path(spec)
    if path.is_file():
        try:
            c = HydroCoefficients.load(path)
            if c.inputs_hash == spec_hash(spec):
                return c, True
        except InputError:
            pass  # a damaged cache entry: recompute
    c = compute(spec, progress)
    if os.environ.get("OCEANGNC_NO_HYDRO_CACHE") is None:
        c.save(path)
    return c, False
