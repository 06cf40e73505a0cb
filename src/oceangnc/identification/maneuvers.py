"""Vertical-plane zig-zag maneuvers of document 002 and the measurements they produce.

002 (``002_05c842517d8c1175.txt`` ch. 4-5) drives the heave-pitch model with 5-5 and 10-5 deg stern
plane zig-zags, integrates the truth with RK4 at 1e-4 s and samples w, theta and q every 0.01 s for
200 s. The paper prints neither the switching rule nor the plane history (fig 5.1 is an image), so
we use the vertical-plane analogue of the standard (ITTC/IMO) horizontal zig-zag:

* a zig-zag ``a-b`` puts the stern plane at ``a`` deg and reverses it to the opposite ``a`` deg
  each time the pitch angle has moved ``b`` deg away from zero *in the direction the current
  deflection drives it*. With 002's coefficients (M_ds' < 0) a positive plane pitches the bow down,
  so the first reversal comes at theta = -b, the next at theta = +b, and so on;
* the first deflection is ``+a`` (bow down) after ``t_start_s`` seconds of straight run
  (default 0 s: the run starts from 002 table 4.1's initial state w = 0.028 m/s, theta = q = 0);
* the rule is evaluated at the measurement instants (the plane is commanded by a digital loop at the
  measurement rate) and the plane angle is held constant between them (zero-order hold), optionally
  slewing at ``rate_degps`` per second. So the input the filter reads from the log, held over each
  sample interval, is exactly the input the truth saw; the truth is still integrated at the fine
  step ``dt_truth``.

Measurement noise is white Gaussian, independent per channel, with standard deviations in SI units,
drawn from the ``numpy.random.Generator`` passed in (determinism).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from numba import njit

from ..core.integrators import rk4_advance
from ..errors import ConfigError
from ..models.submarine_vertical import LAYOUT, sub_rhs

MANEUVERS = {"5-5": (5.0, 5.0), "10-5": (10.0, 5.0)}


def parse_maneuver(name: str) -> tuple[float, float]:
    """``"10-5"`` -> (plane angle deg, switching pitch deg); accepts any ``a-b`` with positive numbers."""
    if name in MANEUVERS:
        return MANEUVERS[name]
    try:
        a, b = (float(v) for v in str(name).split("-"))
    except ValueError:
        raise ConfigError(f"maneuver {name!r}: expected 'a-b' (plane deg - pitch deg), e.g. '10-5'") from None
    if not (0 < a <= 30 and 0 < b <= 30):
        raise ConfigError(f"maneuver {name!r}: plane angle and pitch threshold must lie in (0, 30] deg")
    return a, b


@njit(cache=True)
def _zigzag_loop(rhs, x0, p, n_meas, dt_meas, n_fine, ds_amp, th_sw, resp_sign, t_start, rate, X, DS):
    """Integrate the truth, evaluating the zig-zag rule at each of the ``n_meas`` sample instants.

    Writes the state at sample k into ``X[k]`` and the plane angle held over [t_k, t_k+1) into
    ``DS[k]``. Returns the number of plane reversals, or -1 - k if the state became non-finite.
    """
    x = x0.copy()
    u = np.zeros(1)
    work = np.zeros((5, x.size))
    h = dt_meas / n_fine
    sgn = 1.0
    started = False
    ds = 0.0
    n_sw = 0
    t = 0.0
    for k in range(n_meas):
        t = k * dt_meas
        for i in range(x.size):
            X[k, i] = x[i]
        if not started and t >= t_start - 1e-12:
            started = True
        if started:
            # pitch moved th_sw in the direction the current deflection drives it -> reverse
            if resp_sign * sgn * x[1] >= th_sw:
                sgn = -sgn
                n_sw += 1
            target = sgn * ds_amp
            if rate > 0.0:
                step = rate * dt_meas
                if target > ds + step:
                    ds += step
                elif target < ds - step:
                    ds -= step
                else:
                    ds = target
            else:
                ds = target
        DS[k] = ds
        u[0] = ds
        if k < n_meas - 1:
            r = rk4_advance(rhs, t, x, u, p, h, n_fine, work)
            if r < 0.0:
                return -1 - k
    return n_sw


@dataclass
class ManeuverData:
    """A generated maneuver: sample times, the plane history, true and measured states.

    Attributes
    ----------
    t : (N,) s
    ds : (N,) rad, stern plane angle held over [t_k, t_k+1)
    x_true : (N, 4) true [w (m/s), theta (rad), q (rad/s), z (m)]
    z_meas : (N, 3) measured [w, theta, q] (true plus noise)
    noise_std : (3,) the noise standard deviations used (SI)
    n_reversals : int, number of plane reversals
    """

    t: np.ndarray
    ds: np.ndarray
    x_true: np.ndarray
    z_meas: np.ndarray
    noise_std: np.ndarray
    n_reversals: int

    def columns(self, prefix: str = "sub") -> dict[str, np.ndarray]:
        """Log columns: ``<prefix>.w/theta/q`` measured, ``<prefix>.ds``, and ``*_true`` and ``z`` truth."""
        out = {"t": self.t, f"{prefix}.ds": self.ds}
        for i, k in enumerate(("w", "theta", "q")):
            out[f"{prefix}.{k}"] = self.z_meas[:, i]
            out[f"{prefix}.{k}_true"] = self.x_true[:, i]
        out[f"{prefix}.z_true"] = self.x_true[:, 3]
        return out


def zigzag(
    params,
    x0,
    maneuver: str = "10-5",
    duration: float = 200.0,
    rate_hz: float = 100.0,
    dt_truth: float = 1e-4,
    noise_std=(0.0, 0.0, 0.0),
    rng: np.random.Generator | None = None,
    t_start_s: float = 0.0,
    plane_rate_degps: float = 0.0,
    response_sign: float | None = None,
) -> ManeuverData:
    """Simulate a vertical zig-zag of the submarine and sample it (002 ch. 4-5).

    Parameters
    ----------
    params : array
        Model parameters in the layout of :data:`oceangnc.models.submarine_vertical.P_NAMES`.
    x0 : array (4,)
        Initial [w (m/s), theta (rad), q (rad/s), z (m)].
    maneuver : str
        ``"5-5"``, ``"10-5"`` or any ``"a-b"``: plane angle a deg, pitch threshold b deg.
    duration, rate_hz : float
        Record length (s) and measurement rate (Hz); default 200 s at 100 Hz as in 002.
    dt_truth : float
        RK4 step of the truth (s); 002 uses 1e-4 s. Rounded so that it divides the sample interval.
    noise_std : 3 floats
        Standard deviation of the noise on w (m/s), theta (rad), q (rad/s); zeros = noise-free.
    rng : numpy Generator
        Source of the noise (needed if any noise_std > 0).
    t_start_s : float
        Straight run before the first deflection (s).
    plane_rate_degps : float
        Plane slew rate (deg/s); 0 = the plane jumps within one sample interval.
    response_sign : float, optional
        Sign of the pitch response to a positive plane angle; default sign(M_ds'), i.e. -1 for 002.
    """
    a_deg, b_deg = parse_maneuver(maneuver)
    p = np.ascontiguousarray(params, dtype=np.float64)
    if duration <= 0 or rate_hz <= 0 or dt_truth <= 0:
        raise ConfigError("zigzag: duration, rate_hz and dt_truth must be positive")
    dt_meas = 1.0 / rate_hz
    n_fine = max(1, int(round(dt_meas / dt_truth)))
    n_meas = int(round(duration * rate_hz)) + 1
    if response_sign is None:
        mds = p[LAYOUT.index("Mds")]
        response_sign = math.copysign(1.0, mds) if mds != 0 else -1.0
    X = np.zeros((n_meas, 4))
    DS = np.zeros(n_meas)
    n_sw = _zigzag_loop(
        sub_rhs,
        np.asarray(x0, dtype=np.float64),
        p,
        n_meas,
        dt_meas,
        n_fine,
        math.radians(a_deg),
        math.radians(b_deg),
        float(response_sign),
        float(t_start_s),
        math.radians(plane_rate_degps),
        X,
        DS,
    )
    if n_sw < 0:
        raise ConfigError(f"zigzag: the truth model diverged at t={(-1 - n_sw) * dt_meas:.2f} s; check the parameters")
    sd = np.asarray(noise_std, dtype=np.float64)
    Z = X[:, :3].copy()
    if np.any(sd > 0):
        if rng is None:
            raise ConfigError("zigzag: noise requested but no random generator given")
        Z += rng.standard_normal(Z.shape) * sd
    t = np.arange(n_meas) * dt_meas
    return ManeuverData(t=t, ds=DS, x_true=X, z_meas=Z, noise_std=sd, n_reversals=int(n_sw))
