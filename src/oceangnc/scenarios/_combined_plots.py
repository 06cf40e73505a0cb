"""Plots of the combined USV-cable-UUV scenarios (003 figs 4-7 to 4-15), one job per figure.

The jobs are independent (see :meth:`oceangnc.scenarios.base.Scenario.plot_jobs`), so
:mod:`oceangnc.postproc` can draw them in two processes; the 3-D view is the costliest and comes first.
"""

from __future__ import annotations

from functools import partial
from pathlib import Path

import numpy as np

from ..io.plots import figure, plot_signals, plot_track, save
from ..units import KGF

DEG = 180.0 / np.pi


def rel_distance(df) -> np.ndarray:
    """Horizontal USV-UUV distance (m) of every log row."""
    return np.hypot(df["usv.x"] - df["uuv.x"], df["usv.y"] - df["uuv.y"]).to_numpy()


def plot_jobs(name: str, df, cfg, out_dir: Path) -> list:
    """The six figures of a combined scenario's run as jobs (callables returning ``[path]``)."""
    out_dir = Path(out_dir)
    df = df.copy()
    df["rel.distance"] = rel_distance(df)
    for col in ("usv.psi", "guidance.psi_d", "uuv.psi", "uuv_ctrl.psi_d"):
        if col in df:
            df[col + "_deg"] = np.degrees(np.unwrap(df[col].to_numpy()))
    wp = cfg.guidance.waypoints

    def signals(groups, file, title):
        return [plot_signals(df, groups, out_dir / file, title=f"{name}: {title}")]

    speeds = [
        ("surge speed [m/s]", [("usv.u", "USV u", 1.0), ("usv_ctrl.u_d", "USV target", 1.0), ("uuv.u", "UUV u", 1.0)]),
        ("sway speed [m/s]", [("usv.v", "USV v", 1.0), ("uuv.v", "UUV v", 1.0)]),
        ("yaw rate [deg/s]", [("usv.r", "USV r", DEG), ("uuv.r", "UUV r", DEG)]),
    ]
    thrusts = [
        ("USV thrust [kgf]", [("usv.thrust_port", "port (L)", 1 / KGF), ("usv.thrust_stbd", "stbd (R)", 1 / KGF)]),
        (
            "UUV thrust [N]",
            [
                ("uuv.thrust_port", "port (L)", 1.0),
                ("uuv.thrust_stbd", "stbd (R)", 1.0),
                ("uuv.thrust_bow", "bow (F)", 1.0),
            ],
        ),
    ]
    headings = [
        ("USV heading [deg]", [("usv.psi_deg", "psi", 1.0), ("guidance.psi_d_deg", "target", 1.0)]),
        ("UUV heading [deg]", [("uuv.psi_deg", "psi", 1.0), ("uuv_ctrl.psi_d_deg", "target", 1.0)]),
    ]
    depth = [
        ("UUV depth [m]", [("uuv.z", "true", 1.0), ("depth.z", "depth sensor (filtered)", 1.0)]),
        ("rel. distance [m]", [("rel.distance", "true horizontal", 1.0), ("lf.range", "as measured", 1.0)]),
        ("cable tension [N]", [("cable.top_tension", "top", 1.0), ("cable.bottom_tension", "bottom", 1.0)]),
    ]
    # the costliest first: the two drawers of oceangnc.postproc take jobs in this order
    return [
        lambda: [plot_3d(df, out_dir / "trajectory3d.png", title=f"{name}: 3D trajectory")],
        partial(signals, speeds, "speeds.png", "speeds (cf. 003 fig 4-9)"),
        partial(signals, depth, "depth_distance.png", "depth and distance (cf. 003 figs 4-14, 4-15)"),
        partial(signals, thrusts, "thrusts.png", "thrusts (cf. 003 figs 4-10, 4-11)"),
        partial(signals, headings, "headings.png", "headings (cf. 003 figs 4-12, 4-13)"),
        lambda: [
            plot_track(
                df, ["usv", "uuv"], out_dir / "track.png", title=f"{name} ({cfg.control.uuv.kind})", waypoints=wp
            )
        ],
    ]


def plot_3d(df, path: Path, title: str = "", n_snap: int = 8) -> Path:
    """3D trajectories (east, north, depth down) with the cable drawn at ``n_snap`` instants (003 fig 4-7).

    A bare Agg figure with fixed margins (those ``tight_layout`` gave for this figure), no pyplot.
    """
    import mpl_toolkits.mplot3d  # noqa: F401  (registers the "3d" projection)

    fig = figure((7, 6), margins=(0.15, 0.17, 0.15, 0.36))
    ax = fig.add_subplot(projection="3d")
    ax.plot(df["usv.y"], df["usv.x"], 0 * df["usv.x"], label="USV")
    ax.plot(df["uuv.y"], df["uuv.x"], -df["uuv.z"], label="UUV")
    n = 0
    while f"cable.x{n}" in df:
        n += 1
    if n:
        xs = df[[f"cable.x{i}" for i in range(n)]].to_numpy()
        ys = df[[f"cable.y{i}" for i in range(n)]].to_numpy()
        zs = df[[f"cable.z{i}" for i in range(n)]].to_numpy()
        for k in np.linspace(0, len(df) - 1, n_snap).astype(int):
            ax.plot(ys[k], xs[k], -zs[k], "k.-", lw=0.8, ms=2)
    ax.set_xlabel("east y [m]")
    ax.set_ylabel("north x [m]")
    ax.set_zlabel("-depth [m]")
    ax.set_title(title)
    ax.legend(fontsize=8)
    return save(fig, path)
