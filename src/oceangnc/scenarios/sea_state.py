"""The tow at sea (issue 29): ``tow-sea-state``.

The USV tows the UUV on a 20 m cable along a straight survey line (heading ``command.heading_deg``,
default north) at ``command.usv_speed`` (1 m/s) in an irregular JONSWAP sea (``environment.waves``:
Hs 1 m, Tp 6 s, gamma 3.3, 128 components, long-crested). The waves load every cable segment and the
UUV (Morison drag on the relative velocity, Froude-Krylov and added-mass inertia;
:mod:`oceangnc.models._combined_sea`), and the USV heaves, rolls and pitches (and surges, sways and
yaws) with the waves by Cummins' equation from its hydrodynamic coefficients
(``environment.usv_motions.enabled = true``, this scenario's default; :mod:`oceangnc.models._usv_waves`):
the cable's attachment point follows it in 6 DOF. With ``environment.usv_motions.enabled=false`` the
USV moves as in calm water and the attachment point only heaves with the surface
(``environment.tow_point_heave``: part A of issue 29). The UUV's stern thrust balances its own drag at
the tow speed (its speed loop's gains are 0: feed-forward only) and its bow thruster holds the line's
heading, so the cable carries its weight and the cable's drag: a towed body, as in a survey.

**Wave heading relative to the line**: ``environment.waves.direction_deg - command.heading_deg`` (the
waves travel toward that bearing): 0 following seas, 90 beam seas from port, 180 head seas. With the
default line (north) ``environment.waves.direction_deg`` *is* the relative heading, the key the
operability sweep varies.

Summary (over the rows after ``analysis.settle_s``, the start-up transient left out; the whole log if
that leaves fewer than two rows): the top and bottom tension statistics and slack/snap events
(:func:`oceangnc.tension.tension_statistics`), the UUV's depth, pitch and roll standard deviations
(:func:`oceangnc.tension.motion_statistics`), and pass/fail against ``limits``: the top tension
below ``limits.tension_max_N``, no snap event (unless ``limits.snap_allowed``), the UUV's depth and
pitch standard deviations below ``limits.depth_std_max_m`` and ``limits.pitch_std_max_deg``;
``sea.pass`` is 1 when all hold. Plots: tension, depth and pitch time series
(``sea_timeseries.png``); the tension spectra against the wave spectrum (``sea_spectra.png``).
"""

from __future__ import annotations

import math
from pathlib import Path
from typing import Literal

import numpy as np
from pydantic import Field, model_validator

from ..control.actuators import USVThrusterBlock, UUVThrusterBlock
from ..control.tow import TowCommand, TowStraightControl
from ..core.clock import Simulation
from ..environment import SeaEnvironmentConfig
from ..io.config import ScenarioConfig, SimConfig, StrictModel
from ..io.plots import plot_signals
from ..models.cable import CableConfig
from ..models.combined import CombinedPlant
from ..models.usv import USVConfig
from ..models.uuv import UUVConfig
from ..units import G
from ._common import environment_blocks
from ._sea_validity import SeaValidity, validity
from .base import Scenario

CONTROL_PERIOD = 0.01  # s


class SeaSimConfig(SimConfig):
    dt: float = Field(0.01, gt=0, le=0.1, description="physics step (implicit cable), s")
    duration: float = Field(1200.0, gt=0, le=1e6, description="simulated time (a 20-min record after the start), s")
    log_rate: float = Field(10.0, gt=0, le=1000, description="logged rows per second, Hz")


class SeaAnalysis(StrictModel):
    settle_s: float = Field(120.0, ge=0, le=1e5, description="start-up transient left out of the statistics, s")
    slack_N: float | None = Field(
        None, ge=0, le=1e7, description="slack threshold (default: analysis.slack_fraction x the mean tension), N"
    )
    slack_fraction: float = Field(
        0.01, ge=0, le=1, description="a slack phase starts below this fraction of the reference tension, 1"
    )
    slack_end_fraction: float = Field(
        0.05, ge=0, le=1, description="a slack phase ends above this fraction of the reference (hysteresis), 1"
    )
    snap_factor: float = Field(2.0, gt=1, le=100, description="snap: tension above this multiple of the reference, 1")
    snap_window_s: float = Field(2.0, gt=0, le=100, description="snap: within this time after the slack ends, s")
    reference: Literal["mean", "static"] = Field(
        "mean",
        description="reference tension of the thresholds: the mean over the second half of settle_s (the "
        "project's rule), or the static tension (static_tension_N)",
    )
    static_tension_N: float | None = Field(
        None, gt=0, le=1e7, description="static tension (default: submerged weight of the cable and the UUV), N"
    )
    in_step: bool = Field(
        True, description="count slack/snap events and tension extremes on every integration step (else on logged rows)"
    )

    @model_validator(mode="after")
    def _hysteresis(self):
        if self.slack_end_fraction < self.slack_fraction:
            raise ValueError(
                f"analysis.slack_end_fraction = {self.slack_end_fraction}: must be >= analysis.slack_fraction "
                f"({self.slack_fraction}) (a slack phase ends above the threshold it started below)"
            )
        return self


class SeaLimits(StrictModel):
    tension_max_N: float = Field(600.0, gt=0, le=1e7, description="top tension limit (load_limit = tension), N")
    snap_allowed: bool = Field(False, description="accept snap events (criterion = project; default: any snap fails)")
    criterion: Literal["project", "static-fraction"] = Field(
        "project",
        description="slack/snap criterion: project (no snap: slack, then a peak above snap_factor x the "
        "reference within snap_window_s), static-fraction (the minimum tension of both ends >= "
        "min_tension_fraction x the static tension: no slack, hence no snap)",
    )
    min_tension_fraction: float = Field(
        0.1, ge=0, le=1, description="criterion = static-fraction: least tension as a fraction of the static, 1"
    )
    load_limit: Literal["tension", "swl", "mbl"] = Field(
        "tension",
        description="what the largest tension over the steps (snap peaks included) is checked against: "
        "tension_max_N, the cable's safe working load swl_N, or its breaking load mbl_N / mbl_factor",
    )
    swl_N: float | None = Field(None, gt=0, le=1e9, description="the cable's safe working load (SWL/WLL), N")
    mbl_N: float | None = Field(None, gt=0, le=1e9, description="the cable's minimum breaking load (MBL), N")
    mbl_factor: float = Field(1.0, ge=1, le=100, description="safety factor on mbl_N (your rule's), 1")
    depth_std_max_m: float = Field(0.5, gt=0, le=100, description="UUV depth standard deviation limit, m")
    pitch_std_max_deg: float = Field(3.0, gt=0, le=90, description="UUV pitch standard deviation limit, deg")

    @model_validator(mode="after")
    def _load(self):
        need = {"swl": "swl_N", "mbl": "mbl_N"}.get(self.load_limit)
        if need and getattr(self, need) is None:
            raise ValueError(f"limits.load_limit = {self.load_limit!r} needs limits.{need} (> 0, N)")
        return self

    def tension_limit(self) -> float:
        """The tension (N) the largest tension is checked against (``load_limit``)."""
        if self.load_limit == "swl":
            return float(self.swl_N)
        if self.load_limit == "mbl":
            return float(self.mbl_N) / self.mbl_factor
        return self.tension_max_N


class TowSeaStateConfig(ScenarioConfig):
    sim: SeaSimConfig = SeaSimConfig()
    usv: USVConfig = USVConfig()
    uuv: UUVConfig = UUVConfig()
    cable: CableConfig = CableConfig()
    environment: SeaEnvironmentConfig = SeaEnvironmentConfig()
    command: TowCommand = TowCommand()
    analysis: SeaAnalysis = SeaAnalysis()
    limits: SeaLimits = SeaLimits()
    validity: SeaValidity = SeaValidity()


def window(df, settle_s: float):
    """The rows after ``settle_s`` (all rows when that leaves fewer than two)."""
    w = df[df["t"] >= settle_s]
    return w if len(w) >= 2 else df


def static_tension(cfg) -> float:
    """The static tension (N): ``analysis.static_tension_N``, default the submerged weight of the cable
    and the UUV (what the cable carries hanging still: DNV-RP-H103's static weight of a lift)."""
    a = cfg.analysis
    if a.static_tension_N is not None:
        return float(a.static_tension_N)
    return float(cfg.cable.weight_per_length * cfg.cable.length + cfg.uuv.weight_in_water_kgf * G)


def event_settings(a, static: float) -> dict:
    """Keyword arguments of the plant's in-step event block (:func:`oceangnc.models._combined_events.event_block`)
    from the analysis settings ``a``: counted after ``settle_s``, thresholds as fractions of the mean over
    the second half of the settle time (``reference = "mean"``) or of ``static`` (N)."""
    return {
        "t0": a.settle_s,
        "tm0": 0.5 * a.settle_s,
        "ref": static if a.reference == "static" else 0.0,
        "f_lo": a.slack_fraction,
        "f_hi": a.slack_end_fraction,
        "f_snap": a.snap_factor,
        "window": a.snap_window_s,
        "lo_abs": a.slack_N if a.slack_N is not None else -1.0,
    }


def _in_step(w, end: str) -> dict:
    """The in-step event counts and tension extremes of ``end`` (last logged row: cumulative counters)."""

    def last(leaf):
        return float(w[f"cable.{end}_{leaf}"].to_numpy()[-1])

    return {
        "max_N": last("tension_max"),
        "min_N": last("tension_min"),
        "slack_events": int(last("slack_events")),
        "slack_time_s": last("slack_time"),
        "snap_events": int(last("snap_events")),
        "snap_max_N": last("snap_max"),
    }


def sea_summary(df, cfg) -> dict:
    """Statistics and pass/fail of a tow at sea (module docstring); ``cfg`` a :class:`TowSeaStateConfig`."""
    from ..tension import motion_statistics, tension_statistics

    a = cfg.analysis
    w = window(df, a.settle_s)
    t = w["t"].to_numpy()
    wv = cfg.environment.waves
    out: dict = {
        "waves.kind": wv.kind,
        "waves.hs_m": float(wv.hs) if wv.kind != "none" else 0.0,
        "waves.tp_s": float(wv.tp),
        "waves.relative_heading_deg": float((wv.direction_deg - cfg.command.heading_deg) % 360.0),
        "tow.speed_mps": float(cfg.command.usv_speed),
        "analysis.window_s": float(t[-1] - t[0]) if t.size else 0.0,
    }
    # the tracker counts from settle_s on: a record that ends before it is summarised on its rows
    in_step = "cable.top_tension_max" in w and t.size > 0 and t[-1] >= a.settle_s
    for end in ("top", "bottom"):
        st = tension_statistics(
            t, w[f"cable.{end}_tension"].to_numpy(), a.slack_N, a.slack_fraction, a.snap_factor, a.snap_window_s
        )
        if in_step:  # counted on every integration step (._combined_events)
            st.update(_in_step(w, end))
        out.update({f"cable.{end}_{k}": v for k, v in st.items()})
    out["analysis.events_in_step"] = int(in_step)
    out.update(motion_statistics(w))
    lim = cfg.limits
    static = static_tension(cfg)
    out["cable.static_tension_N"] = static
    out["limits.tension_limit_N"] = lim.tension_limit()
    if lim.criterion == "static-fraction":
        slack_ok = min(out["cable.top_min_N"], out["cable.bottom_min_N"]) >= lim.min_tension_fraction * static
    else:
        slack_ok = lim.snap_allowed or (out["cable.top_snap_events"] + out["cable.bottom_snap_events"]) == 0
    checks = {
        "limits.tension_ok": max(out["cable.top_max_N"], out["cable.top_snap_max_N"]) <= lim.tension_limit(),
        "limits.no_snap": slack_ok,
        "limits.depth_std_ok": out["uuv.depth_std_m"] <= lim.depth_std_max_m,
        "limits.pitch_std_ok": out["uuv.pitch_std_deg"] <= lim.pitch_std_max_deg,
    }
    out.update({k: int(bool(v)) for k, v in checks.items()})
    out["sea.pass"] = int(all(checks.values()))
    out.update(validity(w, cfg))  # inside the model's assumptions? (._sea_validity)
    return out


class TowSeaState(Scenario):
    frame = "columns"  # summary and plots read columns only (oceangnc.io.frame)
    name = "tow-sea-state"
    summary = "USV tows the UUV on a 20 m cable along a line in a JONSWAP sea: tension, snap loads, UUV motions"
    Config = TowSeaStateConfig
    defaults = {
        "uuv": {"x0": 0.0, "z0": 19.0},
        "cable": {"length": 20.0, "integrator": "imex"},
        "command": {"usv_speed": 1.0, "uuv_speed": 1.0, "uuv_kp_speed": 0.0, "uuv_ki_speed": 0.0, "start_s": 5.0},
        "environment": {
            "waves": {"kind": "jonswap", "hs": 1.0, "tp": 6.0, "gamma": 3.3, "components": 128},
            # the USV heaves, rolls and pitches in the waves and moves the tow point in 6 DOF (issue 29 B)
            "usv_motions": {"enabled": True},
        },
    }

    def build(self, cfg, rng):
        kw = cfg.environment.plant_kwargs(cfg.sim.seed)
        if kw and cfg.analysis.in_step:
            kw["events"] = event_settings(cfg.analysis, static_tension(cfg))
        plant = CombinedPlant(cfg.usv, cfg.uuv, cfg.cable, top="usv", **kw)
        blocks = [
            *environment_blocks(cfg.environment),
            TowStraightControl(cfg.command, cfg.usv, cfg.uuv, CONTROL_PERIOD),
            USVThrusterBlock(cfg.usv, CONTROL_PERIOD),
            UUVThrusterBlock(cfg.uuv, CONTROL_PERIOD),
        ]
        return Simulation([plant], blocks, cfg.sim.dt, 1.0 / cfg.sim.log_rate, rng)

    def summarize(self, df, cfg) -> dict:
        return sea_summary(df, cfg)

    def plot(self, df, cfg, out_dir: Path) -> list[Path]:
        import matplotlib.pyplot as plt

        from ..environment.waves import jonswap, pierson_moskowitz
        from ..tension import spectrum

        out_dir = Path(out_dir)
        p1 = plot_signals(
            df,
            [
                ("tension [N]", [("cable.top_tension", "top", 1.0), ("cable.bottom_tension", "bottom (UUV)", 1.0)]),
                ("UUV depth [m]", [("uuv.z", "z", 1.0)]),
                ("UUV pitch [deg]", [("uuv.theta", "theta", 180.0 / math.pi)]),
                ("speed [m/s]", [("usv.speed", "USV", 1.0), ("uuv.u", "UUV u", 1.0)]),
            ],
            out_dir / "sea_timeseries.png",
            title=f"{self.name}: tension and UUV motions",
        )
        w = window(df, cfg.analysis.settle_s)
        fs = cfg.sim.log_rate
        fig, ax = plt.subplots(figsize=(8, 4.5))
        for end, ls in (("top", "-"), ("bottom", "--")):
            f, s = spectrum(w[f"cable.{end}_tension"].to_numpy(), fs)
            ax.semilogy(f, s, ls, label=f"{end} tension [N^2/Hz]")
        wv = cfg.environment.waves
        if wv.kind in ("jonswap", "pierson-moskowitz"):
            ax2 = ax.twinx()
            fw = np.linspace(0.02, min(fs / 2, wv.f_hi / wv.tp), 400)
            sw = jonswap(fw, wv.hs, wv.tp, wv.gamma) if wv.kind == "jonswap" else pierson_moskowitz(fw, wv.hs, wv.tp)
            ax2.plot(fw, sw, "k:", label="wave spectrum [m^2/Hz]")
            ax2.set_ylabel("wave S(f) [m^2/Hz]")
            ax2.legend(loc="upper right", fontsize=8)
        ax.set_xlim(0, min(fs / 2, 1.0))
        ax.set_xlabel("frequency [Hz]")
        ax.set_ylabel("tension PSD [N^2/Hz]")
        ax.grid(alpha=0.3)
        ax.legend(loc="upper left", fontsize=8)
        ax.set_title(f"{self.name}: tension spectra (Welch) against the wave spectrum")
        fig.tight_layout()
        p2 = out_dir / "sea_spectra.png"
        fig.savefig(p2, dpi=110)
        plt.close(fig)
        return [p1, p2]


SCENARIOS = [TowSeaState()]
