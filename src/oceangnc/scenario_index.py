"""Which scenarios exist, in which module, and which have a light plot module (no imports here).

Read at start-up before anything heavy is imported: ``oceangnc list`` prints :data:`SCENARIO_INDEX`
without importing a scenario module, and ``oceangnc run`` decides from :data:`LIGHT_PLOTS` whether to
fork its drawer first thing (:func:`oceangnc.postproc.start_early`). :mod:`oceangnc.scenarios.base`
re-exports both.
"""

from __future__ import annotations

import importlib.util
import pkgutil

DEFAULT_SCENARIO = "combined-survey"  #: the flagship, run by ``oceangnc run`` without a name
FALLBACK_SCENARIO = "usv-turn"  #: the default when the flagship's module is absent

#: name -> (module under oceangnc.scenarios, one-line summary); kept equal to the modules by a test
SCENARIO_INDEX: dict[str, tuple[str, str]] = {
    "autopilot-heading": ("first_order", "Pole-placed heading PD on the first-order USV: 0 -> 100 deg (000 fig. 17)"),
    "autopilot-speed": (
        "first_order",
        "Pole-placed speed P on the first-order USV: 0 -> 5 m/s, steady error of P control (000 fig. 18)",
    ),
    "berthing-channel": (
        "berthing",
        "S-175 container ship through a Z channel with 30 deg bends by joystick (001 figs 6-10)",
    ),
    "berthing-dock": ("berthing", "S-175 container ship: joystick approach and stop alongside a berth (001)"),
    "cable-current": (
        "cable",
        "Cable with fixed top, UUV hanging in a uniform current: equilibrium tension and angle "
        "(003 sec. 2.2.3.3: fig 2-10 of p. 41, figs 2-12/2-13)",
    ),
    "combined-survey": (
        "combined",
        "USV-cable-UUV through (0,0) (10,10) (20,5) at 0.6 m/s; UUV by PID or backstepping (003 figs 4-7..4-15)",
    ),
    "ekf-zigzag": (
        "ekf_zigzag",
        "submarine heave-pitch coefficients by augmented EKF from a 5-5/10-5 zig-zag (002 tables 5.2/5.3)",
    ),
    "field-test": (
        "combined",
        "sea trial of 003 ch. 6.2: (50,0) (50,-50) (0,-50) (0,0) at 1.3 m/s target, PID, sensors on",
    ),
    "tow-straight": (
        "cable",
        "USV tows the UUV straight at 0.5 m/s, UUV at its own speed: depth change (003 figs 4-2 to 4-5)",
    ),
    "tow-sea-state": (
        "sea_state",
        "USV tows the UUV on a 20 m cable along a line in a JONSWAP sea: tension, snap loads, UUV motions",
    ),
    "tow-deploy": ("tow", "USV holding station, UUV lowered by the winch from the surface to 30 m and recovered"),
    "tow-survey-depth": ("tow", "Towing at 1 m/s on a lawnmower over a sloping seabed, 5 m altitude held by the winch"),
    "otter-waypoints": (
        "vehicles",
        "Otter USV (a vehicle file) on an LOS route at 1.5 m/s with speed and heading PIDs",
    ),
    "rov-station-keeping": (
        "vehicles",
        "BlueROV2 Heavy (a vehicle file) holding position and 5 m depth in a 0.2 m/s current",
    ),
    "trials": (
        "trials",
        "Straight/turning/zig-zag trials from a model, logged for 'oceangnc identify first-order' (000 sec. 2.2)",
    ),
    "usv-remote": (
        "usv_remote",
        "USV for the operator console: stick (speed / yaw-rate PIDs) or pure-pursuit waypoint autopilot",
    ),
    "usv-straight": ("usv_open_loop", "USV, 30 kgf on both thrusters: steady speed (003 fig 2-7, ~0.8 m/s)"),
    "usv-turn": ("usv_open_loop", "USV, 30/15 kgf: turning circle (003 fig 2-8, R ~1.75 m, ~16 deg/s)"),
    "usv-turn-current": ("usv_open_loop", "USV turning in a 0.1 m/s current toward 45 deg (003 fig 2-10 of p. 25)"),
    "usv-turn-wind": ("usv_open_loop", "USV turning in 1 m/s wind, direction settable (003 fig 2-9)"),
    "usv-waypoints-7": (
        "first_order",
        "First-order USV through seven waypoints from heading 90 deg, rest; hybrid/LOS guidance (000 fig. 21)",
    ),
    "uuv-profile-plan": (
        "first_order",
        "USV planned from the towed UUV's plan (000 table 3, eq. 32-34), LOS or hybrid guidance (figs. 22-26)",
    ),
    "waypoints-square": (
        "combined",
        "combined vehicle round a 50 m square; UUV on relative angle (+ heading to USV) (003 fig 4-6)",
    ),
}


#: scenario module -> a module with ``plot_jobs(name, df, cfg, out_dir)`` that draws the figures of
#: that module's scenarios from a :class:`~oceangnc.io.frame.Columns` log and a config read by
#: attribute (the scenario's config or a :class:`~oceangnc.io.frame.Plain` of it), importing neither
#: the models nor numba. ``oceangnc run`` forks their drawer first thing, so it imports matplotlib while
#: this process simulates (:func:`oceangnc.postproc.start_early`). Their scenarios have
#: ``frame = "columns"``; tests/test_frame.py checks both and that the figures are the same bytes.
LIGHT_PLOTS: dict[str, str] = {"combined": "oceangnc.scenarios._combined_plots"}


def light_plots(name: str) -> str | None:
    """The light plot module of scenario ``name`` (see :data:`LIGHT_PLOTS`), None if it has none."""
    entry = SCENARIO_INDEX.get(name)
    return LIGHT_PLOTS.get(entry[0]) if entry else None


def scenario_modules() -> list[str]:
    """The scenario modules in the ``oceangnc.scenarios`` package (their names, none imported)."""
    spec = importlib.util.find_spec("oceangnc.scenarios")  # the package's folder, not its code
    path = list(spec.submodule_search_locations or ()) if spec is not None else []
    return sorted(m.name for m in pkgutil.iter_modules(path) if not m.name.startswith("_") and m.name != "base")


def unindexed_modules() -> list[str]:
    """Scenario modules that :data:`SCENARIO_INDEX` does not name (a user's module dropped in the package)."""
    known = {mod for mod, _ in SCENARIO_INDEX.values()}
    return [m for m in scenario_modules() if m not in known]
