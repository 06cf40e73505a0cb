"""Readers of each field-log format -> raw series ``{signal: (t s, values SI)}`` and metadata.

Conventions converted at this edge (and nowhere else):

* ArduPilot (DataFlash and MAVLink): angles in deg or cdeg -> rad; lat/lon in deg or 1e-7 deg ->
  north/east m about the origin (:mod:`oceangnc.io.geo`); speeds in cm/s -> m/s; servo PWM
  about 1500 us with +-400 us full scale -> -1..1 (skid-steer boat: output 1 = left/port throttle,
  output 3 = right/starboard throttle, ArduPilot SERVOn_FUNCTION 73/74).
* PX4 ULog: ``vehicle_local_position`` is already NED (x north, y east, z down, m); attitude
  quaternion (w, x, y, z) -> Euler ZYX; ``actuator_motors.control[0/1]`` (-1..1) left/right.
* ROS 2 (REP 103/105): ``nav_msgs/Odometry`` pose is ENU (x east, y north, z up) with a FLU body:
  north = y, east = x, down = -z, heading psi_NED = pi/2 - yaw_ENU, r_NED = -omega_z(FLU),
  body velocity (u, v) = (vx, -vy); ``sensor_msgs/Imu`` the same; ``sensor_msgs/NavSatFix`` lat/lon deg.
"""

from __future__ import annotations

from ._common import PWM_CENTER, PWM_SPAN, SERVO_LAYOUTS, north_east, pwm, quat_euler, servo_names, truncated
from .ardupilot import read_dataflash, read_tlog
from .csv_log import UNIT_SCALE, parse_column_map, read_csv
from .px4 import read_ulog
from .ros2 import DEFAULT_TOPICS, read_rosbag2

__all__ = [
    "DEFAULT_TOPICS",
    "PWM_CENTER",
    "PWM_SPAN",
    "SERVO_LAYOUTS",
    "UNIT_SCALE",
    "north_east",
    "parse_column_map",
    "pwm",
    "quat_euler",
    "read_csv",
    "read_dataflash",
    "read_rosbag2",
    "read_tlog",
    "read_ulog",
    "servo_names",
    "truncated",
]
