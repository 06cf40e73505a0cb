"""Saturation by priority: the generalised force asked for is met tier by tier, each tier scaled into
what the thrusters have left after the tiers before it (``control.priority`` of a vehicle file).

With the weighted pseudo-inverse P (n x 6, :func:`oceangnc.control.thrust_allocation.allocation_matrix`)
and tau split into tiers tau = tau_1 + tau_2 + ... (each the DOFs of one tier, the others zero):

    f_0 = 0,    f_k = f_{k-1} + s_k P tau_k,    s_k = max { s in [0, 1] : -rev <= f_{k-1} + s P tau_k <= fwd }

Each tier keeps the direction of its own tau_k and gets the largest share of it the thrusters can still
give; a later tier cannot take thrust from an earlier one. With one tier this is the uniform scaling of
``allocator = "pinv"`` (identical thrusts; tested). Without saturation every s_k = 1 and f = P tau.

Why: with uniform scaling a surge demand past the thrusters' limit scales the pitch and heave forces down
by the same factor, so a ROV translating at full thrust loses the attitude hold that keeps it level (issue
38: the BlueROV2 pitched to -51 deg going astern and climbed out of the water). ArduSub does not mix so:
its ``AP_Motors6DOF::output_armed_stabilizing_vectored_6dof`` (ArduPilot, libraries/AP_Motors) normalises
the roll/pitch/throttle group of the vertical thrusters apart from the yaw/forward/lateral group of the
horizontal ones, so a saturated forward command never reduces the pitch authority; ArduCopter's mixer
likewise gives roll and pitch priority over throttle. The tiers generalise that to a pseudo-inverse
that couples the groups (the horizontal thrusters of the Heavy sit 8.5 cm below the origin and pitch it).
"""

from __future__ import annotations

from numba import njit

#: tier of each DOF when a file gives no ``control.priority``: one tier (uniform scaling)
ONE_TIER = (0.0, 0.0, 0.0, 0.0, 0.0, 0.0)


@njit(cache=True)
def priority_scaled(pa, p0, n, tau, f, t0):
    """Thrusts f (N) for tau (N, N m) by the tiers at ``pa[t0:t0 + 6]`` (tier number of each DOF, 0 first):
    the module docstring's recursion. P (n x 6, row-major) at ``pa[p0:]``, then the n forward and n
    reverse limits."""
    for i in range(n):
        f[i] = 0.0
    last = 0
    for j in range(6):
        last = max(last, int(pa[t0 + j]))
    for k in range(last + 1):
        s = 1.0
        for i in range(n):
            g = 0.0
            for j in range(6):
                if int(pa[t0 + j]) == k:
                    g += pa[p0 + 6 * i + j] * tau[j]
            hi = pa[p0 + 6 * n + i]
            lo = -pa[p0 + 7 * n + i]
            if g > 0.0 and f[i] + s * g > hi:
                s = max(0.0, (hi - f[i]) / g)
            elif g < 0.0 and f[i] + s * g < lo:
                s = max(0.0, (lo - f[i]) / g)
        if s == 0.0:
            continue
        for i in range(n):
            g = 0.0
            for j in range(6):
                if int(pa[t0 + j]) == k:
                    g += pa[p0 + 6 * i + j] * tau[j]
            f[i] += s * g


def tiers(priority: list[list[str]] | None, dofs: tuple[str, ...]) -> tuple[float, ...]:
    """The tier number of each DOF (``dofs`` order) from a file's ``control.priority`` (lists of DOF
    names, first served first; a DOF in no list goes last). None: one tier."""
    if priority is None:
        return ONE_TIER
    out = [float(len(priority))] * 6
    for k, group in enumerate(priority):
        for d in group:
            out[dofs.index(d)] = float(k)
    return tuple(out)
