"""``trials``: sea trials generated from a model, logged for identification (000 sec. 2.2).

Straight-run (thrust step from rest) and turning (10 deg rudder step) trials and ITTC zig-zags
generated from a model (``vehicle = "usv-first-order"`` or ``"usv-3dof"``, the 3-DOF USV of
:mod:`oceangnc.models.usv`), one trial after another in one log with ``trial.id`` / ``trial.kind``
and the measured signals ``trial.*`` (optionally noisy, :class:`oceangnc.identification.trials.TrialSensors`)
that ``oceangnc identify first-order`` reads by default; the true K, T of each trial are logged
(``trial.true_k``, ``trial.true_t``) and the summary identifies the log and reports the errors.
"""

from __future__ import annotations

import math
from pathlib import Path
from typing import Literal

import numpy as np
from pydantic import Field

from ..control.actuators import RudderEngineBlock, USVThrusterBlock
from ..control.commands import DifferentialThrust, StepCommand
from ..core.blocks import ConstantBlock
from ..core.clock import Simulation
from ..errors import ConfigError
from ..identification.trials import TrialNoise, TrialSensors, ZigZag
from ..io.config import ScenarioConfig, StrictModel
from ..models.first_order import FirstOrderConfig, FirstOrderUSV
from ..models.usv import USVConfig
from ..units import KGF
from .base import Scenario

# -- trials -------------------------------------------------------------------------------------------------------


class TrialsSection(StrictModel):
    """Which trials to run (speeds for usv-first-order in m/s; the 3-DOF USV uses ``*_3dof`` ones)."""

    straight_speeds_mps: list[float] = Field(
        [5.0, 6.4, 7.8, 9.2, 10.6, 12.0, 13.4, 14.8, 16.0],
        min_length=1,
        description="final speeds of the straight runs (from rest), m/s",
    )
    turn_speeds_mps: list[float] = Field(
        [4.2, 5.1, 6.0, 6.9, 7.8, 8.6], min_length=1, description="approach speeds of the turning trials, m/s"
    )
    steer_deg: float = Field(10.0, gt=0, le=35, description="rudder step of the turning trials, deg")
    zigzag_deg: list[float] = Field([10.0, 20.0], description="ITTC zig-zag amplitudes (10 -> 10/10), deg")
    zigzag_speed_mps: float = Field(6.0, gt=0, le=20, description="approach speed of the zig-zags, m/s")
    straight_duration_s: float = Field(200.0, gt=5, le=1e4, description="length of a straight run, s")
    turn_duration_s: float = Field(40.0, gt=5, le=1e4, description="length of a turning trial, s")
    zigzag_duration_s: float = Field(120.0, gt=5, le=1e4, description="length of a zig-zag, s")
    step_time_s: float = Field(5.0, ge=0.5, le=100, description="time of the input step in each trial, s")
    straight_speeds_3dof_mps: list[float] = Field(
        [0.3, 0.45, 0.6, 0.75, 0.9], min_length=1, description="straight-run speeds of the 3-DOF USV, m/s"
    )
    turn_speeds_3dof_mps: list[float] = Field(
        [0.4, 0.6, 0.8], min_length=1, description="turning-trial speeds of the 3-DOF USV, m/s"
    )
    steer_3dof_kgf: float = Field(
        2.0, gt=0, le=15, description="differential thrust step (port +, starboard -) of the 3-DOF USV, kgf"
    )


class TrialsConfig(ScenarioConfig):
    vehicle: Literal["usv-first-order", "usv-3dof"] = "usv-first-order"
    usv: FirstOrderConfig = FirstOrderConfig()
    usv3dof: USVConfig = USVConfig()
    trials: TrialsSection = TrialsSection()
    noise: TrialNoise = TrialNoise()
    control_rate: float = Field(20.0, gt=0, le=1000, description="command rate, Hz")


class _OffsetLog:
    """Forwards rows to the run's log with a time offset and the trial's constant columns."""

    def __init__(self, log, t0, extra):
        self.log, self.t0, self.extra = log, t0, extra

    def append(self, t, row):
        r = dict(row)
        r.update(self.extra)
        self.log.append(self.t0 + t, r)

    def append_rows(self, t, names, values):
        """The fused clock's row blocks (:meth:`oceangnc.io.logs.LogWriter.append_rows`), offset and extended alike."""
        keys = [k for k in self.extra if k not in names]
        const = np.tile([float(self.extra[k]) for k in keys], (len(t), 1))
        vals = np.hstack([np.asarray(values, dtype=float), const])
        self.log.append_rows(self.t0 + np.asarray(t, dtype=float), [*names, *keys], vals)


def _nomoto_3dof(c, U):
    """First-order Nomoto (K, T = T1 + T2 - T3) of the linearised 3-DOF USV at speed U, steer in N."""
    A = np.array([[-c.d22 / c.m22, -c.m11 * U / c.m22], [-(c.m22 - c.m11) * U / c.m33, -c.d33 / c.m33]])
    b = c.thruster_spacing / c.m33  # N = (Tp - Ts) B / 2 = steer * B
    lam = np.linalg.eigvals(A)
    T1, T2 = -1.0 / lam.real
    T3 = c.m22 / c.d22
    K = float(np.linalg.solve(-A, np.array([0.0, b]))[1])
    return K, float(T1 + T2 - T3)


class Trials(Scenario):
    def single_simulation(self, cfg) -> bool:
        """Several trial simulations one after the other."""
        return False

    name = "trials"
    summary = "Straight/turning/zig-zag trials from a model, logged for 'oceangnc identify first-order' (000 sec. 2.2)"
    Config = TrialsConfig
    defaults = {"sim": {"dt": 0.05, "log_rate": 20.0}, "usv": {"schedule": "operating"}}

    def _trial_list(self, cfg):
        tr = cfg.trials
        out = []
        if cfg.vehicle == "usv-first-order":
            out += [("straight", u) for u in tr.straight_speeds_mps]
            out += [("turn", u) for u in tr.turn_speeds_mps]
            out += [("zigzag", a) for a in tr.zigzag_deg]
        else:
            out += [("straight", u) for u in tr.straight_speeds_3dof_mps]
            out += [("turn", u) for u in tr.turn_speeds_3dof_mps]
            out += [("zigzag", a) for a in tr.zigzag_deg]
        return out

    def _build_one(self, cfg, kind, val, rng):
        tr = cfg.trials
        h = 1.0 / cfg.control_rate
        ts = tr.step_time_s
        if cfg.vehicle == "usv-first-order":
            m = cfg.usv
            U = val if kind != "zigzag" else tr.zigzag_speed_mps
            n = m.trim_rpm(U)
            if n > m.rpm_max:
                raise ConfigError(f"trials: {U:g} m/s needs {n:.0f} rpm, above usv.rpm_max = {m.rpm_max:g} rpm")
            co = m.coefficients(U)
            usv = m.model_copy(update={"u0": 0.0 if kind == "straight" else U, "psi0_deg": 0.0})
            plant = FirstOrderUSV(usv)
            d = math.radians(tr.steer_deg)
            blocks: list = [ConstantBlock("operating_speed", h, {"usv.u_op": U}, units={"usv.u_op": "m/s"})]
            rudder_engine = {"usv.rpm_cmd": "rpm", "usv.delta_s_cmd": "rad"}
            if kind == "straight":
                steps = {"usv.rpm_cmd": (0.0, n), "usv.delta_s_cmd": (0.0, 0.0)}
                blocks.append(StepCommand("command", h, ts, steps, rudder_engine))
                truth = (co["K_v"], co["T_v"])
            elif kind == "turn":
                steps = {"usv.rpm_cmd": (n, n), "usv.delta_s_cmd": (0.0, d)}
                blocks.append(StepCommand("command", h, ts, steps, rudder_engine))
                truth = (co["K_r"], co["T_r"])
            else:
                a = math.radians(val)
                blocks += [
                    ConstantBlock("command", h, {"usv.rpm_cmd": n}, units=rudder_engine),
                    ZigZag(a, a, ts, h, "usv.delta_s_cmd", unit="rad"),
                ]
                truth = (co["K_r"], co["T_r"])
            blocks.append(RudderEngineBlock(usv, h))
            units = {"usv.delta_s": "rad", "usv.rpm": "rpm"}
            blocks.append(TrialSensors(cfg.noise, h, "usv.delta_s", "usv.rpm", units=units))
        else:
            from ..models.usv import USVPlant

            c = cfg.usv3dof
            U = val if kind != "zigzag" else tr.turn_speeds_3dof_mps[len(tr.turn_speeds_3dof_mps) // 2]
            T0 = c.d11 * U / 2.0
            s = tr.steer_3dof_kgf * KGF
            c0 = c.model_copy(update={"u0": 0.0 if kind == "straight" else U})
            plant = USVPlant(c0)

            thrusts = {"usv.thrust_port_cmd": "N", "usv.thrust_stbd_cmd": "N"}
            if kind == "straight":  # port = mean + steer, stbd = mean - steer
                steps = {"usv.thrust_port_cmd": (0.0 + 0.0, T0 + 0.0), "usv.thrust_stbd_cmd": (0.0 - 0.0, T0 - 0.0)}
                blocks = [StepCommand("command", h, ts, steps, thrusts)]
                truth = (2.0 / c.d11, c.m11 / c.d11)
            elif kind == "turn":
                steps = {"usv.thrust_port_cmd": (T0 + 0.0, T0 + s), "usv.thrust_stbd_cmd": (T0 - 0.0, T0 - s)}
                blocks = [StepCommand("command", h, ts, steps, thrusts)]
                truth = _nomoto_3dof(c, U)
            else:
                zz = ZigZag(s, math.radians(val), ts, h, "_steer", unit="N")
                blocks = [zz, DifferentialThrust("command", h, T0, "_steer", *thrusts)]
                truth = _nomoto_3dof(c, U)
            blocks.append(USVThrusterBlock(c0, h))
            port, stbd = "usv.thrust_port", "usv.thrust_stbd"
            blocks.append(
                TrialSensors(
                    cfg.noise, h, (port, stbd, -1.0, 0.5), (port, stbd, 1.0, 0.5), units={port: "N", stbd: "N"}
                )
            )
        sim = Simulation([plant], blocks, cfg.sim.dt, 1.0 / cfg.sim.log_rate, rng)
        dur = {"straight": tr.straight_duration_s, "turn": tr.turn_duration_s, "zigzag": tr.zigzag_duration_s}[kind]
        return sim, dur, truth

    def run(self, cfg, ctx) -> dict:
        import warnings

        t0 = 0.0
        codes = {"straight": 0.0, "turn": 1.0, "zigzag": 2.0}
        rngs = ctx.rng.spawn(len(self._trial_list(cfg)))
        with warnings.catch_warnings():
            warnings.simplefilter("ignore", RuntimeWarning)  # trials from rest leave the table-2 range on purpose
            for i, ((kind, val), g) in enumerate(zip(self._trial_list(cfg), rngs)):
                sim, dur, truth = self._build_one(cfg, kind, val, g)
                log = _OffsetLog(
                    ctx.log,
                    t0,
                    {
                        "trial.id": float(i),
                        "trial.kind": codes[kind],
                        "trial.true_k": truth[0],
                        "trial.true_t": truth[1],
                    },
                )
                sim.use_fused = ctx.fused
                sim.verbose = ctx.verbose
                sim.run(dur, log=log)
                t0 += dur + 10.0
        ctx.info["t_end"] = t0
        return {"trials.count": float(len(self._trial_list(cfg)))}

    def summarize(self, df, cfg) -> dict:
        from ..errors import InputError
        from ..identification.first_order import Columns, identify_log

        try:
            rep = identify_log(df, Columns(), n_mc=50, seed=cfg.sim.seed)
        except InputError as e:  # the log is still good; say why it cannot be identified as it is
            return {"ident.error": str(e)}
        out: dict = {}
        truth = df.groupby("trial.id")[["trial.true_k", "trial.true_t"]].first()
        for kind, names in (("straight", ("K_v", "T_v")), ("turn", ("K_r", "T_r"))):
            st = [s for s in rep.steps if s.kind == kind]
            if not st:
                continue
            ek = [abs(s.K / truth.loc[s.trial, "trial.true_k"] - 1) * 100 for s in st]
            et = [abs(s.T / truth.loc[s.trial, "trial.true_t"] - 1) * 100 for s in st]
            out[f"ident.{names[0]}_max_err_pct"] = max(ek)
            out[f"ident.{names[1]}_max_err_pct"] = max(et)
            out[f"ident.{names[0]}_max_rel_std_pct"] = max(100 * s.K_std / abs(s.K) for s in st)
            out[f"ident.{names[1]}_max_rel_std_pct"] = max(100 * s.T_std / abs(s.T) for s in st)
        for k, f in rep.fits.items():
            out[f"fit.{k}_slope"] = f.slope
            out[f"fit.{k}_intercept"] = f.intercept
            out[f"fit.{k}_residual_rms"] = f.residual_rms
        zz = [a for k, a in self._trial_list(cfg) if k == "zigzag"]
        for z, amp in zip(rep.zigzags, zz):
            tk = truth.loc[z.trial]
            tag = f"{amp:.0f}_{amp:.0f}"
            out[f"zigzag.{tag}.K_r_err_pct"] = abs(z.K / tk["trial.true_k"] - 1) * 100
            out[f"zigzag.{tag}.T_r_err_pct"] = abs(z.T / tk["trial.true_t"] - 1) * 100
        return out

    def plot(self, df, cfg, out_dir: Path) -> list[Path]:
        import matplotlib.pyplot as plt

        from ..errors import InputError
        from ..identification.first_order import Columns, identify_log
        from ..io.plots import _save

        try:
            rep = identify_log(df, Columns(), n_mc=20)
        except InputError:
            return []
        truth = df.groupby("trial.id")[["trial.true_k", "trial.true_t"]].first()
        fig, axes = plt.subplots(2, 2, figsize=(9, 6))
        for col, (kind, names) in enumerate((("straight", ("K_v", "T_v")), ("turn", ("K_r", "T_r")))):
            st = [s for s in rep.steps if s.kind == kind]
            if not st:
                continue
            u = np.array([s.speed for s in st])
            for row, attr in enumerate(("K", "T")):
                ax = axes[row, col]
                v = np.array([getattr(s, attr) for s in st])
                e = np.array([getattr(s, attr + "_std") for s in st])
                tv = np.array([truth.loc[s.trial, "trial.true_k" if attr == "K" else "trial.true_t"] for s in st])
                ax.errorbar(u, v, yerr=e, fmt="o", label="identified (eq. 12-21)")
                ax.plot(u, tv, "kx", label="model truth")
                f = rep.fits.get(names[row])
                if f is not None:
                    uu = np.linspace(u.min(), u.max(), 10)
                    ax.plot(uu, f.slope * uu + f.intercept, "r-", label=f"fit {f.slope:.4g} u + {f.intercept:.4g}")
                ax.set_xlabel("speed u [m/s]")
                ax.set_ylabel(names[row])
                ax.grid(True, alpha=0.3)
                ax.legend(fontsize=7)
        axes[0, 0].set_title("coefficients vs speed (000 figs. 11-14, table 2)")
        return [_save(fig, Path(out_dir) / "coefficients.png")]


SCENARIOS = [Trials()]
