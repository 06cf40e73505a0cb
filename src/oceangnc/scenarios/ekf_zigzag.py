"""Scenario ``ekf-zigzag``: hydrodynamic coefficients of a submarine by augmented-state EKF (002).

Reproduces document 002 (``002_05c842517d8c1175.txt`` ch. 4-5): a 5-5 or 10-5 deg stern-plane
zig-zag of the heave-pitch model (:mod:`oceangnc.models.submarine_vertical`), truth integrated with
RK4 at ``sim.dt`` (1e-4 s), w, theta and q sampled at ``measurement_rate_hz`` (100 Hz) for
``sim.duration`` (200 s) with optional white noise (``noise`` times the nominal sensor noise
``sensor.*``), then the ten coefficients identified by the continuous-discrete augmented EKF
(:mod:`oceangnc.identification.ekf`, table 3.1).

The log holds one row per measurement: ``sub.ds`` (rad), the measured ``sub.w`` (m/s),
``sub.theta`` (rad), ``sub.q`` (rad/s), the truth ``sub.*_true`` and ``sub.z_true`` (m), and the
filter's ``ekf.w/theta/q``, ``ekf.<coef>`` and ``ekf.<coef>_sigma`` (1-sigma) and ``ekf.nis``.
Summary: ``<coef>.estimate``, ``<coef>.true``, ``<coef>.rel_error`` (signed, (est - true)/|true|),
``<coef>.sigma`` (final 1-sigma), ``max_rel_error``, ``n_within_3sigma``, ``nees`` (final parameter
NEES, chi-square with n_coef dof if the filter is consistent), ``n_plane_reversals``.
"""

from __future__ import annotations

import math
import time
from pathlib import Path
from typing import Literal

import numpy as np
from pydantic import Field

from ..errors import InputError
from ..identification.ekf import (
    nees,
    resolve_estimate,
    run_ekf,
    submarine_vertical_model,
)
from ..identification.maneuvers import zigzag
from ..io.config import ScenarioConfig, StrictModel
from ..models.submarine_vertical import (
    COEFF_NAMES,
    PUBLISHED_ESTIMATES,
    TABLE41_COEFFS,
    SubmarineVerticalConfig,
)
from .base import Scenario


class SensorNoise(StrictModel):
    """Nominal measurement noise (1-sigma, white, per sample); ``noise`` scales it."""

    w_mps: float = Field(0.002, gt=0, le=1, description="heave velocity noise, m/s")
    theta_deg: float = Field(0.02, gt=0, le=10, description="pitch angle noise, deg")
    q_degps: float = Field(0.005, gt=0, le=10, description="pitch rate noise, deg/s")

    def std(self) -> np.ndarray:
        """Standard deviations in SI: (m/s, rad, rad/s)."""
        return np.array([self.w_mps, math.radians(self.theta_deg), math.radians(self.q_degps)])


class FilterTuning(StrictModel):
    """Augmented EKF tuning (002 prints none of it; see docs/ekf-identification.md)."""

    estimate: list[str] = Field(list(COEFF_NAMES), min_length=1, description="coefficients to estimate")
    initial_guess: Literal["perturbed", "table4.1", "prior-draw", "true"] = Field(
        "perturbed",
        description="initial guesses: true x (1 +/- initial_error) alternating, 002 table 4.1, "
        "a draw from N(true, P0) with sim.seed, or the truth",
    )
    initial_error: float = Field(0.2, ge=0, le=0.9, description="relative error of the perturbed/drawn guesses, -")
    p0_rel: float = Field(0.3, gt=0, le=10, description="initial 1-sigma of each coefficient relative to its guess, -")
    p0_state_scale: float = Field(2.0, gt=0, le=1e3, description="initial state 1-sigma in measurement sigmas, -")
    r_scale: float | None = Field(
        None,
        gt=0,
        le=1e3,
        description="measurement sigma assumed by the filter, "
        "in nominal sensor sigmas (default: noise, or 1e-3 if noise = 0), -",
    )
    q_rel: float = Field(2.5e-5, ge=0, le=1, description="state process noise density in units of R per second, 1/s")
    q_param_rel: float = Field(
        0.0, ge=0, le=1, description="coefficient process noise density in units of its P0 variance per second, 1/s"
    )
    passes: int = Field(1, ge=1, le=10, description="passes over the record (each restarts from the last estimate)")
    substeps: int = Field(1, ge=1, le=100, description="RK4 steps per measurement interval")
    jacobian: Literal["analytic", "complex-step", "finite-difference"] = Field(
        "analytic", description="how the filter's Jacobians are computed"
    )


class EKFZigzagConfig(ScenarioConfig):
    vehicle: SubmarineVerticalConfig = SubmarineVerticalConfig()
    maneuver: Literal["5-5", "10-5"] = Field("10-5", description="stern plane deg - pitch switch deg")
    noise: float = Field(
        0.0, ge=0, le=100, description="measurement noise level in nominal sensor sigmas (0 = noise-free), -"
    )
    sensor: SensorNoise = SensorNoise()
    measurement_rate_hz: float = Field(100.0, gt=0, le=1000, description="measurement (and plane command) rate, Hz")
    t_start_s: float = Field(0.0, ge=0, le=1e4, description="straight run before the first deflection, s")
    plane_rate_degps: float = Field(0.0, ge=0, le=100, description="stern plane slew rate (0 = a jump), deg/s")
    filter: FilterTuning = FilterTuning()


def initial_guesses(cfg: EKFZigzagConfig, names: list[str], rng: np.random.Generator) -> np.ndarray:
    """Initial coefficient guesses for the configured rule (see :class:`FilterTuning`)."""
    true = np.array([getattr(cfg.vehicle, k) for k in names])
    f = cfg.filter
    if f.initial_guess == "true":
        return true
    if f.initial_guess == "table4.1":
        return np.array([TABLE41_COEFFS.get(k, getattr(cfg.vehicle, k)) for k in names])
    if f.initial_guess == "prior-draw":
        return true * (1.0 + f.initial_error * rng.standard_normal(len(names)))
    signs = np.array([1.0 if i % 2 == 0 else -1.0 for i in range(len(names))])
    return true * (1.0 + f.initial_error * signs)


def identify(cfg: EKFZigzagConfig, rng: np.random.Generator):
    """Generate the maneuver data and run the filter: returns (data, result, guesses, wall time s)."""
    model = submarine_vertical_model(cfg.vehicle.params())
    names = list(cfg.filter.estimate)
    resolve_estimate(model, names)  # unknown names -> InputError
    sd = cfg.sensor.std()
    noise_sd = cfg.noise * sd
    data = zigzag(
        cfg.vehicle.params(),
        cfg.vehicle.x0(),
        cfg.maneuver,
        duration=cfg.sim.duration,
        rate_hz=cfg.measurement_rate_hz,
        dt_truth=cfg.sim.dt,
        noise_std=noise_sd,
        rng=rng,
        t_start_s=cfg.t_start_s,
        plane_rate_degps=cfg.plane_rate_degps,
    )
    f = cfg.filter
    a0 = initial_guesses(cfg, names, rng)
    r_scale = f.r_scale if f.r_scale is not None else (cfg.noise if cfg.noise > 0 else 1e-3)
    R = (r_scale * sd) ** 2
    ns = 3
    p0_par = (f.p0_rel * np.abs(a0)) ** 2
    P0 = np.concatenate([(f.p0_state_scale * r_scale * sd) ** 2, p0_par])
    Q = np.concatenate([f.q_rel * R, f.q_param_rel * p0_par])
    U = data.ds[:, None]
    t0 = time.perf_counter()
    a = a0
    res = None
    for _ in range(f.passes):
        res = run_ekf(
            model, data.t, data.z_meas, U, names, data.z_meas[0], a, P0, Q, R, substeps=f.substeps, jacobian=f.jacobian
        )
        a = res.X[-1, ns:]
    wall = time.perf_counter() - t0
    return data, res, a0, wall


class EKFZigzag(Scenario):
    name = "ekf-zigzag"
    summary = "submarine heave-pitch coefficients by augmented EKF from a 5-5/10-5 zig-zag (002 tables 5.2/5.3)"
    Config = EKFZigzagConfig
    defaults = {"sim": {"duration": 200.0, "dt": 1e-4}}

    def single_simulation(self, cfg) -> bool:
        """An identification run (a recorded zig-zag, then the filter), not a clock simulation."""
        return False

    def run(self, cfg, ctx) -> dict:
        data, res, a0, wall = identify(cfg, ctx.rng)
        names = res.estimate
        ns = 3
        cols = data.columns("sub")
        for i, k in enumerate(("w", "theta", "q")):
            cols[f"ekf.{k}"] = res.X[:, i]
            cols[f"ekf.{k}_sigma"] = res.sigma[:, i]
        for i, k in enumerate(names):
            cols[f"ekf.{k}"] = res.X[:, ns + i]
            cols[f"ekf.{k}_sigma"] = res.sigma[:, ns + i]
        cols["ekf.nis"] = res.nis
        keys = [k for k in cols if k != "t"]
        arr = np.column_stack([cols[k] for k in keys])
        t = cols["t"]
        ctx.log.append(float(t[0]), dict(zip(keys, arr[0].tolist())))  # fixes the columns
        ctx.log.append_rows(t[1:], keys, arr[1:])
        ctx.info["t_end"] = float(t[-1])
        true = np.array([getattr(cfg.vehicle, k) for k in names])
        err = res.X[-1, ns:] - true
        return {
            "nees": nees(err, res.P[ns:, ns:]),
            "filter_wall_time_s": wall,
            "n_plane_reversals": data.n_reversals,
            **{f"{k}.initial": float(v) for k, v in zip(names, a0)},
        }

    def summarize(self, df, cfg) -> dict:
        names = [k for k in cfg.filter.estimate if f"ekf.{k}" in df]
        if not names:
            raise InputError("log has no ekf.<coefficient> column")
        last = df.iloc[-1]
        out: dict = {}
        worst = 0.0
        inside = 0
        for k in names:
            est = float(last[f"ekf.{k}"])
            sig = float(last[f"ekf.{k}_sigma"])
            tru = float(getattr(cfg.vehicle, k))
            rel = (est - tru) / abs(tru) if tru != 0 else float("nan")
            out[f"{k}.estimate"] = est
            out[f"{k}.true"] = tru
            out[f"{k}.rel_error"] = rel
            out[f"{k}.sigma"] = sig
            worst = max(worst, abs(rel))
            inside += int(abs(est - tru) <= 3.0 * sig)
        out["max_rel_error"] = worst
        out["n_within_3sigma"] = inside
        out["n_estimated"] = len(names)
        return out

    def plot(self, df, cfg, out_dir: Path) -> list[Path]:
        return [
            plot_estimates(df, cfg, Path(out_dir) / "estimates.png"),
            plot_measurements(df, Path(out_dir) / "measurements.png", title=f"{cfg.maneuver} zig-zag"),
        ]


def plot_estimates(df, cfg, path: Path, title: str | None = None) -> Path:
    """Each estimate against time with its 3-sigma band and the true value (like 002 figs 5.3/5.4)."""
    import matplotlib.pyplot as plt

    from ..io.plots import _save

    names = [k for k in cfg.filter.estimate if f"ekf.{k}" in df]
    ncol = 2
    nrow = math.ceil(len(names) / ncol)
    fig, axes = plt.subplots(nrow, ncol, figsize=(9, 1.7 * nrow + 0.8), sharex=True, squeeze=False)
    t = df["t"].to_numpy()
    pub_col = 0 if cfg.maneuver == "5-5" else 1
    for ax, k in zip(axes.ravel(), names):
        est = df[f"ekf.{k}"].to_numpy()
        sig = df[f"ekf.{k}_sigma"].to_numpy()
        tru = getattr(cfg.vehicle, k)
        ax.fill_between(t, est - 3 * sig, est + 3 * sig, color="C0", alpha=0.2, lw=0, label="estimate +/- 3 sigma")
        ax.plot(t, est, "C0", lw=1.2, label="estimate")
        ax.axhline(tru, color="k", ls="--", lw=1, label="true (002 tab. 5.2/5.3)")
        if k in PUBLISHED_ESTIMATES:
            ax.axhline(PUBLISHED_ESTIMATES[k][pub_col], color="C3", ls=":", lw=1, label="002 estimate")
        span = max(abs(tru), 1e-12)
        lo = min(tru - 0.6 * span, np.nanmin(est[len(est) // 20 :]))
        hi = max(tru + 0.6 * span, np.nanmax(est[len(est) // 20 :]))
        ax.set_ylim(lo, hi)
        ax.set_ylabel(f"{k}'")
        ax.grid(True, alpha=0.3)
    for ax in axes.ravel()[len(names) :]:
        ax.set_visible(False)
    axes[0, 0].legend(fontsize=6, loc="best")
    for ax in axes[-1]:
        ax.set_xlabel("time t [s]")
    fig.suptitle(title or f"EKF identification, {cfg.maneuver} zig-zag, noise {cfg.noise:g}", fontsize=10)
    return _save(fig, path)


def plot_measurements(df, path: Path, title: str = "") -> Path:
    """Stern plane, measured and true w, theta, q (like 002 figs 4.1 and 5.1)."""
    from ..io.plots import plot_signals

    d = 180.0 / math.pi
    return plot_signals(
        df,
        [
            ("stern plane [deg]", [("sub.ds", "ds", d)]),
            ("w [m/s]", [("sub.w", "measured", 1.0), ("sub.w_true", "true", 1.0), ("ekf.w", "EKF", 1.0)]),
            ("theta [deg]", [("sub.theta", "measured", d), ("sub.theta_true", "true", d), ("ekf.theta", "EKF", d)]),
            ("q [deg/s]", [("sub.q", "measured", d), ("sub.q_true", "true", d), ("ekf.q", "EKF", d)]),
        ],
        path,
        title=f"{title}: measurements",
    )


SCENARIOS = [EKFZigzag()]
