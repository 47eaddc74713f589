"""A PyTorch auto-encoder as a Python object, ranked by ugl-bench (skipped without torch).

    pip install ./python torch && cargo build --bin ugl
    python examples/python_learner_torch.py [CAMPAIGN.toml]     # default: data/campaigns/quick.toml

The learner trains a small dense auto-encoder on the campaign's training pictures, seeded by the
run's seed, and encodes with the encoder's output, deterministically (ugl-bench caches each
picture's encoding within a run, so the same picture must give the same latents). Run it from
the repository root; the store is data/results/compare-py-torch-ae.
"""
import sys
from pathlib import Path

import numpy as np

import ugl_bench

try:
    import torch
except ImportError:
    torch = None


class TorchAutoEncoder:
    def __init__(self, hidden=256, iterations=300, batch=100, lr=1e-3):
        self.hidden, self.iterations, self.batch, self.lr = hidden, iterations, batch, lr

    def fit(self, images, latents, seed):
        torch.manual_seed(seed)
        torch.use_deterministic_algorithms(True)
        x = torch.from_numpy(np.asarray(images, dtype=np.float32))
        d = x.shape[1]
        self.encoder = torch.nn.Sequential(
            torch.nn.Linear(d, self.hidden), torch.nn.ReLU(), torch.nn.Linear(self.hidden, latents)
        )
        decoder = torch.nn.Sequential(
            torch.nn.Linear(latents, self.hidden), torch.nn.ReLU(), torch.nn.Linear(self.hidden, d)
        )
        params = list(self.encoder.parameters()) + list(decoder.parameters())
        opt = torch.optim.Adam(params, lr=self.lr)
        gen = torch.Generator().manual_seed(seed)
        for step in range(self.iterations):
            idx = torch.randint(0, x.shape[0], (self.batch,), generator=gen)
            loss = torch.nn.functional.binary_cross_entropy_with_logits(decoder(self.encoder(x[idx])), x[idx])
            opt.zero_grad()
            loss.backward()
            opt.step()
            if step % 100 == 0:
                print(f"step {step}: loss {loss.item():.4f}")  # to stderr: stdout is the protocol's
        self.encoder.eval()

    def encode(self, images):
        with torch.no_grad():
            return self.encoder(torch.from_numpy(np.asarray(images, dtype=np.float32))).double().numpy()


if __name__ == "__main__":
    if torch is None:
        print("torch is not installed (pip install torch): the PyTorch example is skipped")
        sys.exit(0)
    config = sys.argv[1] if len(sys.argv) > 1 else "data/campaigns/quick.toml"
    ugl = Path("target/debug/ugl")
    result = ugl_bench.compare(
        TorchAutoEncoder(), name="py-torch-ae", config=config, ugl=ugl if ugl.exists() else None
    )
    print(f"{len(result.manifests)} runs in {result.out}")
    print(result.page or "(no summary page: the campaign's own results are not beside the store)")
