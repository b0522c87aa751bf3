"""python3 -m swarmsim run WORLD [--steps N] [--seed S] [--threads T] [--set NAME=VALUE]... [--hash]

Runs a world from Python, for worlds whose models name a python_controller (which
the swarmsim program cannot run). Exit status: 0 done, 1 error while running,
2 bad input (a world that does not load, a bad option).
"""

import argparse
import sys

from . import World


def _value(text):
    for kind in (int, float):
        try:
            return kind(text)
        except ValueError:
            pass
    if text in ("true", "false"):
        return text == "true"
    return text


def main(argv=None):
    parser = argparse.ArgumentParser(prog="python3 -m swarmsim")
    sub = parser.add_subparsers(dest="command", required=True)
    run = sub.add_parser("run", help="run a world (Python controllers included)")
    run.add_argument("world")
    run.add_argument("--steps", type=int, help="steps to run (default: the world's duration)")
    run.add_argument("--seed", type=int)
    run.add_argument("--threads", type=int, default=0)
    run.add_argument("--set", action="append", default=[], metavar="NAME=VALUE")
    run.add_argument("--hash", action="store_true", help="print the final state hash")
    args = parser.parse_args(argv)

    overrides = {}
    for item in args.set:
        name, eq, value = item.partition("=")
        if not eq or not name:
            print(f"error: --set expects NAME=VALUE, got '{item}'", file=sys.stderr)
            return 2
        overrides[name] = _value(value)
    try:
        world = World(args.world, seed=args.seed, set=overrides, threads=args.threads)
    except (ValueError, TypeError) as e:
        print(f"error: {e}", file=sys.stderr)
        return 2
    steps = args.steps if args.steps is not None else world.default_steps
    if steps is None:
        print(f"error: {args.world} gives no duration: pass --steps N", file=sys.stderr)
        return 2
    try:
        world.step(steps)
    except RuntimeError as e:
        print(f"error: {e}", file=sys.stderr)
        return 1
    if args.hash:
        print(f"state-hash: {world.state_hash()}")
    world.close()
    return 0


if __name__ == "__main__":
    sys.exit(main())
