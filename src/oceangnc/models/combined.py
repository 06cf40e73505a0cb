"""The combined vehicle of 003 ch. 2.4: USV + lumped-mass cable + 6-DOF UUV as one plant.

One flat state, integrated by one compiled right-hand side :func:`combined_rhs`:

    x = [ USV (6): x, y, psi, u, v, r                       (models/usv.py, unchanged physics)
          cable interior node positions r_1..r_{n-1} (3(n-1), NED, m)
          cable interior node velocities v_1..v_{n-1} (3(n-1), m/s)
          UUV (12): x, y, z, phi, theta, psi, u, v, w, p, q, r  (models/uuv.py) ]

The end nodes are not states: the top node r_0 is the USV's attachment point (``cable.top_x/y/z`` in
the USV's body frame; a fixed point when ``top="fixed"``) and the bottom node r_n is the UUV's tow
point r_c, r_n = eta_1 + J_1 r_c and v_n = J_1 (v_1 + omega x r_c) (003 eq. 2.30-2.31). The force the
cable exerts on node n (tension of the last segment plus half its drag and submerged weight) acts
on the UUV at r_c (003 eq. 2.32-2.33). As in 003 ("the USV is assumed unaffected by the cable"), the
cable does not load the USV; the force it would exert on it is published as ``cable.top_tension``.

The half-segment masses at the two end nodes are carried by the vehicles: their weight and drag are
applied, their inertia (0.1 kg each for table 2-6) is neglected.

Inputs (bus keys): ``usv.thrust_port``, ``usv.thrust_stbd``, ``env.current_n``, ``env.current_e``,
``env.wind_n``, ``env.wind_e``, ``uuv.thrust_port``, ``uuv.thrust_stbd``, ``uuv.thrust_bow``.
Published: ``usv.{x,y,psi,u,v,r,speed}``, ``uuv.{x,y,z,phi,theta,psi,u,v,w,p,q,r,speed}``,
``cable.top_tension``, ``cable.bottom_tension`` (N, magnitudes of the cable's end forces),
``cable.angle_deg`` (angle from vertical of the top-to-bottom line) and ``cable.{x,y,z}{i}``.
"""

from __future__ import annotations

import math

import numpy as np

from ..core.blocks import Plant
from ..core.signals import CALM
from ..errors import ConfigError
from ..units import G

# the compiled pieces live in ._combined_*; the layout constants and what generated fused modules and
# tests import are re-exported here
from ._combined_form import combined_plant_form
from ._combined_imex import imex_advance  # noqa: F401
from ._combined_kernels import cable_state, combined_rhs  # noqa: F401
from ._combined_layout import *  # noqa: F403
from ._combined_layout import (
    H_EA,
    H_L0,
    H_N,
    H_SEA,
    H_UO,
    H_WSEG,
    INPUT_NAMES,
    INTEGRATORS,
    N_USV,
    P_SCR,
    P_USV,
    P_UUV,
    UUV_NP,
    top_l0,
)
from ._combined_outputs import _fill_outputs, _fill_outputs_var, _unit_of, output_keys  # noqa: F401
from ._combined_sea import HEAVE_MODES, reset_sea, sea_block, sea_update
from ._sea_layout import S_EV, S_WF, W_XO
from ._combined_events import ENDS, EVENT_KEYS, attach_events, event_table, event_units, reset_events
from ._usv_waves import WF_OUTPUTS, attach_usv_motions
from ._combined_setup import build_arrays
from ._combined_split import damping_substep, split_advance  # noqa: F401
from ._combined_variants import kernels
from ._combined_winch import remesh, winch_command  # noqa: F401
from .cable import CableConfig, axial_stability_limit
from .usv import USVConfig
from .usv import usv_rhs
from .uuv import P_MA, P_MRB, UUVConfig, uuv_deriv, uuv_energy


class CombinedPlant(Plant):
    """USV + cable + UUV as one plant (see the module docstring for layouts and signals).

    Parameters
    ----------
    usv_cfg, uuv_cfg, cable_cfg : the three configs.
    top : "usv" (top node on the USV's attachment point) or "fixed" (held at the USV's initial
        attachment point; the USV's states are frozen).
    name : plant name (used in divergence messages).
    """

    def __init__(
        self,
        usv_cfg: USVConfig,
        uuv_cfg: UUVConfig,
        cable_cfg: CableConfig,
        top: str = "usv",
        name: str = "combined",
        integrator: str | None = None,
        winch=None,
        seabed=None,
        waves=None,
        heave: str = "none",
        heave_amplitude: float = 0.0,
        heave_period: float = 0.0,
        wave_update_dt: float = 0.1,
        usv_motions=None,
        events=None,
    ):
        if top not in ("usv", "fixed"):
            raise ConfigError(f"CombinedPlant top = {top!r}: allowed values 'usv', 'fixed'")
        integrator = integrator or cable_cfg.integrator
        if integrator not in INTEGRATORS:
            raise ConfigError(
                f"cable.integrator = {integrator!r}: allowed values " + ", ".join(repr(k) for k in INTEGRATORS)
            )
        has_winch = winch is not None and winch.enabled
        has_bed = seabed is not None and seabed.depth is not None
        if has_winch and integrator != "imex":
            raise ConfigError(
                f"cable.integrator = {integrator!r}: the winch (winch.enabled) needs 'imex' "
                "(its top segment may be short and stiff)"
            )
        self.integrator = integrator
        self.usv_cfg = usv_cfg
        self.uuv_cfg = uuv_cfg
        self.cable_cfg = cable_cfg
        self.winch_cfg = winch if has_winch else None
        self.seabed_cfg = seabed if has_bed else None
        self.top = top
        if heave not in HEAVE_MODES:
            raise ConfigError(f"heave = {heave!r}: allowed values " + ", ".join(repr(k) for k in HEAVE_MODES))
        if heave == "sine" and not (heave_period > 0):
            raise ConfigError(f"heave_period = {heave_period}: must be > 0 for a prescribed sine heave")
        self.waves = waves
        self._sea = waves is not None or heave != "none"
        # the compiled kernels without the features this plant does not have (._combined_variants)
        self._features = (self._sea, has_bed, has_winch, cable_cfg.attachment == "bridle")
        k = self._kernels
        p, x0, names, nmax = build_arrays(
            usv_cfg, uuv_cfg, cable_cfg, top, integrator, self.winch_cfg, self.seabed_cfg, k["_ends"]
        )
        self.n_max = nmax
        self._sea_dt = float(wave_update_dt)
        if self._sea:  # the sea block at the end of p (layout: ._sea_layout), its offset in the header
            p[H_SEA] = p.size
            block = sea_block(
                waves, nmax, self._sea_dt, heave, cable_cfg.rho_water, cable_cfg.area, p[H_L0],
                uuv_cfg.buoyancy, heave_amplitude, heave_period,
            )  # fmt: skip
            p = np.concatenate([p, block])
        self._wf = usv_motions is not None and getattr(usv_motions, "enabled", True)
        wf_limit = math.inf
        if self._wf:  # the USV's wave-frequency block after the sea block, its states after all others
            p, x0, names, wf_limit = attach_usv_motions(p, x0, names, usv_motions, waves, cable_cfg, top)
        self._ev_idx = np.zeros(0, dtype=np.int64)
        # in-step slack/snap tracking (._combined_events) at the end of p: the imex and split steppers call it
        # (the plain RK4 stepper of oceangnc.core does not: its runs are summarised on their logged rows)
        if self._sea and events is not None and integrator != "rk4":
            p, self._ev_idx = attach_events(p, nmax, events)
        c = cable_cfg
        mrb = p[P_UUV + P_MRB : P_UUV + P_MRB + 36].reshape(6, 6)
        ma = p[P_UUV + P_MA : P_UUV + P_MA + 36].reshape(6, 6)
        end_mass = float(mrb[0, 0] + ma[0, 0])
        if integrator == "imex":
            # no stability limit from the axial modes: the step is set by accuracy (docs/uuv-and-cable.md)
            self.stability_limit = math.inf
        else:
            self.stability_limit = axial_stability_limit(
                c, end_mass=end_mass, last_damper_only=(integrator == "rk4-split")
            )
            if has_bed:  # the explicit contact spring: RK4 limit 2.785 / w on the imaginary axis
                self.stability_limit = min(self.stability_limit, 2.0 / seabed.contact_frequency)
        self.stability_limit = min(self.stability_limit, wf_limit)
        inputs = INPUT_NAMES + (("winch.speed_cmd",) if has_winch else ())
        units = ("N", "N", "m/s", "m/s", "m/s", "m/s", "N", "N", "N") + (("m/s",) if has_winch else ())
        super().__init__(
            name,
            k["combined_rhs"],
            x0,
            p,
            names,
            inputs,
            state_bound=1e6,
            max_dt=self.stability_limit if math.isfinite(self.stability_limit) else None,
            input_units=units,
            input_defaults=CALM,
        )
        if integrator != "rk4":  # same signature as the RK4 stepper: Plant.advance calls it
            self._advance = k["imex_advance"] if integrator == "imex" else k["split_advance"]
        self._var = has_winch or has_bed
        self._nodes = np.zeros(3 * (nmax + 1))
        self._ends = np.zeros(8)
        self.o_uuv = int(self.p[H_UO])
        self._out_keys, self._out_idx, n_full = output_keys(nmax, has_winch, has_bed)
        self._out_full = np.zeros(n_full)
        self.output_units = {k: _unit_of(k) for k in self._out_keys}
        self._wf_idx = np.zeros(0, dtype=np.int64)
        if self._wf:  # usv.z, usv.phi, usv.theta: the wave-frequency heave, roll and pitch
            ow = int(self.p[int(self.p[int(self.p[H_SEA]) + S_WF]) + W_XO])
            self._wf_idx = np.array([ow + k for _, k in WF_OUTPUTS], dtype=np.int64)
            self.output_units.update({k: _unit_of(k) for k, _ in WF_OUTPUTS})
        self.output_units.update(event_units(self._ev_idx))
        self._out = np.zeros(len(self._out_keys))

    @property
    def _kernels(self):
        """The compiled kernels by name for this plant's features (:func:`._combined_variants.kernels`; a
        property, not state: a checkpoint stores the features)."""
        return kernels(*self._features)

    @property
    def n(self) -> int:
        """Active number of segments (changes with a winch)."""
        return int(self.p[H_N])

    def reset(self) -> None:
        """Restore the initial state and node count (and forget the wave expansions)."""
        super().reset()
        reset_sea(self.p)
        if self._ev_idx.size:
            reset_events(self.p, int(self.p[int(self.p[H_SEA]) + S_EV]))
        if self.winch_cfg is not None:
            l0 = self.p[H_L0]
            self.p[H_N] = max(1, int(round(self.cable_cfg.length / l0)))

    def advance(self, t: float, dt: float, n: int) -> float:
        """RK4 steps, for ``integrator="rk4-split"`` Strang-split steps (:func:`split_advance`), for
        ``"imex"`` ROS2 steps with the axial cable forces implicit (:func:`imex_advance`): the kernel is
        chosen in ``__init__`` (``self._advance``). At sea the wave expansions are refreshed before each
        chunk of at most ``wave_update_dt`` (:func:`~oceangnc.models._combined_sea.sea_update`)."""
        if not self._sea:
            return super().advance(t, dt, n)
        m = max(1, int(self._sea_dt / dt + 1e-9))
        while n > 0:
            k = min(m, n)
            sea_update(t, self.x, self.p, k * dt)
            t = super().advance(t, dt, k)
            n -= k
        return t

    def compile_jobs(self) -> list[tuple]:
        """The stepper of the plant's integrator and, at sea, the wave refresh, with arguments of the
        fused loop's types (:meth:`oceangnc.core.blocks.Plant.compile_jobs`).

        The stepper's parts that the output function does not share come first, with the argument types
        the stepper passes them (the IMEX factorisation and solve, the two vehicles' laws): while a child
        compiles them (:func:`oceangnc.core.caches.compile_ahead`), the run's own process compiles the
        output function for its first publish, and with it the cable chain the stepper shares, which
        the child then loads instead of compiling it a second time at the same moment."""
        k, x, p, o = self._kernels, self.x, self.p, self.o_uuv
        n = np.int64(self.n)
        jobs = []
        if self.integrator == "imex":
            jobs += [
                (k["_imex_factor"], (x, p, n, 0.0)),
                (k["_imex_solve"], (x, p, n, self.work[0], 0.0, 0.0, 0.0)),
            ]
        jobs += [
            (usv_rhs, (0.0, x[0:6], self.u[0:6], p[P_USV : P_USV + N_USV], x[0:6])),
            (uuv_deriv, (x[o : o + 12], x[o : o + 12], p[P_UUV : P_UUV + UUV_NP], *([0.0] * 8))),
        ]
        jobs += super().compile_jobs()
        if self._sea:
            jobs.append((sea_update, (0.0, self.x, self.p, 0.0)))
        return jobs

    def publish_jobs(self) -> list[tuple]:
        """The output function :meth:`publish` and the fused loop call, with its arguments: compiled
        ahead with :meth:`compile_jobs` by a builder that starts the child before the simulation
        (the combined scenarios, before their trims)."""
        if self._var:
            args = (self.x, self.p, self.o_uuv, self._nodes, self._ends, self._out_full, self.u, self.n_max)
            return [(self._kernels["_fill_outputs_var"], args)]
        return [(self._kernels["_fill_outputs"], (self.x, self.p, self.o_uuv, self._nodes, self._ends, self._out))]

    def compiled_form(self, slot_of):
        """The fused loop's form (:func:`oceangnc.models._combined_form.combined_plant_form`)."""
        return combined_plant_form(self, slot_of)

    # -- outputs -----------------------------------------------------------------------------------
    def cable_snapshot(self):
        """(nodes (n+1, 3) NED m, top force (3,) N, bottom force (3,) N) at the current state."""
        self._ends[6] = self.u[2]
        self._ends[7] = self.u[3]
        m = 3 * (self.n + 1)
        self._kernels["cable_state"](self.x, self.p, self._nodes[:m], self._ends)
        return self._nodes[:m].reshape(-1, 3), self._ends[0:3], self._ends[3:6]

    def publish(self, bus: dict) -> None:
        """Write the vehicles' states (headings wrapped to (-pi, pi]), speeds, end tensions (N), cable
        angle from vertical (deg) and node positions (m, NED): one compiled call, one dict update."""
        self._ends[6] = self.u[2]
        self._ends[7] = self.u[3]
        if self._var:
            self._kernels["_fill_outputs_var"](
                self.x, self.p, self.o_uuv, self._nodes, self._ends, self._out_full, self.u, self.n_max
            )
            self._out[:] = self._out_full[self._out_idx]
        else:
            self._kernels["_fill_outputs"](self.x, self.p, self.o_uuv, self._nodes, self._ends, self._out)
        bus.update(zip(self._out_keys, self._out.tolist()))
        for (k, _), i in zip(WF_OUTPUTS, self._wf_idx):
            bus[k] = float(self.x[i])
        for k, i in zip(EVENT_KEYS, self._ev_idx):
            bus[k] = float(self.p[i])

    def events(self, end: str = "top") -> np.ndarray:
        """The slack events recorded on every integration step at the ``end`` ("top" or "bottom") after the
        start-up transient, rows (start s, slack duration s, peak N within the snap window after it);
        empty without in-step tracking (the ``events`` argument)."""
        if not self._ev_idx.size:
            return np.zeros((0, 3))
        return event_table(self.p, int(self.p[int(self.p[H_SEA]) + S_EV]), ENDS.index(end))

    # -- diagnostics -------------------------------------------------------------------------------
    def energy(self) -> float:
        """Mechanical energy (J) in still water: UUV (kinetic + potential), cable interior nodes'
        kinetic energy (with their current mass matrices), cable potential (submerged weight at the
        segment centres) and strain energy 1/2 EA l0 eps^2 of stretched segments. The USV is not
        included (the cable does not act on it). Conserved when drag, damping and added mass are off.
        """
        n = self.n
        nodes, _, _ = self.cable_snapshot()
        self.rhs(0.0, self.x, self.u, self.p, np.zeros_like(self.x))  # fills node velocities and masses
        p = self.p
        m = 3 * (n + 1)
        vel = p[P_SCR + m : P_SCR + 2 * m].reshape(-1, 3)
        Mn = p[P_SCR + 3 * m : P_SCR + 5 * m].reshape(-1, 6)
        ke = 0.0
        for i in range(1, n):
            a = Mn[i]
            M = np.array([[a[0], a[1], a[2]], [a[1], a[3], a[4]], [a[2], a[4], a[5]]])
            ke += 0.5 * vel[i] @ M @ vel[i]
        seg = np.diff(nodes, axis=0)
        ln = np.linalg.norm(seg, axis=1)
        l0s = np.full(n, p[H_L0])
        l0s[0] = top_l0(self.x, p, n)
        eps = np.maximum(ln - l0s, 0.0) / l0s
        strain = 0.5 * p[H_EA] * float(np.sum(l0s * eps**2))
        zc = 0.5 * (nodes[:-1, 2] + nodes[1:, 2])
        pe = -p[H_WSEG] / p[H_L0] * float(np.sum(l0s * zc))
        o = self.o_uuv
        e_uuv = uuv_energy(self.x[o : o + 12], p[P_UUV : P_UUV + UUV_NP])
        return float(ke + strain + pe + e_uuv)

    def submerged_weight(self) -> float:
        """Submerged weight (N) of the whole cable plus the UUV."""
        n = self.n
        length = (n - 1) * self.p[H_L0] + top_l0(self.x, self.p, n)
        return self.cable_cfg.weight_per_length * length + self.uuv_cfg.weight_in_water_kgf * G
