"""The emergency stop's resume ramp: one law for every actuator and controller that has one.

While ``_estop`` is set, thrust is zero. When it clears, thrust does not step back to the command:
it is scaled by a weight w rising linearly from 0 to 1 over :data:`RESUME_RAMP_S` (2 s), whatever
block or front end (console, MAVLink) released the stop. w is 1 in a run without a stop, so such a
run is not affected (1.0 x is exact). A controller that scales its PID outputs by the same w lets its
back-calculation see the ramped output (:func:`oceangnc.control.pid.pid_step`), so its integrator does
not wind up while the thrust comes back (no overshoot after Reset).
"""

from __future__ import annotations

from numba import njit

#: resume ramp after an emergency stop (s): thrust returns from zero to the command over this time
RESUME_RAMP_S = 2.0


@njit(cache=True, inline="always")
def resume_weight(w, stop, period, ramp_s):
    """The ramp weight after one step of ``period`` s: 0 while ``stop``, else w + period / ramp_s
    capped at 1 (1 at once when ``ramp_s`` <= 0)."""
    if stop:
        return 0.0
    if w >= 1.0:
        return 1.0
    return 1.0 if ramp_s <= 0.0 else min(1.0, w + period / ramp_s)
