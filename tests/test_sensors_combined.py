"""Sensors of 003 ch. 6.1 / appendix B: GPS, AHRS, USBL, depth sensor, filters and dropout handling."""

import math

import numpy as np
import pytest

from oceangnc.sensors import (
    AHRS,
    GPS,
    USBL,
    AHRSConfig,
    DepthSensor,
    DepthSensorConfig,
    DropoutHold,
    GPSConfig,
    LowPass,
    USBLConfig,
)
from oceangnc.sensors.depth import PARAMS, ideal_voltage
from oceangnc.sensors.filters import AngleLowPass, lowpass_array, lowpass_coefficient
from oceangnc.units import RHO_WATER, G


def _gps_run(seed, t_end=10.0, speed=0.0, course=0.0, cfg=None):
    gps = GPS(cfg or GPSConfig())
    gps.reset(np.random.default_rng(seed))
    bus = {"usv.x": 0.0, "usv.y": 0.0, "usv.psi": 0.0}
    out = []
    t = 0.0
    while t <= t_end + 1e-9:
        bus["usv.x"] = speed * t * math.cos(course)
        bus["usv.y"] = speed * t * math.sin(course)
        gps.step(t, bus)
        out.append(
            (
                bus["gps.x"] - bus["usv.x"],
                bus["gps.y"] - bus["usv.y"],
                bus["gps.cog"],
                bus["gps.cog_valid"],
                bus["gps.sog"],
            )
        )
        t += gps.period
    return np.array(out)


def test_gps_standing_still_is_centimetre_steady_and_hdop_scales_the_error():
    """003 fig 6-3: cm-level scatter when still; the horizontal RMS error over many receivers is
    HDOP x UERE (0.9 x 0.17 m = 0.15 m), 2DRMS ~ 0.3 m (table C-1)."""
    o = _gps_run(1)
    assert np.std(o[:, 0]) < 0.03 and np.std(o[:, 1]) < 0.03
    first = np.array([_gps_run(s, t_end=0.0)[0, :2] for s in range(400)])
    hrms = math.sqrt(np.mean(np.sum(first**2, axis=1)))
    assert hrms == pytest.approx(0.9 * 0.17, rel=0.15)
    first2 = np.array([_gps_run(s, t_end=0.0, cfg=GPSConfig(hdop=2.0))[0, :2] for s in range(400)])
    assert math.sqrt(np.mean(np.sum(first2**2, axis=1))) == pytest.approx(2.0 * 0.17, rel=0.15)


def test_gps_heading_from_track():
    o = _gps_run(2, t_end=20.0, speed=1.0, course=math.radians(30.0))
    assert (o[20:, 3] == 1).all()
    assert np.degrees(np.abs(o[20:, 2] - math.radians(30.0))).max() < 3.0
    assert o[20:, 4].mean() == pytest.approx(1.0, abs=0.03)
    still = _gps_run(2, t_end=5.0)
    assert (still[:, 3] == 0).all()  # no valid course when not moving


def test_ahrs_lags_while_turning_and_agrees_when_still():
    """The lag tau makes the AHRS heading trail the truth by ~tau r while turning (003 fig 6-2)."""
    cfg = AHRSConfig(yaw_noise_deg=0.0, mag_sigma_deg=0.0)
    ahrs = AHRS(cfg, "usv")
    ahrs.reset(np.random.default_rng(0))
    r = math.radians(10.0)
    bus = {"usv.psi": 0.0, "usv.r": r}
    for k in range(400):
        t = k * ahrs.period
        bus["usv.psi"] = (r * t + math.pi) % (2 * math.pi) - math.pi
        ahrs.step(t, bus)
    lag = (bus["usv.psi"] - bus["usv_ahrs.psi"] + math.pi) % (2 * math.pi) - math.pi
    assert math.degrees(lag) == pytest.approx(10.0 * cfg.lag, rel=0.05)
    for k in range(400, 600):
        ahrs.step(k * ahrs.period, bus)  # heading now constant
    assert abs(bus["usv.psi"] - bus["usv_ahrs.psi"]) < 1e-3


def test_ahrs_noise_level():
    cfg = AHRSConfig()
    ahrs = AHRS(cfg, "uuv")
    ahrs.reset(np.random.default_rng(5))
    bus = {"uuv.psi": 0.3, "uuv.r": 0.0}
    e = []
    for k in range(20000):
        ahrs.step(k * ahrs.period, bus)
        e.append(bus["uuv_ahrs.psi"] - 0.3)
    assert math.degrees(np.std(e)) == pytest.approx(math.hypot(1.0, 2.0), rel=0.35)


def _usbl_fixes(cfg, rel, n=2000, seed=0):
    u = USBL(cfg)
    u.reset(np.random.default_rng(seed))
    bus = {"usv.x": 0.0, "usv.y": 0.0, "usv.z": 0.0, "uuv.x": rel[0], "uuv.y": rel[1], "uuv.z": rel[2]}
    out = []
    for k in range(n):
        u.step(k * u.period, bus)
        out.append((bus["usbl.valid"], *(bus.get(f"usbl.{k}", np.nan) for k in ("range", "bearing", "dn", "de"))))
    return np.array(out)


def test_usbl_errors_within_table_c3_resolution():
    rel = (0.4, 0.3, 3.0)
    o = _usbl_fixes(USBLConfig(), rel)
    assert (o[:, 0] == 1).all()
    assert np.abs(o[:, 1] - math.sqrt(0.25 + 9.0)).max() <= 0.05 + 1e-12
    assert np.degrees(np.abs(o[:, 2] - math.atan2(0.3, 0.4))).max() <= 1.0 + 1e-9


def test_usbl_drops_out_beyond_its_usable_range():
    """Horizontal 4.4 m at 0.8 m relative depth (q = 5.5 > 5, the tank test's unreliable zone): about
    p_drop of the pings are lost and the fixes are degraded; at 2.4 m none is lost."""
    cfg = USBLConfig()
    bad = _usbl_fixes(cfg, (4.4, 0.5, 0.8))
    assert 1 - bad[:, 0].mean() == pytest.approx(cfg.p_drop, abs=0.05)
    good = _usbl_fixes(cfg, (2.4, 0.5, 0.8))
    assert good[:, 0].all()
    err_bad = np.std(bad[bad[:, 0] == 1, 3] - 4.4)
    err_good = np.std(good[:, 3] - 2.4)
    assert err_bad > 3 * err_good


def test_usbl_forced_dropout_window_and_downstream_hold():
    """Forced 10 s dropout: no fixes inside; DropoutHold holds the last value, flags it, ages it, and
    recovers with the first fix after the window."""
    u = USBL(USBLConfig(dropout_start=5.0, dropout_duration=10.0))
    u.reset(np.random.default_rng(1))
    hold = DropoutHold("usbl_hold", 0.5, "usbl.valid", {"dn": "usbl.dn"}, "nav.usbl")
    bus = {"usv.x": 0.0, "usv.y": 0.0, "uuv.x": 0.5, "uuv.y": 0.0, "uuv.z": 3.0}
    rows = []
    for k in range(50):
        t = 0.5 * k
        bus["uuv.x"] = 0.5 + 0.05 * t
        u.step(t, bus)
        hold.step(t, bus)
        rows.append((t, bus["usbl.valid"], bus["nav.usbl.dn"], bus["nav.usbl.ok"], bus["nav.usbl.age"]))
    rows = np.array(rows)
    inside = (rows[:, 0] >= 5.0) & (rows[:, 0] < 15.0)
    assert (rows[inside, 1] == 0).all() and (rows[inside, 3] == 0).all()
    held = rows[inside, 2]
    assert np.allclose(held, held[0])
    assert rows[inside, 4].max() == pytest.approx(10.0, abs=0.51)
    after = rows[:, 0] >= 15.0
    assert (rows[after, 3] == 1).all()
    assert np.abs(rows[after, 2] - (0.5 + 0.05 * rows[after, 0])).max() < 0.1
    assert bus["nav.usbl.dropouts"] == 1.0


def test_depth_sensor_voltage_calibration_and_filter():
    """0-10 bar -> 0-5 V; first-order calibration over 0.66-2.46 m recovers depth; the low-pass
    filter cuts the noise (003 ch. 6.1.3)."""
    z_fs = 10e5 / (RHO_WATER * G)
    assert ideal_voltage(z_fs) == pytest.approx(5.0) and ideal_voltage(0.0) == 0.0
    cfg = DepthSensorConfig()
    s = DepthSensor(cfg)
    s.reset(np.random.default_rng(4))
    assert s.pa[PARAMS.at.c1] == pytest.approx(z_fs / 5.0, rel=0.01)  # ~20 m/V
    bus = {"uuv.z": 2.77}
    raw, filt = [], []
    for k in range(2000):
        s.step(k * s.period, bus)
        raw.append(bus["depth.z_raw"])
        filt.append(bus["depth.z"])
    raw, filt = np.array(raw[200:]), np.array(filt[200:])
    assert abs(filt.mean() - 2.77) < 0.03
    assert np.std(filt) < np.std(raw) / 3
    assert 0.0 <= bus["depth.volt"] <= 5.0


def test_lowpass_time_constant_and_angle_wrap():
    h, fc = 0.01, 1.0 / (2 * math.pi)  # tau = 1 s
    lp = LowPass(fc, h)
    lp(0.0)
    for _ in range(100):
        y = lp(1.0)
    assert y == pytest.approx(1 - math.exp(-1.0), rel=1e-9)
    a = lowpass_coefficient(fc, h)
    assert lowpass_array(np.ones(100), a, 0.0)[-1] == pytest.approx(y)
    alp = AngleLowPass(1.0, 0.1)
    alp(math.radians(179.0))
    y = alp(math.radians(-179.0))
    assert abs(y) > math.radians(178.0)  # filtered across the wrap, not through zero
