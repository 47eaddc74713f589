#!/usr/bin/env python3
"""The follow-up's authors' exploration-ratio curves, from their figure data.

Writes `data/paper/followup_authors_curves.csv` (columns algorithm, epoch, count, mean, std) from
`results/armballs_dataset.pkl` of their repository (flowersteam/Curiosity_Driven_Goal_Exploration),
the data behind their comparison figure: per run and per point (0, 333, ..., 9666 rollouts) the
exploration ratio `exploration_30`. We take their numbers, never their code.

Which runs: exploration noise 0.05 and object size 0.1, as their notebook filters them. Their EFR
runs were made at two interest windows (500 and 1000) with the same 15 seeds: the flat ones
(RGE-EFR) are exact duplicates (one module has no choice to make) and the modular ones (MGE-EFR)
are paired, so only window 1000, the window of our `followup` campaign, is kept (with
`--pool-windows`, both, as an earlier version of the file had them). RPE pools its 20 runs at
distractor noise 0.1 and its 20 at 0.5. `std` is the sample standard deviation (n - 1).

    python3 scripts/followup_authors_curves.py THEIR_REPO/results/armballs_dataset.pkl \\
        > data/paper/followup_authors_curves.csv

Needs pandas (which reads their 2018 pickle).
"""
import argparse
import sys

import pandas as pd

ORDER = ["MGE-EFR", "MGE-VAE", "MGE-betaVAE", "RGE-EFR", "RGE-VAE", "RGE-betaVAE", "RPE"]


def main():
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("pkl")
    p.add_argument("--pool-windows", action="store_true",
                   help="keep the EFR runs of both interest windows (500 and 1000)")
    a = p.parse_args()
    df = pd.read_pickle(a.pkl)
    df = df[(df["explo_noise_sdev"] == 0.05) & (df["object_size"] == 0.1)]
    if not a.pool_windows:
        efr = df["algorithm"].isin(["MGE-EFR", "RGE-EFR"])
        df = df[~efr | (df["win_size"] == 1000.0)]
    missing = set(ORDER) - set(df["algorithm"])
    if missing:
        sys.exit(f"{a.pkl}: no runs of {sorted(missing)}")
    out = sys.stdout
    out.write("algorithm,epoch,count,mean,std\n")
    for algo in ORDER:
        runs = df[df["algorithm"] == algo]
        for epoch, g in sorted(runs.groupby("epoch")["exploration_30"], key=lambda t: t[0]):
            v = g.astype(float)
            out.write(f"{algo},{float(epoch)!r},{len(v)},{float(v.mean())!r},{float(v.std(ddof=1))!r}\n")


if __name__ == "__main__":
    main()
