#!/usr/bin/env python3
"""PyTorch (CPU) side of the follow-up's training-speed comparison: one training iteration of
the authors' convolutional beta-VAE, as `benchmark/benches/conv_step.rs` times it in Rust
(`scripts/conv_side_by_side.sh step` alternates the two and prints the ratio).

The same work per iteration: a batch of 64 RGB pictures of 64x64 (two coloured discs on black,
values in [0, 1]); encoder 4 x [Conv2d 32, kernel 4, stride 2, padding 1, ReLU] -> 512 -> 256 ReLU
-> 256 ReLU -> 20 (mean | log-variance); reparameterisation; decoder 10 -> 256 ReLU -> 512 ReLU ->
32x4x4 -> 3 x [ConvTranspose2d 32, ReLU] -> ConvTranspose2d 3 (logits); loss = BCE with logits
summed over pixels and channels, averaged over the batch, + c beta |KL - C| (beta 4, C and c mid
ramp); backward; torch.optim.Adam (lr 1e-3).

Usage: python3 scripts/torch_conv_vae_step.py [--threads 1] [--iters 30]
Needs torch and numpy; not used by CI or tests.
"""

import argparse
import statistics
import time

import numpy as np

try:
    import torch
    from torch import nn
except ImportError as e:  # pragma: no cover
    raise SystemExit(f"torch is not installed ({e}); this comparison is optional")

B, D = 64, 10


def pictures(n, rng):
    ys, xs = np.mgrid[0:64, 0:64]
    out = np.zeros((n, 3, 64, 64), dtype=np.float32)
    for i in range(n):
        for (r, g, b), radius in (((1, 1, 0), 5.4), ((0, 0, 1), 4.8)):
            cx, cy = rng.uniform(4, 60, size=2)
            disc = (((xs - cx) ** 2 + (ys - cy) ** 2) <= radius**2).astype(np.float32)
            for c, v in enumerate((r, g, b)):
                if v:
                    out[i, c] = np.maximum(out[i, c], disc)
    return out


class ConvVAE(nn.Module):
    def __init__(self):
        super().__init__()
        self.enc = nn.Sequential(
            nn.Conv2d(3, 32, 4, 2, 1), nn.ReLU(),
            nn.Conv2d(32, 32, 4, 2, 1), nn.ReLU(),
            nn.Conv2d(32, 32, 4, 2, 1), nn.ReLU(),
            nn.Conv2d(32, 32, 4, 2, 1), nn.ReLU(),
        )
        self.fc = nn.Sequential(
            nn.Linear(512, 256), nn.ReLU(), nn.Linear(256, 256), nn.ReLU(), nn.Linear(256, 2 * D)
        )
        self.dfc = nn.Sequential(nn.Linear(D, 256), nn.ReLU(), nn.Linear(256, 512), nn.ReLU())
        self.dec = nn.Sequential(
            nn.ConvTranspose2d(32, 32, 4, 2, 1), nn.ReLU(),
            nn.ConvTranspose2d(32, 32, 4, 2, 1), nn.ReLU(),
            nn.ConvTranspose2d(32, 32, 4, 2, 1), nn.ReLU(),
            nn.ConvTranspose2d(32, 3, 4, 2, 1),
        )

    def forward(self, x):
        h = self.fc(self.enc(x).view(-1, 512))
        mu, logvar = h[:, :D], h[:, D:]
        z = mu + torch.randn_like(mu) * torch.exp(0.5 * logvar)
        return self.dec(self.dfc(z).view(-1, 32, 4, 4)), mu, logvar


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--threads", type=int, default=1)
    ap.add_argument("--iters", type=int, default=30)
    args = ap.parse_args()
    torch.set_num_threads(args.threads)
    torch.manual_seed(0)
    x = torch.from_numpy(pictures(B, np.random.default_rng(0)))
    net = ConvVAE()
    opt = torch.optim.Adam(net.parameters(), lr=1e-3)
    beta, capacity, warm = 4.0, 6.0, 0.5

    def step():
        opt.zero_grad()
        logits, mu, logvar = net(x)
        rec = nn.functional.binary_cross_entropy_with_logits(logits, x, reduction="sum") / B
        kl = (-0.5 * (1 + logvar - mu.pow(2) - logvar.exp()).sum(1)).mean()
        loss = rec + warm * beta * (kl - capacity).abs()
        loss.backward()
        opt.step()
        return loss.item()

    for _ in range(3):
        step()
    times = []
    for _ in range(args.iters):
        t0 = time.perf_counter()
        step()
        times.append((time.perf_counter() - t0) * 1000)
    print(
        f"torch {torch.__version__} threads {args.threads}: "
        f"median {statistics.median(times):.2f} ms"
    )


if __name__ == "__main__":
    main()
