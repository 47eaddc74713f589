"""A representation learner written as a Python object, ranked by ugl-bench (numpy only).

    pip install ./python && cargo build --bin ugl
    python examples/python_learner_numpy.py [CAMPAIGN.toml]     # default: data/campaigns/quick.toml

`ugl_bench.compare` runs the object on the campaign's cells and repetitions (the same data sets
and exploration streams as every learner of that campaign) and writes the store
data/results/compare-py-projection; with the campaign's own results beside it (the paper's:
data/campaigns/paper.toml and data/results/paper) it prints the learner's summary page, ranked
against the paper's learners. Run it from the repository root.

The model: a Gaussian random projection of the pixels, seeded by the run's seed; the same model
as the program scripts/external_learners/random_projection.py, which `ugl compare --command`
runs through the protocol (python/tests/test_compare.py checks that both give the same bytes).
"""
import sys
from pathlib import Path

import numpy as np

import ugl_bench


class RandomProjection:
    """fit(images, latents, seed) and encode(images): all that compare asks of a learner."""

    def fit(self, images, latents, seed):
        rng = np.random.default_rng(seed)
        self.w = rng.standard_normal((images.shape[1], latents)) / np.sqrt(latents)

    def encode(self, images):
        return images.astype(np.float64) @ self.w


if __name__ == "__main__":
    config = sys.argv[1] if len(sys.argv) > 1 else "data/campaigns/quick.toml"
    ugl = Path("target/debug/ugl")
    result = ugl_bench.compare(
        RandomProjection(), name="py-projection", config=config, ugl=ugl if ugl.exists() else None
    )
    print(f"{len(result.manifests)} runs in {result.out}")
    print(result.page or "(no summary page: the campaign's own results are not beside the store)")
