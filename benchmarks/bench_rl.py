"""Environment steps per second of :mod:`oceangnc.rl` (issue 44): one environment, one core.

For each task: build the environment (compiles or loads the fused driver), then time ``--steps``
calls of ``env.step`` with uniform random actions drawn beforehand (resetting at each episode's end,
the resets counted in the time), best of ``--repeat``. For scale, the same closed loop run in one
``Simulation.run`` call over the same simulated time (the inputs held): the cost of the compiled
physics and blocks alone, so the difference is the per-step Python work (action, bus, observation,
reward). Usage::

    python benchmarks/bench_rl.py [--steps 20000] [--repeat 3]
"""

from __future__ import annotations

import argparse
import os
import platform
import time

import numpy as np

from record import record

os.environ.setdefault("NUMBA_NUM_THREADS", "1")

TASKS = [("otter-waypoints", "otter-path"), ("rov-station-keeping", "rov-station")]


def _time_env(env, steps: int) -> float:
    acts = np.random.default_rng(0).uniform(-1, 1, size=(steps, env.action_space.shape[0])).astype(np.float32)
    env.reset(seed=0)
    t0 = time.perf_counter()
    for i in range(steps):
        _, _, term, trunc, _ = env.step(acts[i])
        if term or trunc:
            env.reset()
    return time.perf_counter() - t0


def _time_loop(env, steps: int) -> float:
    """The compiled loop alone over the same simulated time (one run call, zero thrust, no episode ends)."""
    env.reset(seed=0)
    sim = env.sim
    sim.bus["_stop"] = False
    t0 = time.perf_counter()
    sim.run(steps * env.period)
    return time.perf_counter() - t0


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__)
    ap.add_argument("--steps", type=int, default=20000, help="environment steps per timing")
    ap.add_argument("--repeat", type=int, default=3)
    args = ap.parse_args()

    from oceangnc import rl

    print(
        f"machine: {platform.processor() or platform.machine()}, {os.cpu_count()} cores, python {platform.python_version()}"
    )
    for scenario, task in TASKS:
        t0 = time.perf_counter()
        env = rl.make(scenario, task=task, time_limit=60.0)
        _time_env(env, 50)  # the first reset and steps (loads the driver)
        build = time.perf_counter() - t0
        best = min(_time_env(env, args.steps) for _ in range(args.repeat))
        # the loop alone: no route end, no leaving the channel (a long time limit, the episode never checked)
        loop_env = rl.make(scenario, task=task, time_limit=1e5, current_max=0.0)
        loop = min(_time_loop(loop_env, args.steps) for _ in range(args.repeat))
        rate, loop_rate = args.steps / best, args.steps / loop
        substeps = round(env.period / env.sim.dt)
        print(
            f"{task} over {scenario}: {rate:,.0f} env steps/s ({env.period:g} s control period, {substeps} physics "
            f"steps of {env.sim.dt:g} s each); compiled loop alone {loop_rate:,.0f} control periods/s; "
            f"first make + 50 steps {build:.1f} s"
        )
        record(
            "reinforcement learning (oceangnc.rl)",
            f"`{task}` over `{scenario}`, one env, random actions, best of {args.repeat} x {args.steps} steps",
            rate,
            "steps/s",
            ">= 100,000 on 2 cores (issue 44, vectorised; not built yet)" if task == "rov-station" else "",
            f"{env.period:g} s control period = {substeps} RK4 steps of {env.sim.dt:g} s; the compiled loop alone: "
            f"{loop_rate:,.0f} periods/s",
        )


if __name__ == "__main__":
    main()
