"""Python binding benchmarks (issue 17's targets), run by hand, never by the tests:

    PYTHONPATH=build/python /usr/bin/python3 bench/python/python_bench.py [--robots 1000] [--steps 200]

1. diffusion, N robots, 1 thread: seconds per step with the Lua controller (worlds/diffusion.yaml)
   and with the vectorised numpy controller (worlds/python/diffusion_numpy.yaml), alternating
   runs, median of --repeats; and the controller call alone (time inside control()).
2. World.poses() of 10,000 robots into a reused array (out=) and into a new one: us per call.
"""

import argparse
import pathlib
import statistics
import sys
import time

import numpy as np

import swarmsim

ROOT = pathlib.Path(__file__).resolve().parents[2]
sys.path.insert(0, str(ROOT / "scripts"))
import diffusion_numpy  # noqa: E402


def run_world(path, robots, steps, controllers=None):
    w = swarmsim.World(str(path), seed=1, threads=1, set={"robots": robots},
                       controllers=controllers or {})
    w.step(1)  # start: scripts' init, first sense
    t = time.perf_counter()
    w.step(steps)
    elapsed = time.perf_counter() - t
    w.close()
    return elapsed / steps


def main():
    parser = argparse.ArgumentParser()
    parser.add_argument("--robots", type=int, default=1000)
    parser.add_argument("--steps", type=int, default=200)
    parser.add_argument("--repeats", type=int, default=5)
    args = parser.parse_args()

    lua, py = [], []
    for _ in range(args.repeats):
        lua.append(run_world(ROOT / "worlds" / "diffusion.yaml", args.robots, args.steps))
        py.append(run_world(ROOT / "worlds" / "python" / "diffusion_numpy.yaml", args.robots,
                            args.steps))
    lua_ms, py_ms = statistics.median(lua) * 1e3, statistics.median(py) * 1e3
    print(f"diffusion, {args.robots} robots, 1 thread, {args.steps} steps, median of "
          f"{args.repeats}: Lua controller {lua_ms:.2f} ms/step, numpy controller "
          f"{py_ms:.2f} ms/step ({lua_ms / py_ms:.2f}x)")

    spent = []

    def timed(robots):
        t = time.perf_counter()
        out = diffusion_numpy.control(robots)
        spent.append(time.perf_counter() - t)
        return out

    w = swarmsim.World(str(ROOT / "worlds" / "diffusion.yaml"), seed=1, threads=1,
                       set={"robots": args.robots}, controllers={"footbot": timed})
    w.step(args.steps)
    print(f"  numpy controller call alone (arrays read included): "
          f"{statistics.median(spent) * 1e6:.0f} us per step for {args.robots} robots")
    w.close()

    w = swarmsim.World(str(ROOT / "worlds" / "diffusion.yaml"), seed=1, threads=1,
                       set={"robots": 10000})
    out = np.empty((10000, 3))
    for label, call in (("out= (reused array)", lambda: w.poses(out=out)),
                        ("new array", lambda: w.poses())):
        samples = []
        for _ in range(7):
            t = time.perf_counter()
            for _ in range(1000):
                call()
            samples.append((time.perf_counter() - t) / 1000)
        print(f"poses of 10,000 robots, {label}: {statistics.median(samples) * 1e6:.1f} us per call")
    w.close()


if __name__ == "__main__":
    main()
