"""Environment: ocean current and wind, as discrete blocks publishing NED velocities on the bus."""

from .current import CurrentConfig, OceanCurrent
from .seabed import SeabedConfig
from .wind import Wind, WindConfig, beaufort_speed

__all__ = ["CurrentConfig", "OceanCurrent", "WindConfig", "Wind", "beaufort_speed", "EnvironmentConfig", "SeabedConfig"]

from ..io.config import StrictModel


class EnvironmentConfig(StrictModel):
    """Current, wind and seabed of a scenario."""

    current: CurrentConfig = CurrentConfig()
    wind: WindConfig = WindConfig()
    seabed: SeabedConfig = SeabedConfig()
