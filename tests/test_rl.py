"""oceangnc.rl (issue 44): the Gymnasium environments of the Otter path-following and BlueROV2
station-keeping tasks.

One environment per task and module (building it loads the fused driver); short episodes."""

from __future__ import annotations

import numpy as np
import pytest

gymnasium = pytest.importorskip("gymnasium")

from oceangnc import rl  # noqa: E402
from oceangnc.errors import ConfigError, InputError  # noqa: E402


@pytest.fixture(scope="module", params=[("otter-waypoints", "otter-path"), ("rov-station-keeping", "rov-station")])
def any_env(request):
    scenario, task = request.param
    return rl.make(scenario, task=task, time_limit=3.0)


@pytest.fixture(scope="module")
def env():
    return rl.make("otter-waypoints", task="otter-path", time_limit=3.0)


def test_check_env_passes(any_env):
    from gymnasium.utils.env_checker import check_env

    check_env(any_env, skip_render_check=True)


def _rollout(env, seed, actions):
    obs, _ = env.reset(seed=seed)
    out = [obs]
    for a in actions:
        obs, r, term, trunc, info = env.step(a)
        out.append(np.append(obs, [r, info["t"]]))
        if term or trunc:
            break
    return out, env.sim.plants[0].x.copy()


def test_same_seed_same_trajectory_bit_for_bit(any_env):
    env = any_env
    acts = np.random.default_rng(7).uniform(-1, 1, size=(30, env.action_space.shape[0])).astype(np.float32)
    a, xa = _rollout(env, 11, acts)
    _rollout(env, 12, acts[::-1])  # another episode in between: nothing of it may leak into the next
    b, xb = _rollout(env, 11, acts)
    assert len(a) == len(b) > 20
    for u, v in zip(a, b):
        assert np.array_equal(u, v)
    assert np.array_equal(xa, xb)
    c, _ = _rollout(env, 12, acts)
    assert not np.array_equal(a[0], c[0])  # the seed does draw the initial state


def test_initial_states_lie_in_the_stated_bands_and_fill_them(env):
    p = env.task.params
    e, dpsi, u, cur = [], [], [], []
    for seed in range(20):
        env.reset(seed=seed)
        s = env.signals
        e.append(s["guidance.e"])  # the first leg runs north from (0, 0): e is the east offset
        dpsi.append(np.degrees(s["vehicle.psi"]))
        u.append(s["vehicle.u"])
        cur.append(np.hypot(s["env.current_n"], s["env.current_e"]))
    e, dpsi, u, cur = map(np.array, (e, dpsi, u, cur))
    assert np.abs(e).max() <= p.start_cross_max and np.abs(e).max() > 0.5 * p.start_cross_max
    assert np.abs(dpsi).max() <= p.heading_band_deg and np.abs(dpsi).max() > 0.5 * p.heading_band_deg
    assert u.min() >= 0.0 and u.max() <= p.u0_max and u.max() > 0.5 * p.u0_max
    assert cur.max() <= p.current_max and cur.max() > 0.5 * p.current_max


def test_env_steps_equal_the_clocks_run(env):
    """The env's driver calls (actions written by slot) give the plant state of Simulation.run with the
    actions put on the bus, bit for bit."""
    acts = np.random.default_rng(3).uniform(-1, 1, size=(20, 2)).astype(np.float32)
    a, xa = _rollout(env, 5, acts)
    env.reset(seed=5)
    sim = env.sim
    sim.bus.update({"_stop": False})
    for act in acts[: len(a) - 1]:
        sim.inject(env.task.act(np.asarray(act, np.float64)))
        sim.run(env.period)
    assert np.array_equal(sim.plants[0].x, xa)


def test_full_thrust_moves_forward_faster_than_none():
    env = rl.make("otter-waypoints", time_limit=5.0, u0_max=0.0, current_max=0.0, heading_band_deg=0.0)
    speeds = {}
    for a in (0.0, 1.0):
        env.reset(seed=1)
        while True:
            _, _, term, trunc, _ = env.step(np.full(2, a, np.float32))
            if term or trunc:
                break
        speeds[a] = env.signals["vehicle.u"]
    assert abs(speeds[0.0]) < 0.05  # at rest, no current, no thrust
    assert speeds[1.0] > 1.0  # full forward on both propellers: the Otter's top speed is about 3 m/s
    assert env.signals["vehicle.shaft_left"] > 90.0  # rad/s, the shaft near n_max = 103.9 rad/s


def test_episode_truncates_at_time_limit(env):
    env.reset(seed=2)
    n = 0
    while True:
        n += 1
        _, _, term, trunc, info = env.step(np.zeros(2, np.float32))
        if term or trunc:
            break
    assert trunc and not term and n == 30 and info["t"] == pytest.approx(3.0)


def test_leaving_the_channel_terminates_with_the_penalty():
    env = rl.make("otter-waypoints", e_max=2.0, start_cross_max=1.9, time_limit=60.0, current_max=0.0)
    env.reset(seed=0)
    while True:  # the left propeller alone: the boat turns off the line
        _, r, term, trunc, info = env.step(np.array([1.0, 0.0], np.float32))
        if term or trunc:
            break
    assert term and info["reason"] == "off_channel" and r < -env.task.params.end_penalty + 1.0


@pytest.mark.parametrize(
    "kwargs, err, words",
    [
        ({"task": "docking"}, InputError, "unknown task 'docking'"),
        ({"e_max": -1.0}, ConfigError, "e_max"),
        ({"control_period": 0.015}, ConfigError, "control_period"),
        ({"start_cross_max": 20.0}, ConfigError, "start_cross_max"),
        ({"route.speed": 99.0}, ConfigError, "route.speed"),
        ({"no_such_key": 1}, ConfigError, "no_such_key"),
    ],
)
def test_bad_task_or_override_is_one_clear_error(kwargs, err, words):
    with pytest.raises(err) as ei:
        rl.make("otter-waypoints", **kwargs)
    msg = str(ei.value)
    assert words in msg and "\n" not in msg


def test_station_keeping_spaces_and_penalty():
    env = rl.make("rov-station-keeping", d_max=3.0, start_band=1.0, start_depth_band=0.5, time_limit=30.0)
    assert env.action_space.shape == (8,) and env.observation_space.shape == (20,)  # 12 + the 8 thrusts
    env.reset(seed=4)
    down = np.array([0, 0, 0, 0, 1, 1, 1, 1], np.float32)  # the four vertical thrusters, +z (down) in its file
    while True:
        _, r, term, trunc, info = env.step(down)
        if term or trunc:
            break
    assert term and info["reason"] == "left_station" and r < -env.task.params.end_penalty + 1.0


def test_scenario_without_task_is_refused():
    with pytest.raises(InputError, match="no task over scenario 'usv-turn'"):
        rl.make("usv-turn")
