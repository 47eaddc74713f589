#!/usr/bin/env python3
"""The follow-up's exploration ratio of runs in a results directory, from their outcomes files.

The fraction of the cells of a G x G grid over [-1, 1]^2 that hold at least one final ball
position among a run's first N outcomes (the follow-up's measure, `exploration_30`: G = 30, read
at 9666 rollouts; `data/paper/followup_authors_curves.csv` holds the authors' values). Prints,
per algorithm of the directory's `armballs-corl` runs, the number of runs, the mean and standard
deviation and every run's ratio. Needs numpy and pyarrow.

    python3 scripts/exploration_ratio.py DIR [DIR...] [--grid 30] [--rollouts 9666]
"""
import argparse
import collections
import glob
import os
import sys

import numpy as np
import pyarrow.parquet as pq


def ratio(path, rollouts, grid):
    t = pq.read_table(path, columns=["index", "x", "y"])
    keep = t.column("index").to_numpy() <= rollouts
    cell = lambda v: np.clip(np.floor((v[keep] + 1.0) / 2.0 * grid).astype(int), 0, grid - 1)
    x, y = cell(t.column("x").to_numpy()), cell(t.column("y").to_numpy())
    return len(set(zip(x.tolist(), y.tolist()))) / (grid * grid)


def main():
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("dirs", nargs="+")
    p.add_argument("--grid", type=int, default=30)
    p.add_argument("--rollouts", type=int, default=9666,
                   help="outcomes with index <= this (the initial state is index 0)")
    a = p.parse_args()
    for d in a.dirs:
        by_algo = collections.defaultdict(list)
        for f in sorted(glob.glob(os.path.join(d, "armballs-corl.*.outcomes.parquet"))):
            algo = os.path.basename(f).split(".")[1]
            by_algo[algo].append(ratio(f, a.rollouts, a.grid))
        if not by_algo:
            sys.exit(f"{d}: no armballs-corl outcomes files")
        for algo, r in sorted(by_algo.items()):
            sd = np.std(r, ddof=1) if len(r) > 1 else float("nan")
            runs = " ".join(f"{v:.3f}" for v in r)
            print(f"{d} {algo}: {len(r)} runs, mean {np.mean(r):.3f}, sd {sd:.3f}: {runs}")


if __name__ == "__main__":
    main()
