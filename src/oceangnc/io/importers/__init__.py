"""Field logs in: ArduPilot DataFlash ``.bin`` and telemetry ``.tlog`` (pymavlink), PX4 ``.ulg`` (pyulog),
ROS 2 bags (rosbags) and CSV with a column map -> the project's Parquet log.

Every reader returns *raw series*: ``{signal: (t, values)}`` with t in s and values in SI units under
the standard signal names below; :func:`resample` puts them on one time grid at ``rate`` Hz and
reports gaps (no sample for longer than ``gap_s``: the grid rows inside stay NaN, never
interpolated) and time jumps (non-increasing or leaping time stamps; the samples out of order are
dropped and counted). :func:`read_any` gives a pandas DataFrame ready for the identification
commands; ``oceangnc import LOG --out DIR`` writes ``DIR/log.parquet`` and ``DIR/import.json``.

The readers also say what the log is of (``vehicle``: firmware string, MAV_TYPE, PX4 airframe; a non-boat
is refused by boat identification unless forced), which ArduPilot output drives what (``servo_map`` from
SERVOn_FUNCTION), which sensor instance was read (``instances``), which GPS samples had no 3D fix, and
for a ROS 2 bag without message definitions which distro's typestore read it. ``start`` / ``end`` keep a
stretch of the log; implausible heights are refused (:func:`~.core.check_heights`).

Standard signals (NED earth frame, body x forward / y starboard / z down, SI, angles in rad):

=====================  ===========================================================  =======
signal                 meaning                                                      unit
=====================  ===========================================================  =======
usv.x, usv.y           north, east of the origin (first fix, or ``origin=``)         m
usv.z                  down (depth of a submerged vehicle)                           m
usv.psi                heading (yaw), wrapped to (-pi, pi]                           rad
usv.phi, usv.theta     roll, pitch                                                   rad
usv.r                  yaw rate (body z, down positive)                              rad/s
usv.vn, usv.ve         north, east velocity over ground                              m/s
usv.speed              speed over ground                                             m/s
usv.u, usv.v           surge, sway (over-ground velocity in the body frame)          m/s
act.left, act.right    normalised thruster commands (port, starboard), -1..1         1
act.throttle           (left + right) / 2                                            1
act.steer              (left - right) / 2 (positive turns to starboard)              1
=====================  ===========================================================  =======
"""

from __future__ import annotations

from .core import FORMATS, ImportResult, import_log, read_any, resample

__all__ = ["FORMATS", "ImportResult", "import_log", "read_any", "resample"]
