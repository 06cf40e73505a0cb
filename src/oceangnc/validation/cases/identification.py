"""Validation cases of 002: EKF identification of the submarine's vertical-plane coefficients from 5-5 and
10-5 zig-zags (tables 5.2-5.3, figs 5.3-5.4)."""

from __future__ import annotations

from functools import partial

from .. import Case, Measured
from ._common import D002, in_group


def ekf(maneuver, r):
    from ...models.submarine_vertical import COEFF_NAMES

    s, _ = r.run("ekf-zigzag", maneuver=maneuver)
    names = [k for k in COEFF_NAMES if f"{k}.rel_error" in s]
    errs = [100 * abs(s[f"{k}.rel_error"]) for k in names]
    return Measured(
        100 * s["max_rel_error"],
        [("|estimate / true - 1| [%]", list(range(len(names))), errs)],
        [("002: worst published 3.75 % (Zqdot, 10-5)", [names.index("Zqdot") if "Zqdot" in names else 0], [3.75])],
        xlabel="coefficient " + " ".join(f"{i}:{n}" for i, n in enumerate(names)),
        ylabel="%",
        band=False,
        note=f"{s['n_within_3sigma']} of {s['n_estimated']} inside 3 sigma",
    )


def ekf_sigma(maneuver, r):
    s, _ = r.run("ekf-zigzag", maneuver=maneuver)
    return Measured(
        float(s["n_within_3sigma"]),
        xlabel="",
        ylabel="",
        band=False,
        note=f"{s['n_within_3sigma']} of {s['n_estimated']} final estimates within 3 sigma of the truth",
    )


_WORST = ("max", 3.75), "no worse than the paper's worst estimate"
_CONVERGE = (
    "coefficients within 3 sigma at the end",
    "-",
    10.0,
    "the estimates converge to the true values",
    ("min", 10.0),
    "all ten",
)

CASES: list[Case] = in_group(
    "002",
    Case(
        "002-table5.2-5-5",
        "EKF, 5-5 zig-zag, noise-free",
        f"{D002} table 5.2, fig 5.3",
        "largest |estimate/true - 1|",
        "%",
        None,
        "worst published 3.75 % (all ten)",
        *_WORST,
        partial(ekf, "5-5"),
    ),
    Case(
        "002-table5.3-10-5",
        "EKF, 10-5 zig-zag, noise-free",
        f"{D002} table 5.3, fig 5.4",
        "largest |estimate/true - 1|",
        "%",
        None,
        "worst published 3.75 % (Zqdot)",
        *_WORST,
        partial(ekf, "10-5"),
    ),
    Case(
        "002-fig5.3-3sigma-5-5",
        "EKF, 5-5 zig-zag, noise-free",
        f"{D002} fig 5.3",
        *_CONVERGE,
        partial(ekf_sigma, "5-5"),
    ),
    Case(
        "002-fig5.4-3sigma-10-5",
        "EKF, 10-5 zig-zag, noise-free",
        f"{D002} fig 5.4",
        *_CONVERGE,
        partial(ekf_sigma, "10-5"),
    ),
)
