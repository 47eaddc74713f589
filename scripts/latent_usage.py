#!/usr/bin/env python3
"""How a goal space uses its latents, from the files of `ugl embed` (numpy only).

For each OUT.npy written by `ugl embed --out OUT.npy` (the latents of the training images, and
beside it OUT.grid.npy and OUT.grid_states.npy, a GRID x GRID lattice of object positions):

- active latents: those whose standard deviation over the training images is above 0.2 (a VAE's
  collapsed latents stay near the prior's mean whatever the image: their spread is about 0.05);
- evenness of the map from position to latents: over the pairs of neighbouring lattice points
  inside the disk of radius sqrt(0.95), the latent distance's median, its coefficient of
  variation (sd / mean) and its largest value over the median. A map that stretches some regions
  of the disk far more than others has a high variation.

    ugl embed --env armball --learner vae --seed 0 --profile paper --out DIR/short.s0.npy
    python3 scripts/latent_usage.py DIR/short.s0.npy [...]
"""
import sys

import numpy as np


def usage(path, threshold=0.2, radius2=0.95):
    stem = path[:-4] if path.endswith(".npy") else path
    z = np.load(path)
    grid = np.load(stem + ".grid.npy")
    states = np.load(stem + ".grid_states.npy")
    sd = np.sort(z.std(axis=0))[::-1]
    g = int(round(np.sqrt(len(grid))))
    pos = states[:, :2].reshape(g, g, 2)
    lat = grid.reshape(g, g, -1)
    inside = (pos ** 2).sum(-1) <= radius2
    d = []
    for i in range(g):
        for j in range(g):
            for a, b in ((i, j + 1), (i + 1, j)):
                if a < g and b < g and inside[i, j] and inside[a, b]:
                    d.append(np.linalg.norm(lat[i, j] - lat[a, b]))
    d = np.asarray(d)
    return int((sd > threshold).sum()), sd, np.median(d), d.std() / d.mean(), d.max() / np.median(d)


def main():
    if len(sys.argv) < 2:
        sys.exit(__doc__)
    skip = (".grid.npy", ".states.npy", ".grid_states.npy")
    for p in sys.argv[1:]:
        if p.endswith(skip):  # the lattice files beside a latents file (a shell glob)
            continue
        active, sd, med, cv, top = usage(p)
        print(f"{p}: {active} of {len(sd)} latents active (sd {' '.join(f'{v:.2f}' for v in sd)}); "
              f"neighbour distance median {med:.3f}, cv {cv:.2f}, max/median {top:.1f}")


if __name__ == "__main__":
    main()
