"""Guidance geometry of 003 ch. 3.1-3.2: pure pursuit (eq. 3.1-3.6, table 3-1), leader-follower (3.7-3.9)."""

import math

import numpy as np
import pytest

from oceangnc.errors import ConfigError
from oceangnc.guidance.leader_follower import (
    LeaderFollower,
    los_bearing,
    range_bearing,
    relative_position,
    target_offset,
    target_point,
)
from oceangnc.guidance.pure_pursuit import (
    PurePursuit,
    closest_point,
    look_ahead_distance,
    look_ahead_point,
    pursuit_command,
    pursuit_radius,
    usv_min_turning_radius,
    uuv_turning_radius_at,
)
from oceangnc.models.usv import USVConfig, steady_turn
from oceangnc.models.uuv import UUVConfig
from oceangnc.units import KGF


@pytest.mark.parametrize("l, alpha_deg", [(5.0, 10.0), (8.67, 45.0), (2.0, 89.0), (3.0, -30.0)])
def test_pursuit_radius_is_the_circle_through_the_look_ahead_point(l, alpha_deg):
    """R = l^2/(2d) (eq. 3.5) is the radius of the circle tangent to the heading at P through G."""
    a = math.radians(alpha_deg)
    b, d = l * math.cos(a), l * math.sin(a)  # G in the vehicle frame (forward, starboard), eq. 3.1
    R = pursuit_radius(l, d)
    # centre at (0, R): |G - C| = |R| (eq. 3.2 with a = R - d, eq. 3.3)
    assert math.hypot(b, d - R) == pytest.approx(abs(R), rel=1e-12)
    assert R == pytest.approx(l / (2 * math.sin(a)))


def test_tightest_pursuit_turn_is_half_the_look_ahead():
    """G abeam (d = l) gives R = l/2, hence l = 2 R_min (eq. 3.6)."""
    assert pursuit_radius(6.0, 6.0) == pytest.approx(3.0)
    assert look_ahead_distance(0.36, 4.3) == pytest.approx(8.6)
    assert math.isinf(pursuit_radius(5.0, 0.0))
    with pytest.raises(ConfigError):
        look_ahead_distance(0.0, 2.0)


def test_look_ahead_point_on_leg_at_distance_l():
    """Table 3-1 steps 3-4: closest point, then the leg point at distance l from the vehicle."""
    a, b = (0.0, 0.0), (20.0, 0.0)  # leg heading north
    p = (2.0, 3.0)  # 3 m east = to starboard of the leg
    F, s, e = closest_point(p, a, b)
    assert np.allclose(F, (2.0, 0.0)) and s == pytest.approx(2.0) and e == pytest.approx(3.0)
    g, _, _ = look_ahead_point(p, a, b, 5.0)
    assert np.allclose(g, (6.0, 0.0))
    assert math.hypot(g[0] - p[0], g[1] - p[1]) == pytest.approx(5.0)
    # farther from the line than l: head straight back to it
    g2, _, e2 = look_ahead_point((2.0, -7.0), a, b, 5.0)
    assert np.allclose(g2, (2.0, 0.0)) and e2 == pytest.approx(-7.0)
    # clamped at the final waypoint
    g3, _, _ = look_ahead_point((18.0, 0.5), a, b, 5.0, clamp_end=True)
    assert np.allclose(g3, b)
    psi_d, l, d, R = pursuit_command(p, 0.0, g)
    assert psi_d == pytest.approx(math.atan2(-3.0, 4.0)) and l == pytest.approx(5.0) and d == pytest.approx(-3.0)
    assert R == pytest.approx(25.0 / -6.0)


def test_min_turning_radii_come_from_the_models():
    """R_min of the USV is the model's steady turn at full/zero thrust; the UUV's grows with speed."""
    cfg = USVConfig()
    u, v, r = steady_turn(cfg, cfg.max_thrust_kgf * KGF, 0.0)
    assert usv_min_turning_radius(cfg) == pytest.approx(math.hypot(u, v) / abs(r))
    ucfg = UUVConfig()
    r_slow, r_fast = uuv_turning_radius_at(ucfg, 0.3), uuv_turning_radius_at(ucfg, 1.0)
    assert 0.5 < r_slow < r_fast < 20.0


def _kinematic_run(wp, speed=1.0, l=6.0, acc=2.0, t_end=400.0, dt=0.1):
    """A unicycle that turns at most 30 deg/s toward the guidance heading."""
    pp = PurePursuit(wp, l, acc, dt)
    bus = {"usv.x": wp[0][0], "usv.y": wp[0][1], "usv.psi": 0.0}
    xt = []
    t = 0.0
    while t < t_end and not bus.get("_stop"):
        pp.step(t, bus)
        e = (bus["guidance.psi_d"] - bus["usv.psi"] + math.pi) % (2 * math.pi) - math.pi
        bus["usv.psi"] += max(-0.52 * dt, min(0.52 * dt, e))
        bus["usv.x"] += speed * math.cos(bus["usv.psi"]) * dt
        bus["usv.y"] += speed * math.sin(bus["usv.psi"]) * dt
        xt.append(bus["guidance.cross_track"])
        t += dt
    return bus, np.array(xt), t


def test_pure_pursuit_reaches_every_waypoint_and_switches_legs():
    wp = [(0.0, 0.0), (50.0, 0.0), (50.0, 50.0), (0.0, 50.0)]
    bus, xt, t = _kinematic_run(wp)
    assert bus["_stop"] and bus["guidance.wp_reached"] == 4 and bus["guidance.leg"] == 2
    assert math.hypot(bus["usv.x"] - 0.0, bus["usv.y"] - 50.0) <= 2.0
    assert t < 170.0  # 150 m of legs at 1 m/s, corners cut
    assert np.sqrt(np.mean(xt**2)) < 1.0


def test_pure_pursuit_rejects_bad_waypoints():
    with pytest.raises(ConfigError):
        PurePursuit([(0.0, 0.0)], 5.0, 1.0)
    with pytest.raises(ConfigError):
        PurePursuit([(0.0, 0.0), (0.0, 0.0), (5.0, 0.0)], 5.0, 1.0)


def test_relative_position_matches_printed_eq_3_7():
    rng = np.random.default_rng(3)
    for _ in range(20):
        xu, yu, psi, xf, yf = rng.uniform(-10, 10, 5)
        lx, ly = relative_position(xu, yu, psi, xf, yf)
        assert lx == pytest.approx(-(xu - xf) * math.cos(psi) - (yu - yf) * math.sin(psi))
        assert ly == pytest.approx((xu - xf) * math.sin(psi) - (yu - yf) * math.cos(psi))
        assert math.hypot(lx, ly) == pytest.approx(math.hypot(xu - xf, yu - yf))


def test_leader_follower_offsets_and_bearings():
    """lambda^d = pi puts the target l^d astern; a follower 2 m behind an east-going leader."""
    lxd, lyd = target_offset(0.5, math.pi)
    assert lxd == pytest.approx(-0.5) and lyd == pytest.approx(0.0, abs=1e-12)
    lxd, lyd = target_offset(1.0, math.radians(135))  # astern to starboard
    assert lxd < 0 and lyd > 0
    psi = math.pi / 2
    assert np.allclose(target_point(10.0, 5.0, psi, -0.5, 0.0), (10.0, 4.5))
    lx, ly = relative_position(10.0, 5.0, psi, 10.0, 3.0)
    rng_, lam = range_bearing(lx, ly)
    assert (lx, rng_) == pytest.approx((-2.0, 2.0)) and lam == pytest.approx(math.pi)
    assert los_bearing(10.0, 3.0, 10.0, 5.0) == pytest.approx(math.pi / 2)


def test_leader_follower_switches_to_heading_to_usv_outside_R():
    lf = LeaderFollower(0.5, math.pi, 1.0)
    bus = {"usv.x": 0.0, "usv.y": 0.0, "usv.psi": 0.0, "uuv.x": -0.5, "uuv.y": 0.3, "uuv.psi": 0.2}
    lf.step(0.0, bus)
    assert bus["lf.outside"] == 0.0 and bus["lf.psi_d"] == 0.0
    assert bus["lf.rel_heading_err"] == pytest.approx(-0.2)
    bus.update({"uuv.x": -1.0, "uuv.y": 1.0})
    lf.step(0.1, bus)
    assert bus["lf.outside"] == 1.0
    assert bus["lf.psi_d"] == pytest.approx(math.atan2(-1.0, 1.0))
    only = LeaderFollower(0.5, math.pi, 1.0, mode="relative-angle")
    only.step(0.0, bus)
    assert bus["lf.outside"] == 0.0 and bus["lf.psi_d"] == 0.0


def test_a_longer_route_set_while_running_is_flown_by_the_pure_pursuit_law():
    """A route set on the block (the MAVLink mission hook writes ``wp``) longer than the first is written
    into its parameters: at the old route's last waypoint the law starts the new route's next leg."""
    pp = PurePursuit([(0.0, 0.0), (10.0, 0.0)], 4.0, 1.0, 0.1)
    pp.wp = [(0.0, 0.0), (10.0, 0.0), (10.0, 10.0), (0.0, 10.0)]
    assert pp.wp.tolist() == [[0.0, 0.0], [10.0, 0.0], [10.0, 10.0], [0.0, 10.0]]
    bus = {"usv.x": 10.0, "usv.y": 0.0, "usv.psi": 0.0}
    pp.step(0.0, bus)
    assert pp.leg == 1 and pp.reached == 1 and not pp.done and not bus["_stop"]
    assert (bus["guidance.lookahead_n"], bus["guidance.lookahead_e"]) == (10.0, 4.0)
    assert bus["guidance.psi_d"] == pytest.approx(math.pi / 2)


def test_a_route_sent_while_running_reaches_the_route_pilots_law():
    """``send_route`` (the console's map, a MAVLink mission) writes the route into the pilot's arrays, a
    route longer than the configured one included, and restarts it from where the boat is; the route
    flown already changes nothing."""
    from oceangnc.api import resolve_config
    from oceangnc.guidance.route_pilot import RoutePilot, send_route

    sc, cfg = resolve_config("usv-remote")
    sim = sc.build(cfg, np.random.default_rng(0))
    sim.run(1.0)
    pilot = next(b for b in sim.blocks if isinstance(b, RoutePilot))
    pts = ((-30.0, -30.0), (-30.0, 30.0), (30.0, 30.0), (30.0, -30.0), (-30.0, -30.0), (0.0, 0.0))
    assert len(pts) > len(cfg.guidance.waypoints)
    send_route(sim, [list(p) for p in pts])
    assert sim.bus["console.waypoints"] == pts and pilot.route == pts and pilot.wp == 0 and pilot.leg_start is None
    sim.run(0.1)
    x, y = pilot.leg_start  # where the boat was at the pilot's next period: the new leg's start
    # steering along the leg toward the new first point (south-west; the old route's is north)
    assert sim.bus["guidance.wp_index"] == 0.0
    assert sim.bus["guidance.psi_d"] == pytest.approx(math.atan2(-30.0 - y, -30.0 - x), abs=0.01)
    sim.run(5.0)
    start = pilot.leg_start
    send_route(sim, pts)
    assert pilot.leg_start == start  # the same route again: not restarted
