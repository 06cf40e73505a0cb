"""Time-step advisor (``oceangnc check SCENARIO``).

For a scenario's clocked simulation it reports

* each plant's stability limit for each integrator it offers: the lumped-mass cable's axial chain
  for classical RK4 and for the split integrator (RK4 + backward-Euler axial damping), from the
  eigenvalues of the linearised chain (:func:`oceangnc.models.cable.axial_stability_limit`); for
  every plant also the limits of RK4 and explicit Euler from the eigenvalues of its whole
  right-hand side linearised at the state reached after the horizon (damped modes only; other plants: the smaller of
  their own ``max_dt`` and the linearised RK4 limit);
* the step the scenario will use (``sim.dt`` or the scenario's automatic choice);
* its expected accuracy: the scenario run for a short horizon at dt and at dt/2, the largest
  difference of the plants' states between the two, and the Richardson estimate of the error at dt
  (difference x 2^p / (2^p - 1), p = 4 for RK4);
* the loop rate of every block.

A step above a plant's limit is refused (exit 2) with the largest stable step that divides the
control periods.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

from ..core.integrators import stability_limit
from ..errors import ConfigError


@dataclass
class CheckReport:
    scenario: str
    dt: float | None
    limits: list = field(default_factory=list)  # (plant, integrator, limit s, in use)
    loops: list = field(default_factory=list)  # (block, period s)
    accuracy: list = field(default_factory=list)  # (group, |x_dt - x_dt/2|, richardson error, unit)
    horizon: float = 0.0
    refused: str = ""
    note: str = ""

    def text(self) -> str:
        out = [f"scenario {self.scenario}"]
        if self.dt is None:
            return "\n".join(out + [f"  {self.note}"])
        out.append(f"  physics step dt = {self.dt:.6g} s")
        out.append(
            "  stability limits (largest stable step"
            + (f"; linearised at t = {self.horizon:g} s" if self.horizon else "")
            + "):"
        )
        for plant, integ, lim, used in self.limits:
            mark = " <- in use" if used else ""
            ratio = f"  (dt = {self.dt / lim:.2f} x limit)" if used and math.isfinite(lim) else ""
            shown = f"{lim:.4g} s" if math.isfinite(lim) else "none (step set by accuracy)"
            out.append(f"    {plant:<10} {integ:<20} {shown}{mark}{ratio}")
        if self.loops:
            out.append("  loop rates:")
            for name, per in self.loops:
                out.append(f"    {name:<16} {1.0 / per:8.3g} Hz  (every {round(per / self.dt)} physics steps)")
        if self.refused:
            out.append(f"  REFUSED: {self.refused}")
            return "\n".join(out)
        if self.accuracy:
            out.append(f"  expected accuracy (step-halving run over {self.horizon:g} s, largest difference per group):")
            for group, diff, rich, unit in self.accuracy:
                out.append(f"    {group:<22} |x(dt) - x(dt/2)| = {diff:.3e} {unit}, error at dt ~ {rich:.3e} {unit}")
        if self.note:
            out.append(f"  {self.note}")
        return "\n".join(out)


def _explicit_limit(lam: np.ndarray, amplification) -> float:
    """Largest h with amplification(h lambda) <= 1 for every damped eigenvalue (Re < 0), by bisection from
    below; inf if there is none."""
    lam = lam[(np.abs(lam) > 1e-9) & (lam.real < -1e-12 * np.abs(lam))]
    if lam.size == 0:
        return math.inf
    rmax = float(np.max(np.abs(lam)))
    return stability_limit(lam, amplification, 1e-4 / rmax, 100.0 / rmax)


def linearised_eigenvalues(pl, t: float = 0.0) -> np.ndarray:
    """Eigenvalues (1/s) of the plant's right-hand side linearised at its current state and inputs (central
    differences, relative step 1e-6)."""
    x = np.array(pl.x, dtype=float)
    n = x.size
    J = np.zeros((n, n))
    fp, fm = np.zeros(n), np.zeros(n)
    for j in range(n):
        h = 1e-6 * max(1.0, abs(x[j]))
        xp, xm = x.copy(), x.copy()
        xp[j] += h
        xm[j] -= h
        pl.rhs(t, xp, pl.u, pl.p, fp)
        pl.rhs(t, xm, pl.u, pl.p, fm)
        J[:, j] = (fp - fm) / (2 * h)
    return np.linalg.eigvals(J)


def _linear_rows(pl) -> list:
    """(plant, integrator, limit, in use) from the linearised dynamics: RK4 and, for comparison, explicit Euler."""
    from ..models.cable import _rk4_amplification

    lam = linearised_eigenvalues(pl)
    name = getattr(pl, "name", type(pl).__name__)
    return [
        (name, "rk4 (linearised)", _explicit_limit(lam, _rk4_amplification), False),
        (name, "euler (linearised)", _explicit_limit(lam, lambda z: np.abs(1 + z)), False),
    ]


def _plant_limits(sim, cfg) -> list:
    from ..models.cable import axial_stability_limit

    rows = []
    for pl in sim.plants:
        name = getattr(pl, "name", type(pl).__name__)
        cable = getattr(cfg, "cable", None)
        if hasattr(pl, "stability_limit") and cable is not None:
            end_mass = None
            try:
                from ..models.uuv import P_MA, P_MRB

                uuv = getattr(cfg, "uuv", None)
                if uuv is not None:
                    p = uuv.params()
                    end_mass = float(
                        p[P_MRB : P_MRB + 36].reshape(6, 6)[0, 0] + p[P_MA : P_MA + 36].reshape(6, 6)[0, 0]
                    )
            except Exception:
                end_mass = None
            for integ in ("rk4", "rk4-split"):
                lim = axial_stability_limit(cable, end_mass=end_mass, last_damper_only=(integ == "rk4-split"))
                rows.append((name, integ, lim, integ == cable.integrator))
            # the implicit (ROS2) scheme has no axial stability limit: its step is set by accuracy
            rows.append((name, "imex", math.inf, cable.integrator == "imex"))
            rows += _linear_rows(pl)
        else:
            lin = _linear_rows(pl)
            stated = pl.max_dt if getattr(pl, "max_dt", None) is not None else math.inf
            lim = min(stated, lin[0][2])
            rows.append((name, "rk4", lim, True))
            rows += lin[1:]
    return rows


_POS = {"x", "y", "z", "n", "e", "d"}
_ANG = {"phi", "theta", "psi"}


def _groups(pl) -> dict[str, tuple[list[int], str]]:
    """State indices grouped for the accuracy report: each body's positions (m), attitude (rad) and
    velocities (m/s, rad/s), from the state names (``usv.x``, ``cable.vx3``, ``uuv.theta`` ...)."""
    names = list(getattr(pl, "state_names", []))
    g: dict[str, tuple[list[int], str]] = {}
    for i, n in enumerate(names):
        body, _, var = n.rpartition(".")
        body = body or pl.name
        base = var.rstrip("0123456789")
        if base in _POS:
            key, unit = f"{body} position", "m"
        elif base in _ANG:
            key, unit = f"{body} attitude", "rad"
        elif base in ("p", "q", "r"):
            key, unit = f"{body} angular rate", "rad/s"
        else:
            key, unit = f"{body} velocity", "m/s"
        g.setdefault(key, ([], unit))[0].append(i)
    return g


def check(scenario: str, overrides: dict | None = None, horizon: float = 5.0) -> CheckReport:
    """Build the scenario, report limits and loop rates, and run the step-halving accuracy estimate."""
    from ..api import resolve_config
    from ..scenarios.base import Scenario

    sc, cfg = resolve_config(scenario, overrides=overrides)
    if type(sc).build is Scenario.build:
        return CheckReport(
            sc.name,
            None,
            note="this scenario has no single clocked simulation (its run is custom); "
            "its models choose their own steps",
        )
    try:
        sim = sc.build(cfg, np.random.default_rng(cfg.sim.seed))
    except ConfigError as e:
        if "stability" not in str(e) and "limit" not in str(e):
            raise
        # build once more with a tiny step to read the limits, then refuse with advice
        _, cfg_small = resolve_config(scenario, overrides={**(overrides or {}), "sim.dt": 1e-5})
        sim = sc.build(cfg_small, np.random.default_rng(0))
        rep = CheckReport(sc.name, float(cfg.sim.dt), _plant_limits(sim, cfg), [(b.name, b.period) for b in sim.blocks])
        rep.refused = _advice(rep, str(e))
        return rep
    dt = float(sim.dt)
    rep = CheckReport(sc.name, dt, _plant_limits(sim, cfg), [(b.name, b.period) for b in sim.blocks])
    over_limit = [r for r in rep.limits if r[3] and dt > r[2] * (1 + 1e-9)]
    if over_limit:
        rep.refused = _advice(rep, "")
        return rep
    T = min(horizon, float(cfg.sim.duration))
    rep.horizon = T
    sim.run(T)
    # linearise again where the run has brought the plants (a cable starting slack has no axial stiffness)
    rep.limits = _plant_limits(sim, cfg)
    over_limit = [r for r in rep.limits if r[3] and dt > r[2] * (1 + 1e-9)]
    if over_limit:
        rep.refused = _advice(rep, f"at t = {T:g} s")
        return rep
    _, cfg2 = resolve_config(scenario, overrides={**(overrides or {}), "sim.dt": dt / 2})
    sim2 = sc.build(cfg2, np.random.default_rng(cfg.sim.seed))
    sim2.run(T)
    split = any(r[1] == "rk4-split" and r[3] for r in rep.limits)
    imex = any(r[1] == "imex" and r[3] for r in rep.limits)
    p = 1 if split else (2 if imex else 4)
    for pa, pb in zip(sim.plants, sim2.plants):
        for key, (idx, unit) in _groups(pa).items():
            d = float(np.max(np.abs(pa.x[idx] - pb.x[idx]))) if idx else 0.0
            rep.accuracy.append((key, d, d * 2**p / (2**p - 1), unit))
    rep.note = "error at dt ~ 2^p/(2^p - 1) x the dt vs dt/2 difference, p = " + (
        "1 (the split integrator's backward-Euler damping is first order; RK4 elsewhere)"
        if split
        else ("2 (the implicit-explicit ROS2 scheme of the cable)" if imex else "4 (RK4)")
    )
    return rep


def _advice(rep: CheckReport, msg: str) -> str:
    from ..models.cable import stable_step

    periods = [p for _, p in rep.loops] or [0.01]
    base = min(periods)
    used = [r for r in rep.limits if r[3]]
    lim = min((r[2] for r in used), default=math.inf)
    best = [r for r in rep.limits if r[2] >= (rep.dt or 0)]
    alt = ""
    if best:
        b = max(best, key=lambda r: r[2])
        lim_b = f"limit {b[2]:.4g} s" if math.isfinite(b[2]) else "no axial limit: the step is set by accuracy"
        alt = f"; or switch {b[0]} to integrator '{b[1]}' ({lim_b})"
    return (
        f"dt = {rep.dt:g} s is above the stability limit {lim:.4g} s; use sim.dt <= "
        f"{stable_step(lim, base, 0.9):.6g} s (90 % of the limit, dividing the {base:g} s loop period){alt}"
        + (f" [{msg}]" if msg else "")
    )
