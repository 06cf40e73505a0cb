"""Towed UUV as a trailer of the USV (document 000 eq. 2-7, tractor-trailer model).

Assumptions of 000 sec. 2.1: planar motion, taut cable of length L, the UUV's heading equal to the
cable's direction. With phi = psi_UUV - psi_USV (000 eq. 5)::

    u_UUV = u_USV cos(phi)                          (000 eq. 3)
    r_UUV = -u_USV sin(phi) / L                     (000 eq. 4)
    phi'  = r_UUV - r_USV = -u_USV sin(phi)/L - r_USV   (000 eq. 6-7; the printed (7) lost the minus)

and the UUV sits a cable length behind the USV along its own heading,
``p_UUV = p_USV - L (cos psi_UUV, sin psi_UUV)`` (NED), which is consistent with (3)-(4): the
UUV then moves along its heading at u_USV cos(phi) with no sideslip. Eq. 2's rotation matrix is the
standard planar one (the printed second row has a sign misprint).

The plant integrates the UUV heading ``psi_UUV' = -u_USV sin(psi_UUV - psi_USV) / L`` (the same
equation as (7), but without the Dirac that a jump of psi_USV would put into r_USV), reading the
USV's ``u``, ``psi`` from the bus, and publishes the UUV's position, heading, speed and phi.

The heading equation has one home, :func:`trailer_heading_rate`; the plant's right-hand side, the
offline :func:`simulate_trailer`, :func:`trailer_rates` and the planner's inverse
(:func:`trailer_offset_for`, used by :mod:`oceangnc.guidance.towed_planning`) all call it.
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit

from ..core.blocks import Plant
from ..core.fused import PlantForm, rk4_stepper_imports
from ..core.csmath import csin
from ..core.model import Model, Param, ParamLayout

LAYOUT = ParamLayout([Param("L", "m", description="cable length")])
(_L,) = LAYOUT.indices("L")
STATES = (("psi", "rad"),)
INPUTS = (("u_usv", "m/s"), ("psi_usv", "rad"), ("r_usv", "rad/s"), ("t_ref", "s"))


@njit(cache=True)
def trailer_heading_rate(u_usv, phi, L):
    """r_UUV = psi_UUV' = -u_USV sin(phi) / L (000 eq. 4), phi = psi_UUV - psi_USV (rad), L (m): rad/s."""
    return -u_usv * csin(phi) / L


def trailer_offset_for(u_uuv, r_uuv, L):
    """The inverse of eq. 3-4 (000 eq. 32-34): the offset phi (rad) at which a UUV moving at u_UUV (m/s)
    turns at r_UUV (rad/s): with u_USV = u_UUV / cos(phi), r_UUV = -u_UUV tan(phi) / L, so
    phi = atan(-L r_UUV / u_UUV) (arrays or floats)."""
    return np.arctan(-L * np.asarray(r_uuv, dtype=float) / np.asarray(u_uuv, dtype=float))


@njit(cache=True)
def trailer_rates(u_usv, r_usv, phi, L):
    """(u_UUV, r_UUV, phi') from the USV's surge speed (m/s), yaw rate (rad/s), phi (rad), L (m); 000 eq. 3-7."""
    r_uuv = trailer_heading_rate(u_usv, phi, L)
    return u_usv * math.cos(phi), r_uuv, r_uuv - r_usv


@njit(cache=True)
def trailer_rhs(t, x, u, p, out):
    """d psi_UUV/dt; x = [psi_UUV], u = [u_USV (m/s), psi_USV (rad), r_USV (rad/s), t_ref (s)], p = [L (m)].

    The USV heading inside the step is ``psi_USV + r_USV (t - t_ref)`` (first-order hold about the
    sample time t_ref), which removes the lag a plain zero-order hold of the heading would add.
    """
    out[0] = trailer_heading_rate(u[0], x[0] - u[1] - u[2] * (t - u[3]), p[_L])


def trailer_model(L: float) -> Model:
    """The trailer heading (000 eq. 4-7) as a :class:`~oceangnc.core.model.Model`."""
    return Model("towed-trailer", trailer_rhs, STATES, INPUTS, LAYOUT, LAYOUT.pack({"L": L}))


@njit(cache=True)
def _interp(tq, t, y):
    n = t.size
    if tq <= t[0]:
        return y[0]
    if tq >= t[n - 1]:
        return y[n - 1]
    lo = 0
    hi = n - 1
    while hi - lo > 1:
        mid = (lo + hi) // 2
        if t[mid] <= tq:
            lo = mid
        else:
            hi = mid
    w = (tq - t[lo]) / (t[hi] - t[lo])
    return y[lo] + w * (y[hi] - y[lo])


@njit(cache=True)
def simulate_trailer(t, u_usv, psi_usv, L, psi_uuv0, substeps):
    """UUV heading history (rad) driven by a sampled USV motion (RK4, inputs linearly interpolated).

    ``psi_usv`` must be unwrapped (continuous, jumps allowed). Returns psi_UUV at the times ``t``.
    """
    n = t.size
    out = np.empty(n)
    x = psi_uuv0
    out[0] = x
    for k in range(n - 1):
        h = (t[k + 1] - t[k]) / substeps
        tk = t[k]
        for s in range(substeps):
            ta = tk + s * h
            tb = ta + 0.5 * h
            tc = ta + h
            ua, pa = _interp(ta, t, u_usv), _interp(ta, t, psi_usv)
            ub, pb = _interp(tb, t, u_usv), _interp(tb, t, psi_usv)
            uc, pc = _interp(tc, t, u_usv), _interp(tc, t, psi_usv)
            k1 = trailer_heading_rate(ua, x - pa, L)
            k2 = trailer_heading_rate(ub, x + 0.5 * h * k1 - pb, L)
            k3 = trailer_heading_rate(ub, x + 0.5 * h * k2 - pb, L)
            k4 = trailer_heading_rate(uc, x + h * k3 - pc, L)
            x += h / 6.0 * (k1 + 2 * k2 + 2 * k3 + k4)
        out[k + 1] = x
    return out


def uuv_position(x_usv, y_usv, psi_uuv, L):
    """UUV position (m, NED) a cable length behind the USV along the UUV heading (arrays or floats)."""
    return x_usv - L * np.cos(psi_uuv), y_usv - L * np.sin(psi_uuv)


@njit(cache=True)
def trailer_read(x, u, sig, islots):
    """The trailer's inputs (:class:`TowedTrailer`, both paths): islots usv.u, usv.psi, usv.r."""
    u[0] = sig[islots[0]]
    psi = sig[islots[1]]
    u[1] = x[0] + ((psi - x[0] + math.pi) % (2 * math.pi) - math.pi)
    u[2] = sig[islots[2]]


@njit(cache=True)
def trailer_publish(x, sig, slots, L):
    """The trailer's outputs (:class:`TowedTrailer`, both paths).

    slots: usv.x, usv.y, usv.u, usv.r, usv.psi | uuv.x, uuv.y, uuv.psi, uuv.u, uuv.r, uuv.phi.
    """
    psi = x[0]
    xs = sig[slots[0]]
    ys = sig[slots[1]]
    us = sig[slots[2]]
    rs = sig[slots[3]]
    phi = (psi - sig[slots[4]] + math.pi) % (2 * math.pi) - math.pi
    uu, ru, _ = trailer_rates(us, rs, phi, L)
    sig[slots[5]] = xs - L * math.cos(psi)
    sig[slots[6]] = ys - L * math.sin(psi)
    sig[slots[7]] = (psi + math.pi) % (2 * math.pi) - math.pi
    sig[slots[8]] = uu
    sig[slots[9]] = ru
    sig[slots[10]] = phi


class TowedTrailer(Plant):
    """The towed UUV as a trailer plant (000 eq. 2-7).

    State ``[psi]`` (UUV heading, rad, unwrapped); inputs ``<usv>.u`` (m/s), ``<usv>.psi`` (rad,
    unwrapped here next to the UUV heading) and ``<usv>.r`` (rad/s), read after the USV plant has
    advanced (list this plant after the USV) and held to first order over the interval. Publishes
    ``uuv.x``, ``uuv.y`` (m), ``uuv.psi`` (wrapped), ``uuv.u`` (m/s), ``uuv.r`` (rad/s) and ``uuv.phi``
    (psi_UUV - psi_USV, rad, wrapped). The USV must be published on the bus before this plant
    (list it after the USV plant).
    """

    def __init__(self, cable_length: float, psi0: float = 0.0, name: str = "uuv", usv: str = "usv"):
        if not cable_length > 0:
            raise ValueError(f"cable length must be > 0 m, got {cable_length}")
        self.usv = usv
        self.L = float(cable_length)
        #: what the publish law reads (the USV's) and writes (the UUV's), in its slot order
        self._io_keys = [f"{usv}.{k}" for k in ("x", "y", "u", "r", "psi")] + [
            f"{name}.{k}" for k in ("x", "y", "psi", "u", "r", "phi")
        ]
        super().__init__(
            **trailer_model(self.L).plant_args(
                name, np.array([psi0]), [f"{usv}.u", f"{usv}.psi", f"{usv}.r", "_t_ref"], declare=True
            ),
            outputs={
                f"{name}.{k}": u
                for k, u in (("x", "m"), ("y", "m"), ("psi", "rad"), ("u", "m/s"), ("r", "rad/s"), ("phi", "rad"))
            },
        )

    def compiled_form(self, slot_of):
        """The fused loop's form: :func:`trailer_read`, the RK4 stepper, :func:`trailer_publish`."""
        s, n = self.usv, self.name
        args = {"x": self.x, "u": self.u, "p": self.p, "w": self.work, "bound": float(self.state_bound)}
        args["islots"] = np.array([slot_of(f"{s}.{k}") for k in ("u", "psi", "r")], dtype=np.int64)
        args["oslots"] = np.array([slot_of(k) for k in self._io_keys], dtype=np.int64)
        args["L"] = float(self.L)
        imports = [*rk4_stepper_imports(self.rhs)]
        for fn, alias in ((trailer_read, "_rd_{adv}"), (trailer_publish, "_pub_{adv}")):
            imports.append(f"from {fn.__module__} import {fn.__name__} as {alias}")
        code = [
            "_rd_{adv}({x}, {u}, sig, {islots})",
            "{u}[3] = t + n * dt",
            "tn = {adv}(t, {x}, {u}, {p}, dt, n, {w}, {bound})",
            "_pub_{adv}({x}, sig, {oslots}, {L})",
        ]
        return PlantForm(imports, args, code)

    def _gather(self, bus: dict, keys) -> np.ndarray:
        return np.array([bus.get(k, 0.0) for k in keys], dtype=np.float64)

    def read_inputs(self, bus: dict) -> None:
        """The USV's surge, heading (unwrapped next to the UUV's) and yaw rate: :func:`trailer_read`."""
        sig = self._gather(bus, [f"{self.usv}.{k}" for k in ("u", "psi", "r")])
        trailer_read(self.x, self.u, sig, np.arange(3, dtype=np.int64))

    def advance(self, t: float, dt: float, n: int) -> float:
        # listed after the USV, this plant reads the USV's state at the END of the interval: hold it
        # to first order backwards in time from there
        self.u[3] = t + n * dt
        return super().advance(t, dt, n)

    def publish(self, bus: dict) -> None:
        """The UUV's position, heading, speeds and cable angle from the USV's: :func:`trailer_publish`."""
        sig = self._gather(bus, self._io_keys)
        trailer_publish(self.x, sig, np.arange(len(self._io_keys), dtype=np.int64), self.L)
        bus.update(zip(self._io_keys[5:], sig[5:].tolist()))
