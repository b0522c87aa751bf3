"""swarmsim.env throughput (issue 30's target: 64 environments x 16 robots, a numpy policy,
2 threads, >= 100,000 agent-steps/s from Python), run by hand, never by the tests:

    PYTHONPATH=build/python /usr/bin/python3 bench/python/env_throughput.py [--envs 64]
        [--robots 16] [--steps 300] [--max-steps 100] [--repeats 3]

A VectorEnv over worlds/python/diffusion_numpy.yaml (foot-bots; 24 proximity readings in,
two wheel speeds out), a numpy policy (a fixed linear map of the observations, the
Braitenberg avoidance diffusion does), observations and actions crossing the boundary every
step, episodes of --max-steps steps with next-step autoreset (so resets are counted).
Agent-steps/s = envs x robots x steps / wall time of the step loop (median of --repeats).

Modes: "step_worlds" steps the K worlds with swarmsim.step_worlds on --threads threads (only
when the module has it); "loop" steps them one after the other, each world on 1 thread and on
--threads threads. Also printed: one ParallelEnv's rate (the dict API, one world), the cost
of one environment's reset (World.reset where the module has it, else a new World loaded
from the file), the share of the wall time spent inside the worlds' steps, and agent-steps
per CPU-second of the process (user + system time of all its threads: on a shared machine
the wall-clock rate depends on what else runs; this one much less).
"""

import argparse
import pathlib
import statistics
import time
import warnings

import numpy as np

from swarmsim import _env_core
from swarmsim.env import ParallelEnv, VectorEnv

ROOT = pathlib.Path(__file__).resolve().parents[2]
WORLD = ROOT / "worlds" / "python" / "diffusion_numpy.yaml"


def policy_weights(sensors=24):
    # A Braitenberg vehicle as a (24, 2) matrix: what the front-left sensors see slows the
    # right wheel and the front-right ones the left wheel, so the robot turns away.
    angles = 2 * np.pi * np.arange(sensors) / sensors
    front = np.cos(angles) > 0
    left = np.sin(angles) > 0
    w = np.zeros((sensors, 2))
    w[front & left, 1] = -0.15
    w[front & ~left, 0] = -0.15
    return w


def run(args, threads, parallel):
    env = VectorEnv(str(WORLD), args.envs, set={"robots": args.robots},
                    max_steps=args.max_steps, threads=1 if parallel else threads,
                    step_threads=threads)
    env._core.parallel = parallel  # False: the fallback loop, for comparison
    w = policy_weights()
    obs, _ = env.reset(seed=1)
    stepping = [0.0]
    step_all = env._core.step_all

    def timed():
        t = time.perf_counter()
        step_all()
        stepping[0] += time.perf_counter() - t
    env._core.step_all = timed
    t = time.perf_counter()
    cpu = time.process_time()
    for _ in range(args.steps):
        actions = np.clip(0.08 + obs @ w, -0.1, 0.1)
        obs, rewards, terminations, truncations, infos = env.step(actions)
    elapsed = time.perf_counter() - t
    cpu = time.process_time() - cpu
    env.close()
    agent_steps = args.envs * args.robots * args.steps
    return agent_steps / elapsed, stepping[0] / elapsed, agent_steps / cpu


def reset_cost(args, repeats=20):
    """ms for one environment's reset (World.reset in place, or a new World), its first
    step not included."""
    env = VectorEnv(str(WORLD), 1, set={"robots": args.robots}, threads=1)
    env.reset(seed=1)
    env.step(np.zeros((1, args.robots, 2)))
    t = time.perf_counter()
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        for i in range(repeats):
            env._core.reset_world(0, 100 + i)
    elapsed = time.perf_counter() - t
    failed = env._core.reset_failures
    env.close()
    return elapsed / repeats * 1e3, failed


def parallel_env_rate(args, steps=200):
    """Agent-steps/s of one ParallelEnv (dicts keyed by agent name), the same world and
    policy, its World on 1 thread."""
    env = ParallelEnv(str(WORLD), set={"robots": args.robots}, max_steps=None, threads=1)
    w = policy_weights()
    obs, _ = env.reset(seed=1)
    t = time.perf_counter()
    for _ in range(steps):
        actions = {a: np.clip(0.08 + o @ w, -0.1, 0.1) for a, o in obs.items()}
        obs, rewards, terminations, truncations, infos = env.step(actions)
    elapsed = time.perf_counter() - t
    env.close()
    return args.robots * steps / elapsed


def main():
    parser = argparse.ArgumentParser()
    parser.add_argument("--envs", type=int, default=64)
    parser.add_argument("--robots", type=int, default=16)
    parser.add_argument("--steps", type=int, default=300)
    parser.add_argument("--max-steps", type=int, default=100)
    parser.add_argument("--threads", type=int, default=2)
    parser.add_argument("--repeats", type=int, default=3)
    args = parser.parse_args()

    modes = []
    if _env_core.has_parallel_step():
        modes.append((f"step_worlds, {args.threads} threads", args.threads, True))
    else:
        print("swarmsim.step_worlds: not in this build (only the loop is measured)")
    modes += [("loop, 1 thread a world", 1, False),
              (f"loop, {args.threads} threads a world", args.threads, False)]
    print(f"{args.envs} environments x {args.robots} robots, {args.steps} steps, episodes of "
          f"{args.max_steps} steps (autoreset), World.reset: "
          f"{'yes' if _env_core.has_reset() else 'no (reload)'}; median of {args.repeats}")
    ms, failed = reset_cost(args)
    how = "a new World"
    if _env_core.has_reset():
        how = "World.reset" if not failed else f"World.reset failed {failed} times: a new World"
    print(f"  one environment's reset: {ms:.1f} ms ({how}, {args.robots} robots)")
    print(f"  one ParallelEnv (dicts), 1 thread: {parallel_env_rate(args):,.0f} agent-steps/s")
    for name, threads, parallel in modes:
        rates, shares, cpu_rates = [], [], []
        for _ in range(args.repeats):
            rate, share, cpu_rate = run(args, threads, parallel)
            rates.append(rate)
            shares.append(share)
            cpu_rates.append(cpu_rate)
        print(f"  {name:28s} {statistics.median(rates):10,.0f} agent-steps/s "
              f"(min {min(rates):,.0f}, max {max(rates):,.0f}; "
              f"{100 * statistics.median(shares):.0f}% inside the worlds' steps; "
              f"{statistics.median(cpu_rates):,.0f} per CPU-second of the process)")


if __name__ == "__main__":
    main()
