"""``oceangnc.hydro.bem`` (capytaine) on a coarse mesh, and ``oceangnc hydro``.

Kinds of evidence: physical laws that tie capytaine's separate solutions together - the Haskind relation
(Newman 1977, *Marine Hydrodynamics*, sec. 6.19; Falnes 2002, *Ocean Waves and Oscillating Systems*,
eq. 5.141: in deep water B_jj = w k / (4 pi rho g^2) int_0^2pi |X_j(beta)|^2 dbeta, which for the heave
of an axisymmetric body is B_33 = w^3 |X_3|^2 / (2 rho g^3)) links the radiation damping of the
radiation problem to the excitation force of the diffraction problem; the hydrostatic stiffness
C_33 = rho g A_wp against the waterplane area of the mesh's designed polygon; the cache returns what was
computed. The capytaine tests are skipped only when capytaine (an optional third-party package, the
extra ``oceangnc[hydro]``) is not installed.
"""

from __future__ import annotations

import math
import sys

import numpy as np
import pytest

from oceangnc.cli import main


def cylinder_gdf(path, radius=1.0, draught=1.0, nt=16, nz=3, nr=3):
    """The wetted surface of a truncated vertical cylinder (z up, waterline z = 0) as a WAMIT .gdf file:
    ``nt`` sides, ``nz`` panels down the side, ``nr`` rings on the bottom (a centre fan of triangles)."""
    th = np.linspace(0.0, 2.0 * math.pi, nt, endpoint=False)
    verts: list[tuple[float, float, float]] = []

    def vid(x, y, z):
        verts.append((x, y, z))
        return len(verts) - 1

    side = [[vid(radius * math.cos(t), radius * math.sin(t), -draught * k / nz) for t in th] for k in range(nz + 1)]
    faces = [
        (side[k][i], side[k + 1][i], side[k + 1][(i + 1) % nt], side[k][(i + 1) % nt])
        for k in range(nz)
        for i in range(nt)
    ]
    rings = [side[nz]]
    for m in range(1, nr):
        f = (nr - m) / nr
        rings.append([vid(radius * f * math.cos(t), radius * f * math.sin(t), -draught) for t in th])
    for m in range(nr - 1):
        for i in range(nt):
            j = (i + 1) % nt
            faces.append((rings[m][i], rings[m + 1][i], rings[m + 1][j], rings[m][j]))
    c = vid(0.0, 0.0, -draught)
    faces += [(rings[-1][i], c, rings[-1][(i + 1) % nt], rings[-1][(i + 1) % nt]) for i in range(nt)]
    lines = ["truncated vertical cylinder", "1.0 9.81", "0 0", str(len(faces))]
    for fc in faces:
        lines += [" ".join(f"{v:.9f}" for v in verts[i]) for i in fc]
    path.write_text("\n".join(lines) + "\n")
    return path


@pytest.fixture(scope="module")
def cylinder(tmp_path_factory):
    pytest.importorskip("capytaine")
    from oceangnc.hydro.bem import HullSpec, cached

    d = tmp_path_factory.mktemp("hydro")
    mesh = cylinder_gdf(d / "cyl.gdf")
    spec = HullSpec(kind="mesh", mesh=str(mesh), omega_min=1.0, omega_max=2.0, n_omega=4, n_headings=4, drift=False)
    c, hit = cached(spec)
    return spec, c, hit


def test_haskind_relation_heave(cylinder):
    """capytaine's heave radiation damping equals the Haskind relation's value from its diffraction
    force (two separate boundary-value problems), within 2 %; the force does not depend on heading."""
    _, c, _ = cylinder
    X = c.X[:, :, 2]
    assert np.allclose(np.abs(X), np.abs(X[:, :1]), rtol=1e-6)
    haskind = c.omega**3 * np.abs(X[:, 0]) ** 2 / (2.0 * c.rho * c.g**3)
    np.testing.assert_allclose(c.B[:, 2, 2], haskind, rtol=0.02)
    assert np.all(c.B[:, 2, 2] > 0)


def test_hydrostatic_stiffness_is_rho_g_waterplane(cylinder):
    """C_33 = rho g A_wp with A_wp the designed 16-gon's area (nt/2 r^2 sin(2 pi/nt)), and the mass is
    the displaced water of that prism (rho A_wp T)."""
    _, c, _ = cylinder
    awp = 16 / 2 * math.sin(2 * math.pi / 16)
    assert c.C[2, 2] == pytest.approx(c.rho * c.g * awp, rel=1e-6)
    assert c.M[0, 0] == pytest.approx(c.rho * awp * 1.0, rel=1e-6)


def test_cache_returns_the_computed_file(cylinder, tmp_path):
    from oceangnc.hydro.bem import cache_path, cached
    from oceangnc.hydro.coefficients import HydroCoefficients

    spec, c, _ = cylinder
    again, hit = cached(spec)
    assert hit
    np.testing.assert_array_equal(again.X, c.X)
    assert HydroCoefficients.load(cache_path(spec)).inputs_hash == c.inputs_hash


def test_cli_hydro_file_without_capytaine(monkeypatch, tmp_path, capsys):
    """``oceangnc hydro --file committed`` needs no capytaine: table and hydro.png; computing without it
    is one line naming the extra, exit 2; a bad hull key is one line, exit 2."""
    monkeypatch.setitem(sys.modules, "capytaine", None)
    assert main(["hydro", "--file", "committed", "--out", str(tmp_path)]) == 0
    out = capsys.readouterr().out
    assert "C33 40724 N/m" in out and "RAO amplitudes" in out
    assert (tmp_path / "hydro.png").stat().st_size > 10_000
    monkeypatch.setenv("OCEANGNC_CACHE_DIR", str(tmp_path / "empty-cache"))
    assert main(["hydro", "--set", "n_omega=5", "--no-plot"]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and "oceangnc[hydro]" in err[0]
    assert main(["hydro", "--set", "beam=-1", "--no-plot"]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and "beam" in err[0]
