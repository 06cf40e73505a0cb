"""One system contract: every model of the project is a Model (f(t, x, u, p, out), declared names and
units, generated parameter layout); Plant, linearize and trim take it (issue 17, part B)."""

from __future__ import annotations

import math
import re
from pathlib import Path

import numpy as np
import pytest

from oceangnc.core.linearize import jacobian_columns, linearize, trim
from oceangnc.core.model import Model, Param, ParamLayout
from oceangnc.core.signals import UNITS
from oceangnc.errors import InputError
from oceangnc.units import KGF

SRC = Path(__file__).resolve().parents[1] / "src" / "oceangnc"


def _usv():
    from oceangnc.models.usv import usv_model

    return usv_model(), [1.0, 2.0, 0.3, 0.7, 0.1, 0.2], [200.0, 150.0, 0.1, 0.05, 2.0, 1.0]


def _uuv():
    from oceangnc.models.uuv import uuv_model

    x = [1.0, 2.0, 3.0, 0.05, 0.1, 0.3, 1.2, 0.1, 0.05, 0.02, -0.03, 0.1]
    return uuv_model(tow_point=(0.1, 0.0, 0.05)), x, [20.0, 15.0, 5.0, 0.1, 0.2]


def _ship():
    from oceangnc.models.ship_lowspeed import ship_model

    x = [0.0, 0.0, 0.2, 3.0, 0.3, 0.01, 0.1, 1.0, 0.5, -0.5]
    return ship_model(), x, [0.2, 1.5, 2.0, -2.0, 0.1, 0.2, 3.0, 4.0]


def _first_order():
    from oceangnc.models.first_order import first_order_model

    return first_order_model(), [0.0, 0.0, 0.3, 6.0, 0.05], [1500.0, 0.1, 6.0]


def _submarine():
    from oceangnc.models.submarine_vertical import filter_model

    return filter_model(), [0.1, 0.02, 0.01], [0.05]


CASES = {"usv": _usv, "uuv": _uuv, "ship": _ship, "first-order": _first_order, "submarine": _submarine}


@pytest.mark.parametrize("name", CASES)
def test_models_declare_names_units_and_layout(name):
    """Each model declares states, inputs and parameters with units; the layout is generated from the
    names (offsets consecutive, pack/unpack round trip)."""
    m, x, u = CASES[name]()
    assert isinstance(m, Model)
    assert len(m.state_names) == len(m.state_units) == len(x)
    assert len(m.input_names) == len(m.input_units) == len(u)
    assert all(un in UNITS for un in (*m.state_units, *m.input_units))
    assert len(m.param_names) == m.layout.size == m.p.size
    back = m.layout.pack(m.layout.unpack(m.p))
    assert np.array_equal(back, m.p)
    for q in m.layout.params:
        assert m.layout.index(q.name) + q.size <= m.layout.size
        assert q.unit


def test_no_hand_kept_parameter_indices():
    """Compiled right-hand sides index p only through names taken from the layout: no ``p[<digit>``."""
    for f in ("usv.py", "uuv.py", "ship_lowspeed.py", "first_order.py", "submarine_vertical.py"):
        text = (SRC / "models" / f).read_text()
        assert not re.findall(r"\bp\[\d", text), f
        assert not re.findall(r"^P_\w+ = \d", text, flags=re.MULTILINE), f


def test_uuv_layout_offsets_are_generated():
    """The UUV's P_* offsets (used by the combined model) come from the layout; M_inv is derived."""
    from oceangnc.models import uuv

    lay = uuv.LAYOUT
    assert (uuv.P_MRB, uuv.P_MA, uuv.P_MINV, uuv.P_RC, uuv.NP) == (8, 44, 80, 138, 141)
    assert lay.block("M_A") == slice(44, 80)
    assert lay.derived[lay.index("M_inv[0]")] and not lay.derived[lay.index("X_uu")]
    with pytest.raises(ValueError, match="declared twice"):
        ParamLayout([Param("a"), Param("a")])
    with pytest.raises(InputError, match="unknown parameter 'zz'"):
        lay.index("zz")


@pytest.mark.parametrize("name", CASES)
def test_linearize_matches_finite_differences(name):
    """Complex-step A, B (and df/dp, used by the EKF) agree with central differences to < 1e-6
    relative (entries relative to the largest of their row)."""
    m, x, u = CASES[name]()
    x = np.array(x, float)
    u = np.array(u, float)
    lin = linearize(m, x, u, jacobian="complex-step")
    cols = np.arange(m.nx, m.nx + m.layout.size)
    Fp, _ = jacobian_columns(m, x, u, cols, jacobian="complex-step")
    J = np.hstack([lin.A, lin.B, Fp])
    ys = [("x", i) for i in range(m.nx)] + [("u", i) for i in range(m.nu)] + [("p", i) for i in range(m.layout.size)]
    Jfd = np.zeros_like(J)
    for c, (kind, i) in enumerate(ys):
        base = {"x": x, "u": u, "p": m.p}[kind]
        h = 1e-6 * max(abs(base[i]), 1e-3)
        vals = []
        for s in (1, -1):
            b = base.copy()
            b[i] += s * h
            xx, uu, pp = (b if kind == "x" else x), (b if kind == "u" else u), (b if kind == "p" else m.p)
            vals.append(m.deriv(xx, uu, pp))
        Jfd[:, c] = (vals[0] - vals[1]) / (2 * h)
    scale = np.maximum(np.abs(J).max(axis=1, keepdims=True), 1e-300)
    assert np.all(np.isfinite(J))
    err = np.abs(J - Jfd) / scale
    assert err.max() < 1e-6, (name, np.unravel_index(err.argmax(), err.shape), err.max())


def test_usv_trim_straight_running_fig_2_7():
    """trim(): the USV at 30 + 30 kgf runs straight at 0.800 m/s (003 fig 2-7, within 0.1 %), v = r = 0,
    and the linearisation there has only stable or neutral (position/heading) modes."""
    from oceangnc.models.usv import usv_model

    m = usv_model()
    T = 30 * KGF
    res = trim(m, [0, 0, 0, 0.5, 0.05, 0.05], [T, T, 0, 0, 0, 0], free=("u", "v", "r"), zero=("u", "v", "r"))
    assert res.x[3] == pytest.approx(0.8, rel=1e-3)
    assert abs(res.x[4]) < 1e-12 and abs(res.x[5]) < 1e-12
    assert res.iterations < 20
    ev = linearize(m, res.x, res.u).eigenvalues()
    assert np.all(ev.real < 1e-9)
    assert np.sum(ev.real < -1e-6) == 3  # surge, sway, yaw decay; x, y, psi neutral
    # the 30 / 15 kgf turn of fig 2-8: 16 deg/s on a 1.75 m circle (1 %)
    res = trim(
        m, [0, 0, 0, 0.5, 0.0, 0.1], [30 * KGF, 15 * KGF, 0, 0, 0, 0], free=("u", "v", "r"), zero=("u", "v", "r")
    )
    r = res.x[5]
    assert math.degrees(r) == pytest.approx(16.0, rel=1e-2)
    assert math.hypot(res.x[3], res.x[4]) / r == pytest.approx(1.75, rel=1e-2)


def test_uuv_trim_steady_speed():
    """trim() of the full 6-DOF UUV, neutrally buoyant, equal stern thrusts T: straight and level at the
    drag-balance speed X_u u + X_uu u|u| + 2T = 0, the same as uuv_steady_planar (1e-9)."""
    from oceangnc.models.uuv import UUVConfig, uuv_model, uuv_steady_planar

    cfg = UUVConfig(weight_in_water_kgf=0.0)
    m = uuv_model(cfg)
    for T in (2.0, 20.0):
        x0 = cfg.initial_state()
        x0[6] = 1.0
        res = trim(
            m, x0, [T, T, 0.0, 0.0, 0.0], free=("u", "v", "w", "p", "q", "r"), zero=("u", "v", "w", "p", "q", "r")
        )
        a, b = -cfg.X_uu_total, -cfg.X_u
        assert res.x[6] == pytest.approx((-b + math.sqrt(b * b + 8 * a * T)) / (2 * a), rel=1e-9)
        assert np.abs(res.x[7:12]).max() < 1e-10
        assert res.x[6] == pytest.approx(uuv_steady_planar(cfg, T, T, 0.0)[0], rel=1e-9)


def test_trim_reports_bad_requests():
    from oceangnc.models.usv import usv_model

    m = usv_model()
    with pytest.raises(InputError, match="2 free variables for 3 equations"):
        trim(m, np.zeros(6), np.zeros(6), free=("u", "v"), zero=("u", "v", "r"))
    with pytest.raises(InputError, match="'foo' is neither a state nor an input"):
        trim(m, np.zeros(6), np.zeros(6), free=("foo",), zero=("u",))


def test_submarine_linearisation_is_the_open_loop_modes():
    """linearize() of the 002 submarine (analytic Jacobian) gives the open-loop eigenvalues of the
    model docstring: -0.034 +/- 0.022j and -0.0097 1/s."""
    from oceangnc.models.submarine_vertical import filter_model

    m = filter_model()
    ev = np.sort_complex(linearize(m, np.zeros(3), [0.0], jacobian="analytic").eigenvalues())
    cs = np.sort_complex(linearize(m, np.zeros(3), [0.0], jacobian="complex-step").eigenvalues())
    assert np.allclose(ev, cs, rtol=1e-9)
    assert ev[0].real == pytest.approx(-0.034, abs=1e-3) and abs(ev[0].imag) == pytest.approx(0.022, abs=1e-3)
    assert ev[2].real == pytest.approx(-0.0097, abs=2e-4)


def test_plant_from_model_matches_the_model_plant():
    """A Plant built from the Model (declared units) integrates exactly as USVPlant does."""
    from oceangnc.models.usv import USVConfig, USVPlant, usv_model

    cfg = USVConfig()
    a = USVPlant(cfg)
    b = usv_model(cfg).plant("usv", a.x0, input_signals=a.input_names)
    assert b.inputs["usv.thrust_port"] == "N" and b.outputs["usv.psi"] == "rad"
    bus = {
        "usv.thrust_port": 250.0,
        "usv.thrust_stbd": 150.0,
        "env.current_n": 0.1,
        "env.current_e": 0.0,
        "env.wind_n": 0.0,
        "env.wind_e": 2.0,
    }
    for pl in (a, b):
        pl.read_inputs(bus)
        pl.advance(0.0, 0.01, 200)
    assert np.array_equal(a.x, b.x)


def test_closure_kernels_have_their_own_cache_files():
    """Jacobian kernels of two models are cached in separate numba index files (no cross-model
    overwrite when processes compile different models at once), and the same model maps to the same
    file (a new process reuses it)."""
    from oceangnc.core.linearize import cached_closure, jacobian_functions
    from oceangnc.models.first_order import first_order_rhs
    from oceangnc.models.usv import usv_rhs

    a, _ = jacobian_functions(usv_rhs, None, None, "complex-step")
    b, _ = jacobian_functions(first_order_rhs, None, None, "complex-step")

    def name(d):
        return d._cache._cache_file._index_name

    assert name(a) != name(b)

    def make(g):
        def k(t, x, u, p, out):
            g(t, x, u, p, out)

        return k

    assert name(cached_closure(make(usv_rhs))) == name(cached_closure(make(usv_rhs)))


def test_an_interpreted_trim_compiles_nothing_and_finds_the_compiled_models_root():
    """trim(interpreted=True) (the combined scenarios' turning radii at start-up): the model's and the
    finite-difference Jacobian's Python bodies, so a model never compiled stays uncompiled, and the root
    is the compiled model's to rounding (the fig 2-8 turn of 003: 30 / 15 kgf)."""
    from numba import njit

    from oceangnc.core.model import Model
    from oceangnc.models.usv import usv_model

    m = usv_model()
    fresh = njit(m.f.py_func)  # the same law, never compiled in this process
    states, inputs = zip(m.state_names, m.state_units), zip(m.input_names, m.input_units)
    mf = Model(m.name, fresh, tuple(states), tuple(inputs), m.layout, m.p)
    args = ([0, 0, 0, 0.5, 0.0, 0.1], [30 * KGF, 15 * KGF, 0, 0, 0, 0])
    kw = dict(free=("u", "v", "r"), zero=("u", "v", "r"), tol=1e-13, jacobian="finite-difference")
    res = trim(mf, *args, interpreted=True, **kw)
    assert fresh.signatures == []  # nothing compiled
    ref = trim(m, *args, **kw)
    assert np.allclose(res.x, ref.x, rtol=1e-12, atol=1e-15)
    assert math.degrees(res.x[5]) == pytest.approx(16.0, rel=1e-2)
    with pytest.raises(InputError, match="interpreted=True needs jacobian='finite-difference'"):
        trim(m, *args, free=("u", "v", "r"), zero=("u", "v", "r"), interpreted=True)
