"""``oceangnc hydro``: compute and show a hull's hydrodynamic coefficients and RAOs.

    oceangnc hydro                                   # 003's USV, computed with capytaine (cached)
    oceangnc hydro --set beam=1.82 --set n_omega=24  # a variant of the parametric barge
    oceangnc hydro --mesh hull.gdf --set cog_above_wl=0.2
    oceangnc hydro --file committed                  # the committed file (no capytaine needed)
    oceangnc hydro --save usv.npz                    # also write the coefficient file

Prints the hull, its hydrostatics and natural periods, the radiation fit and a table of heave, roll
and pitch RAOs; draws ``hydro.png`` (A, B with the fitted model, |X|, RAOs) in ``--out``. Bad input:
one line, exit 2; computing without capytaine: one line naming the extra ``oceangnc[hydro]``.
"""

from __future__ import annotations

import math
import sys
from pathlib import Path

from ..cli_options import add_set


def register(sub) -> None:
    p = sub.add_parser("hydro", help="hydrodynamic coefficients and RAOs of a hull (capytaine; oceangnc[hydro])")
    p.add_argument("--file", help="show a coefficient file instead of computing ('committed': 003's USV)")
    p.add_argument("--mesh", help="hull mesh file (gdf, stl, ... as capytaine reads; z up, waterline z = 0)")
    add_set(p, "a hull key (length, beam, draught, mass, height, panel, n_omega, n_headings, ...)")
    p.add_argument("--save", help="write the coefficient file (.npz) here")
    p.add_argument("--out", help="folder of hydro.png (default runs/hydro-<time>)")
    p.add_argument("--no-plot", action="store_true", help="print the tables only")
    p.add_argument("--roll-damping", type=float, help="viscous roll damping ratio of the RAO (default: the file's)")
    p.add_argument("--progress", action="store_true", help="show capytaine's progress")
    p.set_defaults(func=_cmd_hydro)


def _coefficients(args):
    from ..core.config import validate
    from ..errors import ConfigError
    from .bem import HullSpec, cached
    from .coefficients import default_usv_coefficients, load_coefficients

    if args.file:
        if args.mesh or args.set:
            raise ConfigError("--file: shows a file as it is; --mesh and --set describe a hull to compute")
        if args.file == "committed":
            return default_usv_coefficients(), "committed file of 003's USV"
        return load_coefficients(args.file), f"file {args.file}"
    from ..cli_options import set_overrides
    from ..io.config import parse_sets

    data = parse_sets(args.set)
    set_overrides(args)  # the same checks on the keys' syntax
    if args.mesh:
        data.update(kind="mesh", mesh=args.mesh)
    spec = validate(HullSpec, data)
    c, hit = cached(spec, progress=args.progress)
    return c, ("cached " if hit else "computed with capytaine, cached ") + "hull"


def _cmd_hydro(args) -> int:
    import numpy as np

    from ..errors import ConfigError
    from .radiation import fit_radiation

    if args.roll_damping is not None and not (0.0 <= args.roll_damping <= 1.0):
        raise ConfigError(f"--roll-damping = {args.roll_damping:g}: allowed range 0 <= value <= 1")
    c, where = _coefficients(args)
    ratio = args.roll_damping if args.roll_damping is not None else float(c.hull.get("roll_damping_ratio", 0.1))
    rad = fit_radiation(c)
    Bx, Cx = c.time_domain_extras(ratio)
    raos = c.raos(Bx, Cx)
    h = c.hull
    print(f"hull: {h.get('kind', '?')} ({where}); {c.omega.size} frequencies {c.omega[0]:.2f}-{c.omega[-1]:.2f} rad/s, "
          f"{c.headings.size} headings; rho {c.rho:g} kg/m3")  # fmt: skip
    if h.get("kind") == "barge":
        print(f"  L {h['length']:g} m, B {h['beam']:g} m, draught {h['draught']:.4f} m, mass {h['mass']:g} kg")
    inertia = " ".join(f"{c.M[k, k]:.1f}" for k in (3, 4, 5))
    print(f"  mass {c.M[0, 0]:.1f} kg, inertia diag {inertia} kg m2 (about the reference point)")
    m = c.M[0, 0]
    print(f"hydrostatics: C33 {c.C[2, 2]:.0f} N/m, C44 {c.C[3, 3]:.0f} N m/rad (GM_T {c.C[3, 3] / (m * c.g):.2f} m), "
          f"C55 {c.C[4, 4]:.0f} N m/rad (GM_L {c.C[4, 4] / (m * c.g):.2f} m)")  # fmt: skip
    periods = []
    for k, name in ((2, "heave"), (3, "roll"), (4, "pitch")):
        w = math.sqrt(c.C[k, k] / (c.M[k, k] + c.A_inf[k, k]))
        for _ in range(50):
            a = float(c.interp_omega("A", np.array([w]))[0, k, k])
            w = math.sqrt(c.C[k, k] / (c.M[k, k] + a))
        periods.append(f"{name} {2 * math.pi / w:.2f} s")
    print("natural periods: " + ", ".join(periods) + f"; roll damping {ratio:g} of critical (viscous)")
    print("A_inf diag: " + " ".join(f"{v:.1f}" for v in np.diag(c.A_inf)))
    print(
        f"radiation fit: {rad.poles.size} poles ({rad.ns} states per DOF), largest error "
        f"{100 * rad.error:.2f} % of each entry's peak"
    )
    sel = [i for i, hh in enumerate(c.headings) if round(math.degrees(hh)) in (0, 90, 180)] or [0]
    iw = np.unique(np.linspace(0, c.omega.size - 1, 8).round().astype(int))
    print("RAO amplitudes (heave m/m, roll deg/m, pitch deg/m); heading = waves' direction of travel from the bow:")
    print(f"{'T (s)':>7} " + " ".join(f"{'mu=' + str(round(math.degrees(c.headings[j]))):>24}" for j in sel))
    for i in iw:
        cells = []
        for j in sel:
            r = np.abs(raos[i, j])
            cells.append(f"{r[2]:7.3f} {math.degrees(r[3]):7.2f} {math.degrees(r[4]):7.2f}")
        print(f"{2 * math.pi / c.omega[i]:7.2f}  " + "  ".join(f"{s:>22}" for s in cells))
    if c.drift is not None:
        j = sel[-1]
        print(
            f"mean drift surge at mu={round(math.degrees(c.headings[j]))}: "
            + " ".join(f"{v:.0f}" for v in c.drift[iw, j, 0])
            + " N/m2"
        )
    if args.save:
        path = c.save(args.save)
        print(f"saved {path}")
    if not args.no_plot:
        from ..api import new_run_dir

        out = Path(args.out) if args.out else new_run_dir("runs", "hydro")
        out.mkdir(parents=True, exist_ok=True)
        png = plot_hydro(c, rad, raos, out / "hydro.png")
        print(f"wrote {png}")
    sys.stdout.flush()
    return 0


def plot_hydro(c, rad, raos, path: Path) -> Path:
    """A(w), B(w) (diagonal heave, roll, pitch with the fitted model dashed), |X| and the heave, roll and
    pitch RAOs against the wave period at every heading in the file."""
    import numpy as np

    from ..io.plots import figure, save

    fig = figure((12, 7.5), margins=(0.8, 0.55, 0.2, 0.35))
    axs = fig.subplots(2, 3)
    fig.subplots_adjust(hspace=0.35)
    wf = np.linspace(c.omega[0], c.omega[-1], 300)
    Af, Bf = rad.added_mass_damping(wf, c.A_inf)
    names = ("heave", "roll", "pitch")
    for k, name in zip((2, 3, 4), names):
        ax = axs[0, 0]
        ax.plot(c.omega, c.A[:, k, k] / max(abs(c.A[:, k, k]).max(), 1e-9), "o", ms=3, label=f"A{k + 1}{k + 1} {name}")
        ax.plot(wf, Af[:, k, k] / max(abs(c.A[:, k, k]).max(), 1e-9), "--", lw=1, color=ax.lines[-1].get_color())
        ax = axs[0, 1]
        ax.plot(c.omega, c.B[:, k, k] / max(abs(c.B[:, k, k]).max(), 1e-9), "o", ms=3, label=f"B{k + 1}{k + 1} {name}")
        ax.plot(wf, Bf[:, k, k] / max(abs(c.B[:, k, k]).max(), 1e-9), "--", lw=1, color=ax.lines[-1].get_color())
    axs[0, 0].set_title("added mass / peak (dots capytaine, dashed state-space fit)", fontsize=9)
    axs[0, 1].set_title("radiation damping / peak", fontsize=9)
    for ax in axs[0, :2]:
        ax.set_xlabel("omega (rad/s)")
        ax.legend(fontsize=7)
    ax = axs[0, 2]
    for j, hh in enumerate(c.headings):
        ax.plot(c.omega, np.abs(c.X[:, j, 2]) / 1e3, lw=1, label=f"{math.degrees(hh):.0f} deg")
    ax.set_title("|X| heave excitation (kN/m)", fontsize=9)
    ax.set_xlabel("omega (rad/s)")
    ax.legend(fontsize=6, ncol=2)
    T = 2 * math.pi / c.omega
    for ax, k, name, unit in zip(axs[1], (2, 3, 4), names, ("m/m", "deg/m", "deg/m")):
        s = 1.0 if k == 2 else 180.0 / math.pi
        for j, hh in enumerate(c.headings):
            if math.degrees(hh) <= 180.0 + 1e-6:
                ax.plot(T, np.abs(raos[:, j, k]) * s, lw=1, label=f"{math.degrees(hh):.0f} deg")
        ax.set_title(f"{name} RAO ({unit})", fontsize=9)
        ax.set_xlabel("wave period (s)")
        ax.set_xlim(0, min(T.max(), 15))
        ax.legend(fontsize=6, ncol=2)
    return save(fig, path)
