"""Validation cases of the vehicles defined by a file (issue 30; :mod:`oceangnc.models.vehicle`).

Each says what kind of evidence it is. The Otter's top speed is a calibration target (its linear surge
damping is defined from it); the 003 UUV's file against the dedicated model is a round trip of the
form. The Otter's turning circle and the BlueROV2's steady speeds are analytic checks: the simulation
against the steady state of the published coefficients, solved independently at run time (the
turning circle by Newton on the equations of motion, the ROV's speeds in closed form).

The Otter's comparisons with Fossen's own program (class reference implementation) are in
:mod:`.otter_pvs`. Its speed at half thrust is an analytic check: surge is linear, so half of the calibrated
full thrust gives half of U_max (the closed form of its own coefficients: code verification). The BlueROV2's steady forward speed at full thrust is a prediction against the
manufacturer's rated speed. No published *measured* turning circle of the Otter nor numeric step
response of the BlueROV2 benchmark could be found and read (each case's note says so); none is invented.
"""

from __future__ import annotations

import numpy as np

from .. import Case
from ._common import history, in_group, plan

FOSSEN_OTTER = "Fossen (2021), Handbook of Marine Craft Hydrodynamics and Motion Control, 2nd ed.: the Otter USV model"
BENZON = (
    "von Benzon, Sorensen, Uth, Jouffroy, Liniger & Pedersen (2022), An Open-Source Benchmark Simulator: Control "
    "of a BlueROV2 Underwater Robot, J. Mar. Sci. Eng. 10(12) 1898, hydrodynamic parameter table (from Wu 2018)"
)
#: the Otter's turning trial: left propeller at full forward thrust (0.5 x 24.4 kgf), right stopped
OTTER_TURN_N = (119.682, 0.0)
#: the Otter's half-thrust trial: each propeller at half its full thrust (shaft speed n_max / sqrt 2)
OTTER_HALF_N = (59.841, 59.841)
#: the BlueROV2's trials: a pure yaw moment through its allocation, and its 4 vertical thrusters at full
ROV_YAW_NM = 1.0
BLUE_SPEC = (
    "Blue Robotics, BlueROV2 specifications (undated page, 2-D drawing of 2018), 'Performance' table: maximum "
    "forward speed 1 m/s (2 knots), for the standard 6-thruster vehicle (bluerobotics.github.io "
    "brov2/specifications.md at commit 010fce3d4c773d9905404d9e13e679cc79d67f4a); the Heavy has the same 4 "
    "vectored horizontal thrusters"
)
_NO_OTTER_TURN = (
    "no published turning circle of the Otter was found: neither Fossen (2021) nor the otter.py / otter.m "
    "documentation of his MSS and Python Vehicle Simulator print a diameter for stated thrusts; the value is "
    "this model's, checked against its own steady turn, for comparison when one is published"
)
_NO_ROV_STEP = (
    "no numeric step response of the benchmark could be read: its validation against test-facility data is "
    "shown as plotted curves, which we could not access beyond the article's abstract; this case checks the "
    "published coefficients through the simulation (thruster geometry, allocation, coupling), not the vehicle"
)


def _otter(r):
    """The Otter's file as a model, with the runner's ``otter.<parameter>`` overrides (``otter.D_Q[1]``)."""
    from ...models.vehicle import vehicle_model

    return vehicle_model("otter").with_params(**r.section("otter"))


def otter_top_speed(r):
    """Steady surge speed (m/s) of the Otter's file at full forward thrust on both propellers."""
    m = _otter(r)
    t = np.arange(0.0, 120.0, 0.1)
    fwd = m.p[m.layout.index("left.max_forward")]
    U = np.zeros((t.size, m.nu))
    U[:, :2] = fwd
    X = m.simulate(t, U, np.zeros(m.nx), substeps=5)
    return history(float(X[-1, 6]), [("Otter, both propellers at full thrust", t, X[:, 6])], "u [m/s]")


def uuv003_form(r):
    """Largest relative difference of the 12 states between the 003 UUV's file and its dedicated model."""
    from ...models.uuv import uuv_model
    from ...models.vehicle import vehicle_model

    ref, gen = uuv_model(), vehicle_model("uuv-003")
    t = np.linspace(0.0, 30.0, 301)
    U = np.tile([40.0, 10.0, 5.0, 0.2, -0.1], (t.size, 1))
    x0 = np.zeros(12)
    x0[2], x0[6] = 3.0, 0.5
    a = ref.simulate(t, U, x0, substeps=20)
    b = gen.simulate(t, U, np.r_[x0, np.zeros(3)], substeps=20)[:, :12]
    err = np.max(np.abs(a - b) / np.maximum(np.abs(a).max(axis=0), 1e-3), axis=1)
    return history(float(err.max()), [("max relative state difference", t, np.maximum(err, 1e-18))], "difference")


def _otter_turn(r):
    """The Otter's file with the left propeller full and the right stopped for 200 s from rest: (model, states
    every 0.05 s, diameter of the track after 150 s, m)."""
    m = _otter(r)
    t = np.arange(0.0, 200.0, 0.05)
    U = np.zeros((t.size, m.nu))
    U[:, :2] = OTTER_TURN_N
    X = m.simulate(t, U, np.zeros(m.nx), substeps=5)
    late = t > 150.0
    return m, X, float(0.5 * (np.ptp(X[late, 0]) + np.ptp(X[late, 1])))


def otter_turning_circle(r):
    """Steady turning-circle diameter (m) of the Otter's file, left propeller full, right stopped: the
    simulated track after 150 s against 2 U / r of the steady turn solved by Newton on the equations of
    motion (:func:`oceangnc.core.linearize.trim`: u, v, w, p, q, r, heave, roll, pitch, thrusts free)."""
    from ...core.linearize import trim

    m, X, d_track = _otter_turn(r)
    x0 = np.zeros(m.nx)
    x0[6], x0[11] = 1.0, 0.2  # a guess: 1 m/s, 0.2 rad/s
    free = ("u", "v", "w", "p", "q", "r", "z", "phi", "theta", "shaft_left", "shaft_right")
    tr = trim(m, x0, np.r_[OTTER_TURN_N, 0.0, 0.0], free=free, zero=free)
    u, v, rr = tr.x[6], tr.x[7], tr.x[11]
    d_trim = 2.0 * float(np.hypot(u, v)) / abs(float(rr))
    note = f"steady turn: u = {u:.3f} m/s, v = {v:.3f} m/s, r = {np.degrees(rr):.2f} deg/s; {_NO_OTTER_TURN}"
    return plan(float(d_track), [("Otter, left full, right stopped", X[:, 1], X[:, 0])], published=d_trim, note=note)


def otter_speed_fossen(r):
    """Steady surge speed (m/s) of the Otter's file with both propellers at half thrust (59.841 N each), against
    the closed form 2 x 59.841 N / X_u of its own linear surge damping (surge is linear: no other surge force)."""
    m = _otter(r)
    t = np.arange(0.0, 120.0, 0.1)
    U = np.zeros((t.size, m.nu))
    U[:, :2] = OTTER_HALF_N
    X = m.simulate(t, U, np.zeros(m.nx), substeps=5)
    ref = sum(OTTER_HALF_N) / m.p[m.layout.index("D_L")]
    note = f"pitch {np.degrees(X[-1, 4]):.2f} deg; closed form {ref:.4f} m/s = 2 x 59.841 N / X_u"
    return history(
        float(X[-1, 6]),
        [("Otter file, both propellers at half thrust", t, X[:, 6])],
        "u [m/s]",
        published=ref,
        note=note,
    )


def _rov_steady(tau_or_thrusts, col, t_end=30.0):
    from ...control.thrust_allocation import allocation_matrix
    from ...models.vehicle import load_vehicle, vehicle_model

    vf = load_vehicle("bluerov2-heavy")
    m = vehicle_model(vf)
    n = len(vf.thrusters)
    f = allocation_matrix(vf) @ tau_or_thrusts if len(tau_or_thrusts) == 6 else np.asarray(tau_or_thrusts)
    t = np.arange(0.0, t_end, 0.01)
    U = np.zeros((t.size, m.nu))
    U[:, :n] = f
    X = m.simulate(t, U, np.zeros(m.nx), substeps=2)
    return vf, t, X[:, col], f


def _quadratic_speed(d_l, d_q, force):
    """Steady speed of d_l v + d_q v |v| = force (force >= 0), the positive root."""
    return (-d_l + np.sqrt(d_l * d_l + 4.0 * d_q * force)) / (2.0 * d_q)


def rov_yaw_rate(r):
    """Steady yaw rate (rad/s) of the BlueROV2 file under a pure yaw moment of ROV_YAW_NM through its
    allocation, against the closed form of its published yaw damping (N_r = 0, N_r|r| = 1.5 kg m^2)."""
    vf, t, rr, f = _rov_steady(np.r_[0.0, 0.0, 0.0, 0.0, 0.0, ROV_YAW_NM], 11)
    ref = _quadratic_speed(vf.damping.linear[5], vf.damping.quadratic[5], ROV_YAW_NM)
    note = f"thrusts {', '.join(f'{x:.2f}' for x in f)} N (all within their limits); {_NO_ROV_STEP}"
    return history(float(rr[-1]), [("BlueROV2 Heavy, 1 N m yaw", t, rr)], "r [rad/s]", published=ref, note=note)


def rov_forward_speed(r):
    """Steady surge speed (m/s) of the BlueROV2 file with its 4 horizontal thrusters at full forward thrust
    (the largest pure surge force the allocation gives, 4 x 51.48 N x cos 45 deg = 145.6 N), attitude held as
    the pilot's STABILIZE mode does: open loop the benchmark's model diverges in pitch within a second at
    1 m/s (the Munk moment (Z_wdot - X_udot) u w against W BG = 1.3 N m, docs/vehicles.md), so a PD on roll,
    pitch, yaw rate and heave rate is added to the surge force through the allocation (RK4, 0.01 s)."""
    from ...control.thrust_allocation import allocation_matrix
    from ...models.vehicle import load_vehicle

    vf = load_vehicle("bluerov2-heavy")
    m = vehicle_model_with(vf, r.section("bluerov2-heavy"))
    n = len(vf.thrusters)
    A = allocation_matrix(vf)
    hi = np.array([t.max_forward for t in vf.thrusters])
    lo = -np.array([t.max_reverse for t in vf.thrusters])
    horizontal = [i for i, t in enumerate(vf.thrusters) if abs(t.direction[2]) < 0.5]
    force = sum(
        hi[i] * abs(vf.thrusters[i].direction[0]) / np.linalg.norm(vf.thrusters[i].direction) for i in horizontal
    )
    dt, x, u_in = 0.01, np.zeros(m.nx), np.zeros(m.nu)
    t = np.arange(1, 501) * dt
    X = np.empty((t.size, m.nx))
    for k in range(t.size):
        phi, th, w, p, q, rr = x[3], x[4], x[8], x[9], x[10], x[11]
        tau = np.array([force, 0.0, -40.0 * w, -20.0 * phi - 5.0 * p, -20.0 * th - 5.0 * q, -5.0 * rr])
        u_in[:n] = np.clip(A @ tau, lo, hi)
        k1 = m.deriv(x, u_in)
        k2 = m.deriv(x + 0.5 * dt * k1, u_in)
        k3 = m.deriv(x + 0.5 * dt * k2, u_in)
        k4 = m.deriv(x + dt * k3, u_in)
        x = x + dt / 6.0 * (k1 + 2.0 * k2 + 2.0 * k3 + k4)
        X[k] = x
    d_l, d_q = m.p[m.layout.index("D_L[0]")], m.p[m.layout.index("D_Q[0]")]
    note = (
        f"surge force {force:.1f} N (T200 at 16 V, 5.25 kgf each); pitch held at {np.degrees(X[-1, 4]):.2f} deg; "
        f"closed form of the damping {_quadratic_speed(d_l, d_q, force):.4f} m/s; at the 9 kgf forward bollard "
        f"thrust the same page prints, {_quadratic_speed(d_l, d_q, 9.0 * 9.80665):.3f} m/s"
    )
    return history(float(X[-1, 6]), [("BlueROV2 Heavy, full forward, attitude held", t, X[:, 6])], "u [m/s]", note=note)


def vehicle_model_with(vf, overrides):
    """The vehicle file's model with parameters changed by name (the runner's ``<vehicle>.<param>`` keys)."""
    from ...models.vehicle import vehicle_model

    return vehicle_model(vf).with_params(**overrides)


def rov_heave_speed(r):
    """Steady heave speed (m/s) of the BlueROV2 file, its 4 vertical thrusters at full forward thrust
    (down), against the closed form of its published heave damping with its net weight W - B."""
    from ...models.vehicle import load_vehicle
    from ...units import G

    full = [t.max_forward if t.direction[2] > 0.5 else 0.0 for t in load_vehicle("bluerov2-heavy").thrusters]
    vf, t, w, f = _rov_steady(full, 8)
    h = vf.hydrostatics
    force = sum(full) + vf.rigid_body.mass * G - h.rho * G * h.volume
    ref = _quadratic_speed(vf.damping.linear[2], vf.damping.quadratic[2], force)
    return history(
        float(w[-1]), [("BlueROV2 Heavy, vertical thrusters full", t, w)], "w [m/s]", published=ref, note=_NO_ROV_STEP
    )


CASES: list[Case] = in_group(
    "vehicles of a file",
    Case(
        "vehicle-otter-top-speed",
        "Otter USV (file otter.toml), both propellers at full forward thrust",
        FOSSEN_OTTER,
        "steady surge speed",
        "m/s",
        6 * 0.5144,
        "U_max = 6 knots",
        ("rel", 0.01),
        "the linear surge damping is defined so that full thrust gives U_max: only the generic form's "
        "surge balance (thrust limits, saturation, lag) is checked",
        otter_top_speed,
        kind="calibration",
        basis="D_L[0] = 24.4 g / U_max (Fossen's X_u for the Otter)",
    ),
    Case(
        "vehicle-uuv003-generic-form",
        "003 UUV as a vehicle file against its dedicated model, turning with a bow thrust in a current",
        "003_486f48bcab6eec1d.txt ch. 2.2, appendix A",
        "largest relative state difference over 30 s",
        "1",
        0.0,
        "the same model",
        ("abs", 1e-9),
        "the same numbers summed in another order: rounding only",
        uuv003_form,
        kind="round-trip",
        basis="oceangnc.models.uuv (the dedicated 003 model) wrote the file's numbers",
    ),
    Case(
        "vehicle-otter-turning-circle",
        "Otter USV (file otter.toml), left propeller at full forward thrust (119.7 N), right stopped",
        f"{FOSSEN_OTTER}; steady turn solved by Newton on the same equations at run time",
        "steady turning-circle diameter",
        "m",
        None,
        "2 U / r of the steady turn (computed)",
        ("rel", 0.01),
        "the simulated track after 150 s is the steady circle; 1 % for the 20 s of track read",
        otter_turning_circle,
        kind="analytic",
        basis="trim of the file's equations of motion: the published coefficients, no fitted value",
    ),
    Case(
        "vehicle-bluerov2-yaw-rate",
        "BlueROV2 Heavy (file bluerov2-heavy.toml), a pure 1 N m yaw moment through its allocation",
        BENZON,
        "steady yaw rate",
        "rad/s",
        None,
        "root of 0 r + 1.5 r|r| = 1 N m (computed)",
        ("rel", 0.001),
        "the allocation cancels every other force and moment, so yaw decouples; 0.1 % for the 30 s transient",
        rov_yaw_rate,
        kind="analytic",
        basis="closed form of the published quadratic yaw damping",
    ),
    Case(
        "vehicle-bluerov2-heave-speed",
        "BlueROV2 Heavy, its 4 vertical thrusters at full forward thrust (4 x 5.25 kgf, down)",
        BENZON,
        "steady heave speed",
        "m/s",
        None,
        "root of 33 w + 190 w|w| = 4 x 51.48 N + W - B (computed)",
        ("rel", 0.001),
        "the thrusters are symmetric about CO: no moment, heave decouples",
        rov_heave_speed,
        kind="analytic",
        basis="closed form of the published heave damping, weight and volume",
    ),
    Case(
        "vehicle-otter-speed-fossen",
        "Otter USV (file otter.toml), both propellers at half thrust (59.84 N each, n = n_max / sqrt 2)",
        f"{FOSSEN_OTTER}; the surge law X_u u = thrust, X_u = 24.4 g / U_max",
        "steady surge speed",
        "m/s",
        None,
        "2 x 59.84 N / X_u = U_max / 2 (computed)",
        ("rel", 0.005),
        "surge is linear and decoupled in straight running: the simulated speed is the closed form to the "
        "transient left after 120 s",
        otter_speed_fossen,
        kind="analytic",
        basis="re-classed from prediction (issue 38): half of the calibrated full thrust gives half of the "
        "calibrated top speed, a closed form of the file's own coefficients (code verification); the comparison "
        "with Fossen's program is vehicle-otter-pvs-*",
    ),
    Case(
        "vehicle-bluerov2-rated-speed",
        "BlueROV2 Heavy (file bluerov2-heavy.toml), 4 horizontal thrusters at full forward thrust, attitude held",
        f"{BLUE_SPEC}; the model: {BENZON}",
        "steady forward speed",
        "m/s",
        1.0,
        "1 m/s (2 knots), the manufacturer's rating",
        ("range", 0.77, 1.29),
        "the rating is given in whole knots: 2 knots covers 1.5 … 2.5 knots = 0.77 … 1.29 m/s",
        rov_forward_speed,
        kind="prediction",
        basis="Wu's (2018) surge damping from tank tests and the T200 data sheet's thrust; nothing fitted to the rating",
    ),
)
