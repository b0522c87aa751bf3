"""Times World.snapshot(), restore() and reset(seed) against reloading the world file.

    PYTHONPATH=build/python /usr/bin/python3 bench/python/snapshot_bench.py [--robots 1000]

For each backend: the median of --repeats calls, in ms, and the snapshot's size. The world
is tests/data/worlds/snapshot.yaml (foot-bots driven from Python, density 6 per m^2) after
--steps steps, so that bodies touch. Targets (issue 30): snapshot and restore <= 10 ms,
reset <= 20 ms at 1,000 robots.
"""

import argparse
import pathlib
import statistics
import time

import swarmsim

ROOT = pathlib.Path(__file__).resolve().parents[2]
WORLD = str(ROOT / "tests" / "data" / "worlds" / "snapshot.yaml")


def median_ms(fn, repeats):
    times = []
    for _ in range(repeats):
        start = time.perf_counter()
        fn()
        times.append(1e3 * (time.perf_counter() - start))
    return statistics.median(times)


def main():
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--robots", type=int, default=1000)
    p.add_argument("--steps", type=int, default=20)
    p.add_argument("--repeats", type=int, default=7)
    p.add_argument("--threads", type=int, default=2)
    p.add_argument("--backends", default="kinematic,planar,box2d,ode")
    a = p.parse_args()
    print(f"{a.robots} robots, {a.threads} threads, median of {a.repeats} (ms)")
    print(f"{'backend':10} {'load':>8} {'snapshot':>9} {'restore':>8} {'reset':>8} "
          f"{'reset(s)':>9} {'MiB':>6}")
    for physics in a.backends.split(","):
        settings = {"physics": physics, "robots": a.robots}
        load = median_ms(lambda: swarmsim.World(WORLD, set=settings, threads=a.threads).close(),
                         max(1, a.repeats // 3))
        w = swarmsim.World(WORLD, set=settings, threads=a.threads)
        w.reset()  # the world before its first step, kept for reset()
        w.step(a.steps)
        state = w.snapshot()
        snap = median_ms(w.snapshot, a.repeats)
        restore = median_ms(lambda: w.restore(state), a.repeats)
        reset_same = median_ms(lambda: w.reset(), a.repeats)
        seeds = iter(range(100, 100 + a.repeats))
        reset_other = median_ms(lambda: w.reset(next(seeds)), a.repeats)
        print(f"{physics:10} {load:8.1f} {snap:9.2f} {restore:8.2f} {reset_same:8.2f} "
              f"{reset_other:9.2f} {len(state) / 2**20:6.2f}")
        w.close()


if __name__ == "__main__":
    main()
