"""Environment: ocean current and wind, as discrete blocks publishing NED velocities on the bus."""

from .current import CurrentConfig, OceanCurrent
from .seabed import SeabedConfig
from .wind import Wind, WindConfig, beaufort_speed

__all__ = [
    "CurrentConfig",
    "OceanCurrent",
    "WindConfig",
    "Wind",
    "beaufort_speed",
    "EnvironmentConfig",
    "SeabedConfig",
    "SeaEnvironmentConfig",
    "USVMotionsConfig",
    "WaveConfig",
]

from typing import Literal

from pydantic import Field

from ..io.config import StrictModel
from .waves import WaveConfig


class EnvironmentConfig(StrictModel):
    """Current, wind and seabed of a scenario."""

    current: CurrentConfig = CurrentConfig()
    wind: WindConfig = WindConfig()
    seabed: SeabedConfig = SeabedConfig()


class USVMotionsConfig(StrictModel):
    """The USV's wave-frequency motions (issue 29 part B; :mod:`oceangnc.models._usv_waves`)."""

    enabled: bool = Field(
        False,
        description="with waves: the USV heaves, rolls, pitches (and surges, sways, yaws) by Cummins' equation "
        "from its hydrodynamic coefficients, and the cable's attachment point follows it in 6 DOF "
        "(replaces tow_point_heave)",
    )
    file: str | None = Field(
        None, description="coefficient file (oceangnc hydro --save); default: 003's USV, committed with the package"
    )
    drift: bool = Field(False, description="apply the mean wave drift force to the USV's manoeuvring model")
    roll_damping_ratio: float | None = Field(
        None, ge=0, le=1, description="viscous roll damping, fraction of critical (default: the file's, 0.1)"
    )
    manoeuvring_damping: bool = Field(
        True,
        description="apply the manoeuvring model's linear damping d11, d22, d33 to the wave-frequency surge, "
        "sway and yaw too (a linear damping of the total velocity splits over the two time scales)",
    )


class SeaEnvironmentConfig(EnvironmentConfig):
    """Current, wind, seabed and waves of a scenario with the towed cable (issue 29)."""

    waves: WaveConfig = WaveConfig()
    usv_motions: USVMotionsConfig = USVMotionsConfig()
    tow_point_heave: Literal["none", "surface"] = Field(
        "surface",
        description="with waves: the cable's attachment point heaves with the wave elevation at the USV "
        "(a USV much shorter than the waves, heave RAO 1), or stays at its calm-water depth",
    )

    def plant_kwargs(self, seed: int) -> dict:
        """Keyword arguments of :class:`~oceangnc.models.combined.CombinedPlant` for these waves: the wave
        field (components drawn from ``waves.seed``, else from a stream of the scenario's ``seed`` of its
        own, so that the scenario's other draws are unchanged), the top point's heave and the update
        interval of the kinematics; empty in calm water."""
        if self.waves.kind == "none":
            return {}
        import numpy as np

        from .waves import WaveField

        s = self.waves.seed
        rng = np.random.default_rng(s if s is not None else [int(seed), 29])
        kw = {
            "waves": WaveField.from_config(self.waves, rng),
            "heave": self.tow_point_heave,
            "wave_update_dt": self.waves.update_dt,
        }
        if self.usv_motions.enabled:  # the attachment point follows the USV's 6-DOF motion instead
            kw.update(heave="none", usv_motions=self.usv_motions)
        return kw
