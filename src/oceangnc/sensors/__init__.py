"""Sensors of the combined vehicle (003 ch. 6.1, appendix B): GPS, AHRS, USBL, depth; and filters.

Each sensor is a :class:`~oceangnc.core.law.LawBlock` whose one compiled law (in the sensor's own module)
draws its noise from the block's own generator, on the Python clock and in the fused loop alike.
"""

from .ahrs import AHRS, AHRSConfig
from .depth import DepthSensor, DepthSensorConfig
from .filters import AngleLowPass, DropoutHold, LowPass
from .gps import GPS, GPSConfig
from .usbl import USBL, USBLConfig

__all__ = [
    "AHRS",
    "AHRSConfig",
    "DepthSensor",
    "DepthSensorConfig",
    "AngleLowPass",
    "DropoutHold",
    "LowPass",
    "GPS",
    "GPSConfig",
    "USBL",
    "USBLConfig",
]
