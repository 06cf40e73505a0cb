"""Plots drawn from run logs (matplotlib, Agg backend, PNG files).

Conventions: tracks are drawn with east (y) to the right and north (x) up, as on a chart.

Cost: a run's plots used to take longer than its simulation. The helpers here build a bare
:class:`matplotlib.figure.Figure` (no pyplot, no figure manager), place the axes with fixed margins
instead of ``tight_layout`` (which lays every tick label out twice, ~0.1 s per figure) and save at
100 dpi; :func:`figure` gives scenario modules the same cheap figure.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np


def pyplot():
    """matplotlib.pyplot on the Agg backend, imported on first use (it costs ~1 s at start-up)."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    return plt


def figure(figsize, margins: tuple[float, float, float, float] = (0.95, 0.45, 0.15, 0.45), **kw):
    """A pyplot-free Agg figure with fixed margins (inches: left, bottom, right, top); ``kw`` to Figure."""
    from matplotlib.figure import Figure

    fig = Figure(figsize=figsize, **kw)
    w, h = figsize
    left, bottom, right, top = margins
    fig.subplots_adjust(left=left / w, bottom=bottom / h, right=1 - right / w, top=1 - top / h)
    return fig


def save(fig, path: Path, dpi: int = 100) -> Path:
    """Write ``fig`` as PNG (Agg canvas) and free it."""
    from matplotlib.backends.backend_agg import FigureCanvasAgg

    FigureCanvasAgg(fig)
    fig.savefig(path, dpi=dpi)
    fig.clear()
    return path


_save = save


def plot_track(df, bodies: list[str], path: Path, title: str = "", waypoints=None, extra=None) -> Path:
    """Plan view of the bodies' tracks (east right, north up), with optional waypoints (N, E)."""
    fig = figure((6.5, 6), margins=(0.8, 0.6, 0.2, 0.4))
    ax = fig.add_subplot()
    for b in bodies:
        if f"{b}.x" in df and f"{b}.y" in df:
            ax.plot(df[f"{b}.y"], df[f"{b}.x"], label=b)
            ax.plot(df[f"{b}.y"].iloc[0], df[f"{b}.x"].iloc[0], "o", color="k", ms=4)
    if waypoints is not None and len(waypoints):
        wp = np.asarray(waypoints, dtype=float)
        ax.plot(wp[:, 1], wp[:, 0], "k--", lw=0.8)
        ax.plot(wp[:, 1], wp[:, 0], "ks", ms=5, label="waypoints")
    if extra is not None:
        extra(ax)
    ax.set_xlabel("east y [m]")
    ax.set_ylabel("north x [m]")
    ax.set_aspect("equal", adjustable="datalim")
    ax.grid(True, alpha=0.3)
    ax.legend(loc="best", fontsize=8)
    ax.set_title(title)
    return _save(fig, path)


def plot_signals(df, groups: list[tuple[str, list[tuple[str, str, float]]]], path: Path, title: str = "") -> Path:
    """Stacked time plots. ``groups`` = [(ylabel, [(column, label, scale), ...]), ...]."""
    groups = [(lab, [c for c in cols if c[0] in df]) for lab, cols in groups]
    groups = [g for g in groups if g[1]]
    if not groups:
        groups = [("(no signals)", [])]
    fig = figure((8, 1.9 * len(groups) + 0.6), margins=(0.9, 0.55, 0.2, 0.35))
    axes = fig.subplots(len(groups), 1, sharex=True, squeeze=False)
    fig.subplots_adjust(hspace=0.12)
    for ax, (ylabel, cols) in zip(axes[:, 0], groups):
        for col, label, scale in cols:
            ax.plot(df["t"], df[col] * scale, label=label)
        ax.set_ylabel(ylabel)
        ax.grid(True, alpha=0.3)
        if len(cols) > 1:
            ax.legend(loc="best", fontsize=7)
    axes[-1, 0].set_xlabel("time t [s]")
    axes[0, 0].set_title(title)
    return _save(fig, path)


def plot_3d(df, path: Path, title: str = "", n_snap: int = 8) -> Path:
    """3D trajectories (east, north, depth down) with the cable drawn at ``n_snap`` instants (003 fig 4-7)."""
    import matplotlib.pyplot as plt

    fig = plt.figure(figsize=(7, 6))
    ax = fig.add_subplot(projection="3d")
    ax.plot(df["usv.y"], df["usv.x"], 0 * df["usv.x"], label="USV")
    ax.plot(df["uuv.y"], df["uuv.x"], -df["uuv.z"], label="UUV")
    n = 0
    while f"cable.x{n}" in df:
        n += 1
    if n:
        for k in np.linspace(0, len(df) - 1, n_snap).astype(int):
            row = df.iloc[k]
            xs = [row[f"cable.x{i}"] for i in range(n)]
            ys = [row[f"cable.y{i}"] for i in range(n)]
            zs = [-row[f"cable.z{i}"] for i in range(n)]
            ax.plot(ys, xs, zs, "k.-", lw=0.8, ms=2)
    ax.set_xlabel("east y [m]")
    ax.set_ylabel("north x [m]")
    ax.set_zlabel("-depth [m]")
    ax.set_title(title)
    ax.legend(fontsize=8)
    fig.tight_layout()
    fig.savefig(path, dpi=100)
    plt.close(fig)
    return path
