"""One system contract for every model of the project: :class:`Model` and its :class:`ParamLayout`.

A model (in the spirit of python-control's named I/O systems and of MuJoCo's model/data split) is

* a numba-compiled right-hand side ``f(t, x, u, p, out)`` writing dx/dt of the states into ``out``;
* optionally an output function ``h(t, x, u, p, out)`` writing the outputs (what a sensor set
  measures); without one the outputs are the states;
* declared names and units of its states, inputs, outputs and parameters;
* a nominal parameter vector ``p`` whose layout (:class:`ParamLayout`) is *generated once from the
  declared parameter names* (scalars and fixed-size blocks such as a 6 x 6 mass matrix); compiled code
  indexes ``p`` through constants taken from the layout (``I = LAYOUT.index; P_D11 = I("d11")``),
  never through hand-kept numbers;
* optionally an analytic Jacobian ``jac(t, x, u, p, J)`` with ``J = [df/dx, df/dp]`` (n_x x (n_x + n_p)).

The same object feeds :class:`~oceangnc.core.blocks.Plant` (:meth:`Model.plant`), the
augmented-state EKF (:func:`oceangnc.identification.ekf.run_ekf`, which identifies any parameter
by name) and :func:`oceangnc.core.linearize.trim` / :func:`~oceangnc.core.linearize.linearize`.
For complex-step Jacobians ``f`` must run in complex arithmetic: write it with the functions of
:mod:`oceangnc.core.csmath` (``csin``, ``cabs``, ``catan2``...) and compare real parts in branches.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from dataclasses import dataclass

import numpy as np

from ..errors import InputError


@dataclass(frozen=True)
class Param:
    """A declared parameter: ``name``, ``unit`` (free text, SI), ``size`` (a block of that many
    consecutive values, e.g. 36 for a row-major 6 x 6 matrix), ``derived`` (computed from others, e.g.
    an inverse mass matrix: not estimable), ``description``."""

    name: str
    unit: str = "1"
    size: int = 1
    derived: bool = False
    description: str = ""


class ParamLayout:
    """Offsets of the parameters in the flat vector ``p``, generated from the declarations in order.

    ``layout.index("d11")`` is the offset of a scalar (or the first entry of a block),
    ``layout.block("M_A")`` its slice, ``layout.names`` the scalar names (a block of size k
    contributes ``name[0] ... name[k-1]``), ``layout.size`` the length of ``p``;
    :meth:`pack` / :meth:`unpack` convert between ``{name: value}`` and the vector.
    """

    def __init__(self, params: Sequence[Param | tuple]):
        self.params: tuple[Param, ...] = tuple(q if isinstance(q, Param) else Param(*q) for q in params)
        self._off: dict[str, int] = {}
        names: list[str] = []
        units: list[str] = []
        derived: list[bool] = []
        k = 0
        for q in self.params:
            if q.name in self._off:
                raise ValueError(f"parameter '{q.name}' declared twice")
            if q.size < 1:
                raise ValueError(f"parameter '{q.name}': size must be >= 1")
            self._off[q.name] = k
            if q.size == 1:
                names.append(q.name)
            else:
                names.extend(f"{q.name}[{i}]" for i in range(q.size))
            units.extend([q.unit] * q.size)
            derived.extend([q.derived] * q.size)
            k += q.size
        self.size = k
        self.names: tuple[str, ...] = tuple(names)
        self.units: tuple[str, ...] = tuple(units)
        self.derived: tuple[bool, ...] = tuple(derived)
        self._flat = {n: i for i, n in enumerate(self.names)}

    def __len__(self) -> int:
        return self.size

    def __contains__(self, name: str) -> bool:
        return name in self._off or name in self._flat

    def index(self, name: str) -> int:
        """Offset of a scalar parameter, of an element ``"name[i]"``, or of a block's first entry."""
        if name in self._off:
            return self._off[name]
        if name in self._flat:
            return self._flat[name]
        raise InputError(f"unknown parameter '{name}'; known: {', '.join(q.name for q in self.params)}")

    def indices(self, *names: str) -> tuple[int, ...]:
        """Offsets of several parameters (for module constants of compiled code)."""
        return tuple(self.index(n) for n in names)

    def block(self, name: str) -> slice:
        """Slice of ``p`` holding parameter ``name``."""
        i = self.index(name)
        size = next(q.size for q in self.params if q.name == name) if name in self._off else 1
        return slice(i, i + size)

    def pack(self, values: Mapping[str, object]) -> np.ndarray:
        """``{name: value or array}`` -> flat vector; every declared parameter must be given."""
        missing = [q.name for q in self.params if q.name not in values]
        extra = [k for k in values if k not in self._off]
        if missing or extra:
            raise ValueError(f"pack: missing {missing}, unknown {extra}")
        p = np.zeros(self.size)
        for q in self.params:
            p[self.block(q.name)] = np.asarray(values[q.name], dtype=np.float64).ravel()
        return p

    def unpack(self, p) -> dict[str, object]:
        """Flat vector -> ``{name: float or array}``."""
        p = np.asarray(p, dtype=np.float64)
        if p.size != self.size:
            raise ValueError(f"unpack: expected {self.size} values, got {p.size}")
        return {
            q.name: (float(p[self._off[q.name]]) if q.size == 1 else p[self.block(q.name)].copy()) for q in self.params
        }


def _pairs(decl, what: str) -> tuple[tuple[str, ...], tuple[str, ...]]:
    names, units = [], []
    for d in decl:
        if isinstance(d, str):
            raise TypeError(f"{what} '{d}': declare (name, unit)")
        names.append(d[0])
        units.append(d[1])
    if len(set(names)) != len(names):
        raise ValueError(f"{what}: repeated names in {names}")
    return tuple(names), tuple(units)


class Model:
    """A continuous-time model with declared signals and parameters (see the module docstring).

    Parameters
    ----------
    name : str
    f : numba dispatcher ``f(t, x, u, p, out)``
    states, inputs : sequences of ``(name, unit)``
    layout : ParamLayout
    p : array (layout.size,) nominal parameters
    h : numba dispatcher ``h(t, x, u, p, out)``, optional (default: outputs = states)
    outputs : sequence of ``(name, unit)`` (required with ``h``)
    jac : numba dispatcher ``jac(t, x, u, p, J)``, optional analytic [df/dx, df/dp]
    complex_safe : bool
        ``f`` and ``h`` run in complex arithmetic (complex-step Jacobians available).
    bound : float
        |state| or |estimate| above this counts as divergence (EKF).
    """

    def __init__(
        self,
        name: str,
        f,
        states,
        inputs,
        layout: ParamLayout,
        p,
        h=None,
        outputs=None,
        jac=None,
        complex_safe: bool = True,
        bound: float = 1e6,
        description: str = "",
    ):
        self.name = name
        self.f = f
        self.h = h
        self.jac = jac
        self.state_names, self.state_units = _pairs(states, "state")
        self.input_names, self.input_units = _pairs(inputs, "input")
        if h is None:
            if outputs is not None:
                raise ValueError(f"model {name}: outputs declared without an output function h")
            self.output_names, self.output_units = self.state_names, self.state_units
        else:
            if outputs is None:
                raise ValueError(f"model {name}: an output function h needs declared outputs")
            self.output_names, self.output_units = _pairs(outputs, "output")
        self.layout = layout
        p = np.ascontiguousarray(p, dtype=np.float64)
        if p.size != layout.size:
            raise ValueError(f"model {name}: {p.size} parameters for a layout of {layout.size}")
        self.p = p
        self.complex_safe = bool(complex_safe)
        self.bound = float(bound)
        self.description = description

    # names the EKF interface uses
    @property
    def param_names(self) -> tuple[str, ...]:
        return self.layout.names

    @property
    def params(self) -> np.ndarray:
        return self.p

    @property
    def measurement_names(self) -> tuple[str, ...]:
        return self.output_names

    @property
    def nx(self) -> int:
        return len(self.state_names)

    @property
    def nu(self) -> int:
        return len(self.input_names)

    def with_params(self, **values: float) -> Model:
        """A copy with some scalar parameters changed by name (``model.with_params(d11=700.0)``)."""
        p = self.p.copy()
        for k, v in values.items():
            p[self.layout.index(k)] = v
        return Model(
            self.name,
            self.f,
            tuple(zip(self.state_names, self.state_units)),
            tuple(zip(self.input_names, self.input_units)),
            self.layout,
            p,
            h=self.h,
            outputs=None if self.h is None else tuple(zip(self.output_names, self.output_units)),
            jac=self.jac,
            complex_safe=self.complex_safe,
            bound=self.bound,
            description=self.description,
        )

    def deriv(self, x, u, p=None, t: float = 0.0) -> np.ndarray:
        """dx/dt at (t, x, u) (a convenience for checks; compiled code calls ``f`` directly)."""
        out = np.zeros(self.nx)
        self.f(
            float(t),
            np.asarray(x, dtype=np.float64),
            np.asarray(u, dtype=np.float64),
            self.p if p is None else np.asarray(p, dtype=np.float64),
            out,
        )
        return out

    def output(self, x, u, p=None, t: float = 0.0) -> np.ndarray:
        """Outputs at (t, x, u)."""
        x = np.asarray(x, dtype=np.float64)
        if self.h is None:
            return x.copy()
        out = np.zeros(len(self.output_names))
        self.h(float(t), x, np.asarray(u, dtype=np.float64), self.p if p is None else np.asarray(p, float), out)
        return out

    def simulate(self, t, U, x0, substeps: int = 10, p=None) -> np.ndarray:
        """States at the sample times ``t`` (N,) for inputs ``U`` (N, n_u) held over each interval (RK4,
        ``substeps`` steps per interval); the truth of simulated identification trials."""
        from .integrators import rk4_advance, rk4_workspace

        t = np.asarray(t, dtype=np.float64)
        U = np.asarray(U, dtype=np.float64).reshape(t.size, self.nu)
        pp = self.p if p is None else np.asarray(p, dtype=np.float64)
        x = np.array(x0, dtype=np.float64)
        X = np.zeros((t.size, self.nx))
        work = rk4_workspace(self.nx)
        X[0] = x
        for k in range(t.size - 1):
            dt = (t[k + 1] - t[k]) / substeps
            tn = rk4_advance(self.f, t[k], x, np.ascontiguousarray(U[k]), pp, dt, substeps, work)
            if tn < 0:
                raise InputError(f"model {self.name}: simulation diverged at t={t[k]:.3f} s")
            X[k + 1] = x
        return X

    def plant_args(
        self, name: str, x0, input_signals: Sequence[str] | None = None, p=None, declare: bool = False
    ) -> dict:
        """Keyword arguments of :class:`~oceangnc.core.blocks.Plant` for this model.

        ``input_signals`` are the bus keys of the inputs (default ``<name>.<input>``); with
        ``declare`` the plant declares its state and input units for the simulation's wiring check.
        """
        sig = list(input_signals) if input_signals is not None else [f"{name}.{k}" for k in self.input_names]
        if len(sig) != self.nu:
            raise ValueError(f"model {self.name}: {len(sig)} input signals for {self.nu} inputs")
        kw = {
            "name": name,
            "rhs": self.f,
            "x0": np.asarray(x0, dtype=np.float64),
            "p": self.p if p is None else np.asarray(p, dtype=np.float64),
            "state_names": self.state_names,
            "input_names": sig,
        }
        if declare:
            kw.update(state_units=self.state_units, input_units=self.input_units)
        return kw

    def plant(self, name: str, x0, input_signals: Sequence[str] | None = None, p=None, declare: bool = True, **kw):
        """A :class:`~oceangnc.core.blocks.Plant` integrating this model (extra keywords: ``max_dt``...)."""
        from .blocks import Plant
        from .signals import CALM

        args = self.plant_args(name, x0, input_signals, p, declare)
        # environment inputs read calm water and air when no environment block runs
        kw.setdefault("input_defaults", {k: v for k, v in CALM.items() if k in args["input_names"]})
        return Plant(**args, **kw)

    def __repr__(self) -> str:
        return (
            f"Model({self.name!r}: states {list(self.state_names)}, inputs {list(self.input_names)}, "
            f"{self.layout.size} parameters)"
        )


# -- the model registry -------------------------------------------------------------------------------

#: entry-point group naming the models by name: ``name = "module:factory"``, ``factory(params=None)``
MODEL_GROUP = "oceangnc.models"


def _model_entry_points() -> dict:
    from importlib.metadata import entry_points

    return {ep.name: ep for ep in entry_points(group=MODEL_GROUP)}


def model_names() -> list[str]:
    """Names of the registered models (the package's in pyproject.toml, and any user package's
    ``oceangnc.models`` entry points): ``oceangnc identify ekf --model NAME`` and :func:`get_model`."""
    return sorted(_model_entry_points())


def get_model(name: str, params=None) -> Model:
    """The model registered as ``name`` (parameters ``params`` or its defaults); unknown names give
    InputError listing the known ones."""
    eps = _model_entry_points()
    if name not in eps:
        raise InputError(f"unknown model '{name}'; known models: {', '.join(sorted(eps))}")
    return eps[name].load()(params=params)


class ModelNames:
    """A live view of :func:`model_names` (``name in MODELS``, ``', '.join(MODELS)``)."""

    def __iter__(self):
        return iter(model_names())

    def __contains__(self, name) -> bool:
        return name in _model_entry_points()

    def __len__(self) -> int:
        return len(model_names())
