"""Validation cases of the cable: 003 ch. 2.3 statics and the tow (figs 4-2 to 4-5), and the
independent quasi-static solution of :func:`oceangnc.validation.physics.quasi_static_hang`."""

from __future__ import annotations

import math
from functools import partial

from .. import Case, Measured
from ._common import D003, history, in_group, ts


def hang_tension(r):
    from ...models.cable import CableConfig
    from ...models.uuv import UUVConfig

    s, df = r.run("cable-current", **{"environment.current.speed": 0.0})
    cc, uc = CableConfig(**r.section("cable")), UUVConfig(**r.section("uuv"))
    w = cc.weight_per_length * cc.length + (uc.weight - uc.buoyancy)
    return history(
        s["cable.top_tension_N"],
        [ts(df, "cable.top_tension", label="top tension")],
        "tension [N]",
        published=w,
        note=f"submerged weight of cable + UUV = {w:.2f} N (W - B of the UUV + w_c L)",
    )


# the column plotted for each summary key of the quasi-static cases (None: no time history)
_QUASI_SERIES = {
    "cable.top_tension_N": ("cable.top_tension", 1.0, "lumped model: top tension"),
    "cable.angle_deg": None,
    "uuv.pitch_deg": ("uuv.theta", 180 / math.pi, "lumped model: UUV pitch"),
}


def quasi(key, qkey, current, r):
    from ..physics import quasi_static_hang

    s, df = r.run("cable-current", **{"environment.current.speed": current})
    ref = quasi_static_hang(current, math.radians(s["uuv.pitch_deg"]), r.section("uuv"), r.section("cable"))
    col = _QUASI_SERIES[key]
    series = [] if col is None else [ts(df, *col)]
    return history(
        s[key],
        series,
        key,
        published=ref[qkey],
        band=bool(series),
        note=f"continuous quasi-static solution: top {ref['top_tension_N']:.2f} N, bottom "
        f"{ref['bottom_tension_N']:.2f} N, angle {ref['angle_deg']:.2f} deg, pitch {ref['pitch_deg']:.2f} deg",
    )


def tow(speed, r) -> Measured:
    s, df = r.run("tow-straight", **{"command.uuv_speed": speed, "sim.duration": 60.0})
    return history(
        s["uuv.depth_change_max_m"],
        [ts(df, "uuv.z", label=f"UUV depth, UUV at {speed} m/s")],
        "depth [m]",
        band=False,
        note=f"depth start {s['uuv.depth_start_m']:.3f} m, final {s['uuv.depth_final_m']:.3f} m, "
        f"cable angle {s['cable.angle_final_deg']:.1f} deg",
    )


_IN_CURRENT = "UUV on the cable in a 0.5 m/s current"
_QUASI_SOURCE = "independent quasi-static solution"
_COMPUTED = "analytic (computed)"

CASES: list[Case] = [
    *in_group(
        "cable",
        Case(
            "003-ch2.3-hanging-tension",
            "cable + UUV hanging in still water",
            f"{D003} eq. 2.22, 2.26, table 2-6 (statics: top tension = submerged weight)",
            "top tension",
            "N",
            None,
            "w_c L + (W - B)",
            ("rel", 0.01),
            "statics is exact; 1 % covers the settling residual after 60 s",
            hang_tension,
            kind="law",
            basis="statics: the top tension carries the submerged weight",
        ),
    ),
    *in_group(
        "physics",
        Case(
            "physics-cable-statics-tension",
            _IN_CURRENT,
            "independent continuous quasi-static solution (shooting on the pitch balance + catenary-with-drag ODE)",
            "top tension",
            "N",
            None,
            _COMPUTED,
            ("rel", 0.05),
            "lumped 20 segments vs continuous cable: discretisation of the drag (measured agreement 5 digits)",
            partial(quasi, "cable.top_tension_N", "top_tension_N", 0.5),
            kind="analytic",
        ),
        Case(
            "physics-cable-statics-angle",
            _IN_CURRENT,
            _QUASI_SOURCE,
            "cable angle from vertical",
            "deg",
            None,
            _COMPUTED,
            ("abs", 2.0),
            "as above; 2 deg is the tank-test resolution of 003 (0.23-1.3 deg)",
            partial(quasi, "cable.angle_deg", "angle_deg", 0.5),
            kind="analytic",
        ),
        Case(
            "physics-cable-statics-pitch",
            _IN_CURRENT,
            _QUASI_SOURCE,
            "UUV pitch",
            "deg",
            None,
            _COMPUTED,
            ("abs", 2.0),
            "as above",
            partial(quasi, "uuv.pitch_deg", "pitch_deg", 0.5),
            kind="analytic",
        ),
    ),
    *in_group(
        "cable",
        Case(
            "003-fig4-2-tow-slow",
            "tow at 0.5 m/s, UUV at 0.27 m/s",
            f"{D003} figs 4-2, 4-3",
            "largest depth change",
            "m",
            None,
            "'large' depth change",
            ("min", 0.3),
            "the text says 'large' only: at least 10 % of the 3 m depth",
            partial(tow, 0.27),
            kind="prediction",
            qualitative=True,
        ),
        Case(
            "003-fig4-4-tow-matched",
            "tow at 0.5 m/s, UUV at 0.48 m/s",
            f"{D003} figs 4-4, 4-5",
            "largest depth change",
            "m",
            None,
            "'small' depth change",
            ("max", 0.1),
            "the text says 'small' only: under 0.1 m (3 %)",
            partial(tow, 0.48),
            kind="prediction",
            qualitative=True,
        ),
    ),
]
