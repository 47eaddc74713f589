#!/usr/bin/env python3
"""Example external representation learner for ugl-bench (protocol v1, numpy only).

A Gaussian random projection of the 4900 pixels to UGL_LATENTS dimensions, seeded by UGL_SEED,
so it is deterministic. The protocol (docs/external-learners.md) is handled by the helper module
`ugl_protocol.py` beside this file: read the training images, fit, write the training latents,
print `READY fit_s=...`, answer encode requests until stdin closes.

Replace `fit` and `encode` with your model (PyTorch: torch.from_numpy(x), model.eval(),
torch.no_grad(), .cpu().numpy()).
"""
import os
import sys

import numpy as np

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from ugl_protocol import serve  # noqa: E402


def fit(train, latents, seed):
    """The 'model': a (4900, d) Gaussian matrix scaled by 1/sqrt(d)."""
    print(f"random projection: {train.shape[0]} images -> {latents} dims (seed {seed})")
    rng = np.random.default_rng(seed)
    return rng.standard_normal((train.shape[1], latents)) / np.sqrt(latents)


def encode(model, x):
    """x: float32 (m, 4900), pixel (px, py) at column px*70 + py. Returns float64 (m, d)."""
    return x.astype(np.float64) @ model


if __name__ == "__main__":
    serve(fit, encode)
