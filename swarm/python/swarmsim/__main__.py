"""python3 -m swarmsim run WORLD [--steps N] [--seed S] [--threads T] [--set NAME=VALUE]...
                          [--out DIR] [--quiet] [--hash]

Runs a world from Python, for worlds whose models name a python_controller (which
the swarmsim program cannot run), with `swarmsim run`'s progress, summary table and,
with --out DIR, its summary.json and metrics.csv. Exit status: 0 done, 1 error while
running (the outputs of the steps that finished are kept), 2 bad input (a world that
does not load, a bad option), 128 + N for a stop signal N (Ctrl-C: 130).
"""

import argparse
import signal
import sys

from . import World, _swarmsim


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
    run.add_argument("--out", metavar="DIR",
                     help="write summary.json and metrics.csv to DIR (made if missing)")
    run.add_argument("--quiet", action="store_true",
                     help="no progress and no summary table (errors still go to stderr)")
    run.add_argument("--hash", action="store_true", help="print the final state hash")
    args = parser.parse_args(argv)

    overrides = {}
    for item in args.set:
        name, eq, value = item.partition("=")
        if not eq or not name:
            print(f"error: --set expects NAME=VALUE, got '{item}'", file=sys.stderr)
            return 2
        overrides[name] = _value(value)
    def bad_input(message):
        # As `swarmsim run`: the folder gets summary.json with status error,
        # the earlier run's outputs removed (README, "The outputs").
        print(f"error: {message}", file=sys.stderr)
        if args.out is not None:
            try:
                _swarmsim._write_load_failure(args.out, args.world, message)
            except ValueError as e:
                print(f"error: {e}", file=sys.stderr)
        return 2

    try:
        world = World(args.world, seed=args.seed, set=overrides, threads=args.threads)
    except (ValueError, TypeError) as e:
        return bad_input(str(e))
    steps = args.steps if args.steps is not None else world.default_steps
    if steps is None:
        world.close()
        return bad_input(f"{args.world} gives no duration: pass --steps N")
    try:
        world.run(steps, out_dir=args.out, quiet=args.quiet, hash=args.hash)
    except ValueError as e:  # --out is not a folder we can use
        print(f"error: {e}", file=sys.stderr)
        return 2
    except RuntimeError as e:
        print(f"error: {e}", file=sys.stderr)
        return 1
    except KeyboardInterrupt as e:
        if str(e):
            print(f"error: {e}", file=sys.stderr)
        return 128 + getattr(e, "signal", signal.SIGINT)
    finally:
        world.close()
    return 0


if __name__ == "__main__":
    sys.exit(main())
