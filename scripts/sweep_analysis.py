"""Reads a sweep's results database with Python's sqlite3 and prints, for each value of
one parameter, the mean and standard deviation of a final metric over seeds.

    build/swarmsim sweep worlds/diffusion.yaml --param robots=20,40 --seeds 3 --steps 100 --db d.db
    /usr/bin/python3 scripts/sweep_analysis.py d.db --param robots --metric mean_nearest_neighbor_distance

Tables (README.md, "Sweeps"): runs (one row per run: status, seed, wall_s, state_hash),
run_params (run, name, value), final_metrics (run, metric, value), series (run, metric,
step, time, value).
"""

import argparse
import math
import sqlite3
import sys


def summarise(db, param, metric):
    """[(parameter value, runs, mean, std)] over the runs that finished ok."""
    con = sqlite3.connect(f"file:{db}?mode=ro", uri=True)
    rows = con.execute(
        """SELECT p.value, m.value FROM runs r
           JOIN run_params p ON p.run = r.id AND p.name = ?
           JOIN final_metrics m ON m.run = r.id AND m.metric = ?
           WHERE r.status = 'ok' AND m.value IS NOT NULL""", (param, metric)).fetchall()
    con.close()
    groups = {}
    for value, x in rows:
        groups.setdefault(value, []).append(x)

    def key(v):
        try:
            return (0, float(v), v)
        except ValueError:
            return (1, 0.0, v)

    out = []
    for value in sorted(groups, key=key):
        xs = groups[value]
        mean = sum(xs) / len(xs)
        std = math.sqrt(sum((x - mean) ** 2 for x in xs) / (len(xs) - 1)) if len(xs) > 1 else 0.0
        out.append((value, len(xs), mean, std))
    return out


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("db")
    parser.add_argument("--param", required=True)
    parser.add_argument("--metric", required=True)
    args = parser.parse_args()
    try:
        table = summarise(args.db, args.param, args.metric)
    except sqlite3.Error as e:
        print(f"error: {args.db}: {e}", file=sys.stderr)
        return 2
    if not table:
        print(f"error: {args.db} has no finished run with parameter '{args.param}' "
              f"and final metric '{args.metric}'", file=sys.stderr)
        return 2
    print(f"{args.param}\truns\tmean {args.metric}\tstd")
    for value, n, mean, std in table:
        print(f"{value}\t{n}\t{mean:.6g}\t{std:.3g}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
