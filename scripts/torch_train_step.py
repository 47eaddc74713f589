#!/usr/bin/env python3
"""PyTorch (CPU) side of the training-speed comparison (issue 4): one training iteration of the
paper's dense VAE, as `benchmark/benches/train_step.rs` times it in Rust on burn's flex backend.

Same work per iteration: a batch of 100 images of 4900 pixels (disc images like the renderer's
balls), encoder 4900 -> H1 ReLU -> H2 ReLU -> (mu, logvar) of d latents, reparameterisation,
decoder d -> H2 ReLU -> H1 ReLU -> 4900 logits, loss = mean over the batch of (pixel-summed BCE
with logits + analytic KL), backward, element-wise gradient clipping to [-1, 1], Adam (lr 1e-3).
FLOPs are counted as in `ugl_bench::repr::neural::flops_per_iteration`: 3 x 2 m n k per dense
layer.

Usage: python3 scripts/torch_train_step.py [--hidden 1200 1200] [--latents 10] [--threads 1]
       [--iters 30]
Needs torch; not used by CI or tests.
"""

import argparse
import statistics
import time

import numpy as np

try:
    import torch
except ImportError as e:  # pragma: no cover
    raise SystemExit(f"torch is not installed ({e}); this comparison is optional")


def disc_images(n, rng):
    """n 70x70 images, each a filled disc of radius ~5.6 px at a random position."""
    ys, xs = np.mgrid[0:70, 0:70]
    out = np.zeros((n, 4900), dtype=np.float32)
    for i in range(n):
        cx, cy = rng.uniform(0, 70, size=2)
        out[i] = (((xs - cx) ** 2 + (ys - cy) ** 2) <= 5.6**2).astype(np.float32).ravel()
    return out


class DenseVae(torch.nn.Module):
    def __init__(self, dim, h1, h2, d):
        super().__init__()
        self.enc = torch.nn.Sequential(
            torch.nn.Linear(dim, h1), torch.nn.ReLU(), torch.nn.Linear(h1, h2), torch.nn.ReLU()
        )
        self.head = torch.nn.Linear(h2, 2 * d)
        self.dec = torch.nn.Sequential(
            torch.nn.Linear(d, h2),
            torch.nn.ReLU(),
            torch.nn.Linear(h2, h1),
            torch.nn.ReLU(),
            torch.nn.Linear(h1, dim),
        )
        self.d = d
        for m in self.modules():
            if isinstance(m, torch.nn.Linear):
                torch.nn.init.trunc_normal_(m.weight, std=1e-3, a=-2e-3, b=2e-3)
                torch.nn.init.zeros_(m.bias)

    def loss(self, x):
        h = self.head(self.enc(x))
        mu, logvar = h[:, : self.d], h[:, self.d :]
        z = mu + torch.randn_like(mu) * torch.exp(0.5 * logvar)
        logits = self.dec(z)
        rec = torch.nn.functional.binary_cross_entropy_with_logits(logits, x, reduction="none").sum(1)
        kl = -0.5 * (1 + logvar - mu**2 - logvar.exp()).sum(1)
        return (rec + kl).mean()


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--hidden", type=int, nargs=2, default=[1200, 1200])
    ap.add_argument("--latents", type=int, default=10)
    ap.add_argument("--threads", type=int, default=1)
    ap.add_argument("--iters", type=int, default=30)
    ap.add_argument("--batch", type=int, default=100)
    a = ap.parse_args()
    torch.set_num_threads(a.threads)
    torch.manual_seed(0)
    rng = np.random.default_rng(0)
    data = torch.from_numpy(disc_images(1000, rng))
    h1, h2 = a.hidden
    d, dim, m = a.latents, 4900, a.batch
    net = DenseVae(dim, h1, h2, d)
    opt = torch.optim.Adam(net.parameters(), lr=1e-3, betas=(0.9, 0.999), eps=1e-8)
    macs = dim * h1 + h1 * h2 + h2 * 2 * d + d * h2 + h2 * h1 + h1 * dim
    flops = 3 * 2 * m * macs
    times = []
    for it in range(a.iters + 5):
        idx = torch.from_numpy(rng.permutation(1000)[:m])
        t0 = time.perf_counter()
        x = data[idx]
        opt.zero_grad(set_to_none=True)
        loss = net.loss(x)
        loss.backward()
        for p in net.parameters():
            p.grad.clamp_(-1.0, 1.0)
        opt.step()
        if it >= 5:  # warm-up iterations are not timed
            times.append(time.perf_counter() - t0)
    med = statistics.median(times)
    print(
        f"torch {torch.__version__} CPU, {a.threads} thread(s), VAE 4900-{h1}-{h2}-{d}, batch {m}: "
        f"median {med * 1e3:.1f} ms/iteration over {a.iters} (min {min(times) * 1e3:.1f}), "
        f"{flops / med / 1e9:.1f} GFLOP/s; final loss {loss.item():.1f}"
    )


if __name__ == "__main__":
    main()
