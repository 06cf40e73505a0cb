"""Pieces shared by scenario modules: the USV bundle (plant, thrusters, environment) and metrics."""

from __future__ import annotations

import math

import numpy as np

from ..environment import OceanCurrent, Wind


def environment_blocks(env_cfg, period: float = 0.1):
    """Current and wind blocks for an EnvironmentConfig."""
    return [OceanCurrent(env_cfg.current, period), Wind(env_cfg.wind, period)]


def circle_fit_drifting(t, x, y, psi):
    """Fit a turning circle whose centre drifts uniformly: x = xc + vx t + A cos(psi) + B sin(psi), same for y.

    For a steady turn the position relative to the circle's centre is a rotation of a constant vector
    by the heading, so with the heading as the phase this is a linear least-squares problem. Returns
    (radius_m, drift_speed_mps, drift_direction_deg, rms_residual_m); the direction is where the centre
    moves toward, deg from north.
    """
    t = np.asarray(t, float)
    psi = np.unwrap(np.asarray(psi, float))
    H = np.column_stack([np.ones_like(t), t, np.cos(psi), np.sin(psi)])
    cx, *_ = np.linalg.lstsq(H, np.asarray(x, float), rcond=None)
    cy, *_ = np.linalg.lstsq(H, np.asarray(y, float), rcond=None)
    radius = math.sqrt((cx[2] ** 2 + cx[3] ** 2 + cy[2] ** 2 + cy[3] ** 2) / 2.0)
    vx, vy = cx[1], cy[1]
    res = np.concatenate([x - H @ cx, y - H @ cy])
    return radius, math.hypot(vx, vy), math.degrees(math.atan2(vy, vx)) % 360.0, float(np.sqrt(np.mean(res**2)))
