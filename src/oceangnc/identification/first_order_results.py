"""Results of the first-order identification (:mod:`oceangnc.identification.first_order`): the log's
column names, one step trial's fit, a coefficient's line against speed, a zig-zag's fit, and the report."""

from __future__ import annotations

from dataclasses import asdict, dataclass, field


@dataclass
class Columns:
    """Log column names of the signals (CLI options --time --steer --thrust --speed --heading --yaw-rate --trial)."""

    time: str = "t"
    steer: str = "trial.steer"
    thrust: str = "trial.thrust"
    speed: str = "trial.speed"
    heading: str = "trial.heading"
    yaw_rate: str = "trial.yaw_rate"
    trial: str | None = "trial.id"
    kind: str | None = "trial.kind"


@dataclass
class StepFit:
    """Result of the integral method on one step trial (units: those of the log's columns)."""

    trial: int
    kind: str
    speed: float  # mean speed over the last part of the steady interval, m/s
    K: float
    T: float
    K_std: float
    T_std: float
    t1: float
    t2: float
    t3: float
    noise_std: float  # estimated output noise (y units)
    checks: dict = field(default_factory=dict)  # first_order_checks: bound, condition, fit, whiteness


@dataclass
class LinearFit:
    """``value = slope * u + intercept`` fitted over trials (000 table 2)."""

    name: str
    slope: float
    intercept: float
    slope_std: float
    intercept_std: float
    residual_rms: float
    residuals: list
    speeds: list
    n: int


@dataclass
class ZigzagFit:
    """Least-squares Nomoto fit of a zig-zag trial."""

    trial: int
    speed: float
    amplitude_deg: float  # heading change at the rudder reversals, deg (10 for a 10/10 zig-zag)
    rudder: float  # rudder amplitude, steer units (rad for an angle)
    K: float
    T: float
    K_std: float
    T_std: float
    heading_rms_deg: float
    checks: dict = field(default_factory=dict)  # first_order_checks: bound, condition, fit, whiteness


@dataclass
class Report:
    """Everything an identification run found."""

    steps: list = field(default_factory=list)
    fits: dict = field(default_factory=dict)
    zigzags: list = field(default_factory=list)
    units: dict = field(default_factory=dict)
    failures: list = field(default_factory=list)  # failed checks (first_order_checks.judge)

    def to_dict(self) -> dict:
        return {
            "units": self.units,
            "failed_checks": self.failures,
            "trials": [asdict(s) for s in self.steps],
            "speed_fits": {k: asdict(v) for k, v in self.fits.items()},
            "zigzag": [asdict(z) for z in self.zigzags],
        }

    def table(self) -> str:
        """Human-readable tables (trials, linear fits, zig-zags) and the units."""
        sections = (
            (self.steps, _STEP_HEADER, _step_row),
            (list(self.fits.items()), _FIT_HEADER, _fit_row),
            (self.zigzags, _ZIGZAG_HEADER, _zigzag_row),
        )
        lines: list[str] = []
        for i, (items, header, row) in enumerate(sections):
            if items:
                lines += ([""] if i else []) + [header] + [row(x) for x in items]
        if self.units:
            lines += ["", "units: " + "; ".join(f"{k} in {v}" for k, v in self.units.items())]
        return "\n".join(lines)


_STEP_HEADER = (
    f"{'trial':>5} {'kind':<8} {'speed':>7} {'K':>11} {'+-K':>9} {'T [s]':>8} {'+-T':>7} {'t1':>7} {'t2':>7} {'t3':>7}"
)
_FIT_HEADER = (
    f"{'coef':<5} {'slope a':>11} {'+-a':>9} {'intercept b':>12} {'+-b':>9} {'res rms':>9} {'n':>3}"
    "   (coef = a u + b, u in m/s)"
)
_ZIGZAG_HEADER = (
    f"{'trial':>5} {'psi amp':>8} {'rudder':>8} {'speed':>7} {'K_r':>9} {'+-K':>8} {'T_r':>8} {'+-T':>8} {'rms psi':>8}"
)


def _step_row(s: StepFit) -> str:
    return (
        f"{s.trial:>5d} {s.kind:<8} {s.speed:7.3f} {s.K:11.5g} {s.K_std:9.2g} {s.T:8.4f} "
        f"{s.T_std:7.2g} {s.t1:7.2f} {s.t2:7.2f} {s.t3:7.2f}"
    )


def _fit_row(item: tuple[str, LinearFit]) -> str:
    k, f = item
    return (
        f"{k:<5} {f.slope:11.5g} {f.slope_std:9.2g} {f.intercept:12.5g} {f.intercept_std:9.2g} "
        f"{f.residual_rms:9.2g} {f.n:3d}"
    )


def _zigzag_row(z: ZigzagFit) -> str:
    return (
        f"{z.trial:>5d} {z.amplitude_deg:7.1f}d {z.rudder:8.4g} {z.speed:7.3f} {z.K:9.5g} "
        f"{z.K_std:8.2g} {z.T:8.4f} {z.T_std:8.2g} {z.heading_rms_deg:7.3f}d"
    )
