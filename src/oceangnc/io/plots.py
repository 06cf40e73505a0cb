"""Plots drawn from run logs (matplotlib, Agg backend, PNG files).

Conventions: tracks are drawn with east (y) to the right and north (x) up, as on a chart.

Cost: a run's plots used to take longer than its simulation. The helpers here build a bare
:class:`matplotlib.figure.Figure` (no pyplot, no figure manager), place the axes with fixed margins
instead of ``tight_layout`` (which lays every tick label out twice, ~0.1 s per figure) and save at
100 dpi with fast PNG compression; :func:`figure` gives scenario modules the same cheap figure. A run's
figures are drawn in two forked processes while the simulation runs (:mod:`oceangnc.postproc`).
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
    """Write ``fig`` as PNG (Agg canvas).

    zlib level 1 instead of PIL's 6: the same pixels (PNG is lossless), files ~15 % larger, and the
    encoding about 3x faster (it was a third of a simple figure's time). The figure is not cleared:
    ``Figure.clear`` re-initialises every axes before dropping it (~20 ms each); without pyplot
    nothing else holds the figure, so it is freed with its last reference.
    """
    from matplotlib.backends.backend_agg import FigureCanvasAgg

    FigureCanvasAgg(fig)
    fig.savefig(path, dpi=dpi, pil_kwargs={"compress_level": 1})
    return path


_save = save


def warm_up() -> None:
    """Import the drawing machinery and draw one small figure in memory (fonts, ticks, text layout,
    the 3-D projection): the one-off cost of a process's first plot, paid ahead of time by
    :mod:`oceangnc.postproc`'s helper while the simulation runs."""
    import io

    import mpl_toolkits.mplot3d  # noqa: F401
    from matplotlib.backends.backend_agg import FigureCanvasAgg

    fig = figure((2, 2))
    ax = fig.add_subplot()
    ax.plot([0.0, 1.0], [0.0, 1.0], label="x")
    ax.set_xlabel("t [s]")
    ax.set_title("warm-up")
    ax.legend(fontsize=7)
    FigureCanvasAgg(fig)
    fig.savefig(io.BytesIO(), format="png", dpi=20)


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
