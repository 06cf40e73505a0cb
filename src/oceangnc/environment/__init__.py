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


class SeaEnvironmentConfig(EnvironmentConfig):
    """Current, wind, seabed and waves of a scenario with the towed cable (issue 29)."""

    waves: WaveConfig = WaveConfig()
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
        return {
            "waves": WaveField.from_config(self.waves, rng),
            "heave": self.tow_point_heave,
            "wave_update_dt": self.waves.update_dt,
        }
