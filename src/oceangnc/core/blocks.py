"""Blocks: discrete (sensors, guidance, control, actuators) and continuous (plants).

A *discrete block* fires every ``period`` seconds. Its :meth:`Block.step` reads named signals from the
signal bus (a plain ``dict[str, float]``) and writes its outputs back; the outputs stay on the bus
unchanged until the block fires again (zero-order hold). Its internal state lives in attributes, is
set by :meth:`Block.reset` and is never shared between blocks.

A *plant* holds continuous state as one flat float64 array with documented layout, a flat
parameter array, and a numba-compiled right-hand side ``rhs(t, x, u, p, out)``. Between two clock
ticks the simulator integrates it with the compiled RK4 of :mod:`oceangnc.core.integrators`, the
inputs ``u`` being read from the bus (zero-order hold) by name.

Signal names are ``<body>.<signal>``: ``usv.x``, ``usv.psi``, ``usv.thrust_port``; names that start
with ``_`` are internal and not logged.

**Declared signals** (see :mod:`oceangnc.core.signals`): a block sets ``inputs``,
``optional_inputs`` and ``outputs`` (``{signal: unit}``, usually in ``__init__`` since names carry the
body prefix); a plant declares its inputs (``input_units``) and outputs (every
``<name>.<state>`` with ``state_units``, plus ``extra_outputs`` for derived signals it publishes).
The simulation checks the wiring when it is built. ``None`` means "not declared" (legacy or quick
glue blocks) and is skipped by the check.

**State for checkpoints**: :meth:`Block.get_state` / :meth:`Block.set_state` return/restore every
piece of internal state (default: a deep copy of the instance's attributes); blocks holding
something that cannot be copied (a socket, a compiled function) override them.
"""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np
from numba import njit

from ..errors import DivergenceError
from .fused import CompiledBlock, PlantForm, _kernel_ref, advance_and_publish, rk4_stepper_imports
from .integrators import rk4_stepper, rk4_workspace


class Block:
    """A discrete-time block with explicit state.

    Subclasses set ``name`` and ``period`` (s) and implement :meth:`step`; they may override
    :meth:`reset` to (re)initialise their state from a random generator (for determinism every source
    of randomness is a ``numpy.random.Generator`` given here, never a global one).
    """

    name: str = "block"
    period: float = 0.01
    kind: str | None = None  # set by @register_block
    inputs: dict[str, str] | None = None
    optional_inputs: dict[str, str] | None = None
    outputs: dict[str, str] | None = None

    def get_state(self) -> dict:
        """A deep copy of the block's internal state (for checkpoints)."""
        import copy

        return copy.deepcopy(self.__dict__)

    def set_state(self, state: dict) -> None:
        """Restore what :meth:`get_state` returned."""
        import copy

        self.__dict__.update(copy.deepcopy(state))

    def reset(self, rng: np.random.Generator) -> None:  # noqa: D401 - default: stateless
        """Reinitialise the block's state; ``rng`` is the block's own generator."""

    def step(self, t: float, bus: dict) -> None:
        """Read inputs from ``bus`` and write outputs to it at time ``t`` (s)."""
        raise NotImplementedError

    def bus_outputs(self) -> list[str]:
        """The keys :meth:`step` writes on the bus at each firing: the declared outputs."""
        return list(self.outputs or {})


class FunctionBlock(Block):
    """A stateless block made from a function ``fn(t, bus)``; handy for commands and glue."""

    def __init__(
        self,
        name: str,
        period: float,
        fn,
        inputs: dict[str, str] | None = None,
        outputs: dict[str, str] | None = None,
        optional_inputs: dict[str, str] | None = None,
    ):
        self.name = name
        self.period = float(period)
        self._fn = fn
        self.inputs = dict(inputs) if inputs is not None else None
        self.outputs = dict(outputs) if outputs is not None else None
        self.optional_inputs = dict(optional_inputs) if optional_inputs is not None else None

    def step(self, t: float, bus: dict) -> None:
        self._fn(t, bus)


class Plant:
    """A continuous-time system integrated by the simulator.

    Parameters
    ----------
    name : str
        Body name; states are published as ``<name>.<state_name>``.
    rhs : numba dispatcher
        ``rhs(t, x, u, p, out)`` writing dx/dt into ``out``.
    x0 : array (n,)
        Initial state; its layout is ``state_names``.
    p : array
        Flat parameter array in the layout the ``rhs`` expects.
    input_names : sequence of str
        Bus keys read (zero-order hold) into ``u`` before each integration interval.
    state_bound : float
        A state component larger than this in magnitude counts as divergence (default 1e7).
    max_dt : float or None
        Largest stable physics step (s), if the model knows it; the simulator refuses larger steps.
    state_units, input_units : sequence of str, optional
        Units of the states and inputs (:data:`oceangnc.core.signals.UNITS`); when given, the
        plant's signals are declared and checked by the simulation's wiring check. Inputs whose
        name starts with ``_`` are internal (set by the plant itself, not read from the bus).
    input_defaults : dict, optional
        ``{input: value}`` for inputs that may legitimately be absent from the bus (declared as
        optional inputs; e.g. calm water when no environment block runs). Every other input must
        be written by some block: reading one that is absent raises
        :class:`~oceangnc.core.signals.WiringError` (it never reads as zero).
    extra_outputs : dict, optional
        Derived signals published besides the states, ``{signal: unit}``.
    outputs : dict, optional
        The complete ``{signal: unit}`` the plant publishes, for plants whose published names are
        not ``<name>.<state>`` (the combined vehicle); replaces the states + ``extra_outputs`` rule.
    """

    #: derived signals a subclass publishes besides its states, ``{signal: unit}``
    extra_outputs: dict[str, str] = {}
    #: explicit output declaration (see ``outputs`` above); None: states + extra_outputs
    output_units: dict[str, str] | None = None
    #: the child process compiling this plant's functions ahead (:func:`oceangnc.core.caches.compile_ahead`),
    #: started by whoever built the plant (else by the :class:`~oceangnc.core.clock.Simulation`); waited for
    #: before the plant is first advanced
    ahead = None

    def __init__(
        self,
        name: str,
        rhs,
        x0,
        p,
        state_names: Sequence[str],
        input_names: Sequence[str],
        state_bound: float = 1e7,
        max_dt: float | None = None,
        state_units: Sequence[str] | None = None,
        input_units: Sequence[str] | None = None,
        input_defaults: dict[str, float] | None = None,
        extra_outputs: dict[str, str] | None = None,
        outputs: dict[str, str] | None = None,
    ):
        self.name = name
        self.rhs = rhs
        self.x = np.array(x0, dtype=np.float64)
        self.x0 = self.x.copy()
        self.p = np.ascontiguousarray(p, dtype=np.float64)
        self.state_names = list(state_names)
        self.input_names = list(input_names)
        if len(self.state_names) != self.x.size:
            raise ValueError(f"plant {name}: {len(self.state_names)} state names for {self.x.size} states")
        self.u = np.zeros(len(self.input_names))
        self.work = rk4_workspace(self.x.size)
        self.state_bound = float(state_bound)
        self.max_dt = max_dt
        self._advance = rk4_stepper(rhs)
        self.state_units = list(state_units) if state_units is not None else None
        self.input_units = list(input_units) if input_units is not None else None
        if self.input_units is not None and len(self.input_units) != len(self.input_names):
            raise ValueError(f"plant {name}: {len(self.input_units)} input units for {len(self.input_names)} inputs")
        if self.state_units is not None and len(self.state_units) != len(self.state_names):
            raise ValueError(f"plant {name}: {len(self.state_units)} state units for {len(self.state_names)} states")
        self.input_defaults = dict(input_defaults or {})
        if extra_outputs is not None:
            self.extra_outputs = dict(extra_outputs)
        if outputs is not None:
            self.output_units = dict(outputs)

    def _declared_inputs(self, optional: bool) -> dict[str, str] | None:
        if self.input_units is None:
            return None
        return {
            k: u
            for k, u in zip(self.input_names, self.input_units)
            if not k.startswith("_") and (k in self.input_defaults) == optional
        }

    @property
    def inputs(self) -> dict[str, str] | None:
        """Declared required inputs ``{signal: unit}`` (None if the plant gave no input units)."""
        return self._declared_inputs(False)

    @property
    def optional_inputs(self) -> dict[str, str] | None:
        """Declared inputs with a default (``input_defaults``), ``{signal: unit}``."""
        return self._declared_inputs(True)

    @property
    def outputs(self) -> dict[str, str] | None:
        """Declared outputs: every ``<name>.<state>`` and :attr:`extra_outputs` (None if undeclared)."""
        if self.output_units is not None:
            return dict(self.output_units)
        if self.state_units is None:
            return None
        out = {f"{self.name}.{k}": u for k, u in zip(self.state_names, self.state_units)}
        out.update(self.extra_outputs)
        return out

    def reset(self) -> None:
        """Restore the initial state."""
        self.x[:] = self.x0

    def read_inputs(self, bus: dict) -> None:
        """Copy the plant's inputs from the bus (zero-order hold).

        An input absent from the bus takes its ``input_defaults`` value if it has one; otherwise
        it is a wiring error (a mistyped or unproduced signal never silently reads as zero).
        Internal inputs (``_`` prefix) are left to the plant.
        """
        for i, k in enumerate(self.input_names):
            try:
                self.u[i] = bus[k]
            except KeyError:
                if k in self.input_defaults:
                    self.u[i] = self.input_defaults[k]
                elif not k.startswith("_"):
                    from .signals import WiringError

                    raise WiringError(
                        f"plant '{self.name}' reads '{k}' but no block has written it "
                        f"(declare a producer or give the plant an input default)"
                    ) from None

    def compile_jobs(self) -> list[tuple]:
        """The compiled functions that advance this plant in the fused loop, each with arguments of the
        types the loop passes (``[(dispatcher, args)]``, :func:`oceangnc.core.caches.compile_ahead`):
        its stepper ``advance(t, x, u, p, dt, n, work, bound)``."""
        return [(self._advance, (0.0, self.x, self.u, self.p, 0.0, 1, self.work, float(self.state_bound)))]

    def advance(self, t: float, dt: float, n: int) -> float:
        """Integrate ``n`` RK4 steps of ``dt`` s from time ``t``; raises :class:`DivergenceError`."""
        t_new = self._advance(t, self.x, self.u, self.p, dt, n, self.work, self.state_bound)
        if t_new < 0.0:
            k = int(-t_new - 1.0)
            finite = bool(np.all(np.isfinite(self.x)))
            raise DivergenceError(
                t + (k + 1) * dt,
                self.name,
                self.state_dict(),
                reason=f"|state| above {self.state_bound:g}" if finite else "non-finite state",
            )
        return t_new

    def state_dict(self) -> dict[str, float]:
        """State as ``{"<name>.<state>": value}``."""
        return {f"{self.name}.{k}": float(v) for k, v in zip(self.state_names, self.x)}

    def publish(self, bus: dict) -> None:
        """Write the plant's outputs to the bus. Default: every state; subclasses add derived signals."""
        for k, v in zip(self.state_names, self.x):
            bus[f"{self.name}.{k}"] = float(v)

    def compiled_form(self, slot_of) -> PlantForm | None:
        """The plant's part of the fused loop (:class:`~oceangnc.core.fused.PlantForm`).

        Default: the disk-cached RK4 stepper of ``rhs`` and every state published. A subclass with
        its own integration or outputs returns its own form from its own module (or None: the
        simulation then runs on the Python clock, saying why)."""
        if type(self).advance is not Plant.advance or type(self).publish is not Plant.publish:
            return None
        mod, name = _kernel_ref(self.rhs)
        if mod is None or name is None or "<" in name:
            return None
        names = [f"{self.name}.{k}" for k in self.state_names]
        return advance_and_publish(self, slot_of, rk4_stepper_imports(self.rhs), names, states_publish)


class ConstantBlock(Block):
    """A block writing constant values ``{signal: value}`` every period (open-loop commands, set points).

    Unlike a :class:`FunctionBlock` it has a compiled form, so a scenario made of it runs fused
    (:mod:`oceangnc.core.fused`).
    """

    def __init__(self, name: str, period: float, values: dict[str, float], units: dict[str, str] | None = None):
        self.name = name
        self.period = float(period)
        self.values = {k: float(v) for k, v in values.items()}
        if units is not None:
            self.inputs = {}
            self.outputs = {k: units[k] for k in self.values}

    def step(self, t: float, bus: dict) -> None:
        bus.update(self.values)

    def compiled(self):
        """Compiled form: :func:`constant_step`, the same constants."""
        return CompiledBlock(constant_step, list(self.values), params=np.array(list(self.values.values())))


@njit(cache=True)
def constant_step(t, sig, sl, st, pa):
    """A block writing constants: ``sig[sl[i]] = pa[i]``."""
    for i in range(sl.size):
        sig[sl[i]] = pa[i]


@njit(cache=True)
def scatter(out, sig, slots):
    """``sig[slots[i]] = out[i]``."""
    for i in range(slots.size):
        sig[slots[i]] = out[i]


@njit(cache=True)
def states_publish(x, sig, slots):
    """:meth:`Plant.publish` in the fused loop: every state (one slot per state)."""
    scatter(x, sig, slots)
