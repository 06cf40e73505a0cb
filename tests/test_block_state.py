"""Checkpoints: ``Block.get_state()`` / ``set_state()`` of every block of the live scenarios.

Run a scenario, save every block's state with the plants' states and the bus, run on, restore,
run the same interval again: the second pass must repeat the first exactly (issue 17 contract).
"""

from __future__ import annotations

import copy

import numpy as np
import pytest

from oceangnc.api import resolve_config

LIVE = ["combined-survey", "field-test", "usv-remote", "usv-turn", "autopilot-heading", "berthing-dock", "tow-straight"]


def _snapshot(sim):
    return (
        [b.get_state() for b in sim.blocks],
        [pl.x.copy() for pl in sim.plants],
        copy.deepcopy(sim.bus),
        (sim.k, sim.t, sim._done_k, list(sim.fire_count)),
    )


def _restore(sim, snap):
    blocks, xs, bus, (k, t, done, fires) = snap
    for b, s in zip(sim.blocks, blocks):
        b.set_state(s)
    for pl, x in zip(sim.plants, xs):
        pl.x[:] = x
    sim.bus.clear()
    sim.bus.update(copy.deepcopy(bus))
    sim.k, sim.t, sim._done_k, sim.fire_count = k, t, done, list(fires)


@pytest.mark.parametrize("name", LIVE)
def test_restored_state_repeats_the_run_exactly(name):
    sc, cfg = resolve_config(name)
    sim = sc.build(cfg, np.random.default_rng(0))
    sim.run(1.0)
    snap = _snapshot(sim)
    sim.run(1.0)
    first = {k: v for k, v in sim.bus.items() if isinstance(v, float)}
    x_first = [pl.x.copy() for pl in sim.plants]
    _restore(sim, snap)
    sim.run(1.0)
    second = {k: v for k, v in sim.bus.items() if isinstance(v, float)}
    assert first == second
    for a, b in zip(x_first, [pl.x for pl in sim.plants]):
        assert np.array_equal(a, b)
