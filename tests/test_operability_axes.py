"""Issue 41: the operability report names its axes from the swept keys, and its PNG title fits the figure.

On the code at the issue's filing a sweep over Hs and the wave heading was titled "Hs \\ Tp" with the
headings printed as "0 s", the diagram's x axis read "Tp [s]", and the title ran off a one-panel figure."""

from __future__ import annotations

import matplotlib.pyplot as plt
import pandas as pd

from oceangnc.sweep.operability import operability, operability_figure, operability_table


def _results(keys: dict) -> pd.DataFrame:
    rows = []
    (k1, v1), (k2, v2) = keys.items()
    for a in v1:
        for b in v2:
            ok = a < 2.0
            rows.append({f"param.{k1}": a, f"param.{k2}": b, "status": "ok", "sea.pass": int(ok),
                         "limits.tension_ok": int(ok), "limits.no_snap": 1})  # fmt: skip
    return pd.DataFrame(rows)


def test_a_sweep_over_hs_and_heading_is_labelled_so(tmp_path):
    df = _results({"environment.waves.hs": [0.5, 2.5], "environment.waves.direction_deg": [0.0, 90.0, 180.0]})
    operability(df, tmp_path, plots=False)
    md = (tmp_path / "operability.md").read_text()
    assert "| Hs \\ wave heading | 0 deg | 90 deg | 180 deg |" in md
    assert "Tp" not in md and " s |" not in md
    assert "| 2.5 m | T | T | T |" in md
    t, hs_key, tp_key, panels = operability_table(df)
    fig = operability_figure(t, hs_key, tp_key, panels, "operability: tow-sea-state over Hs and heading")
    ax = fig.axes[0]
    assert ax.get_xlabel() == "wave heading [deg]" and ax.get_ylabel() == "Hs [m]"
    plt.close(fig)


def test_hs_by_tp_keeps_its_labels_and_the_title_fits_a_one_panel_figure():
    df = _results({"environment.waves.hs": [0.5, 2.5], "environment.waves.tp": [6.0, 8.0]})
    t, hs_key, tp_key, panels = operability_table(df)
    fig = operability_figure(t, hs_key, tp_key, panels, "operability: tow-sea-state, 4 sea states, 1 seed each")
    assert fig.axes[0].get_xlabel() == "Tp [s]"
    fig.canvas.draw()
    box = fig._suptitle.get_window_extent(fig.canvas.get_renderer())
    assert box.x0 >= 0 and box.x1 <= fig.bbox.width and box.y1 <= fig.bbox.height
    plt.close(fig)
