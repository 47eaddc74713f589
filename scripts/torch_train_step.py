#!/usr/bin/env python3
"""PyTorch (CPU) side of the training-speed comparison: one training iteration of the paper's
dense AE, VAE or RFVAE, as `benchmark/benches/train_step.rs` times it in Rust (host and burn
engines). `scripts/train_step_side_by_side.sh` alternates the two and prints the ratio.

Same work per iteration: a batch of 100 images of 4900 pixels (disc images like the renderer's
balls), encoder 4900 -> H1 ReLU -> H2 ReLU -> heads, decoder d -> H2 ReLU -> H1 ReLU -> 4900
logits, loss = mean over the batch of the pixel-summed BCE with logits (+ the model's terms),
backward, element-wise gradient clipping to [-1, 1], the original's optimiser:
- ae: sigmoid latents; Adagrad (lr 1e-3, initial accumulator 0.1);
- vae: (mu, logvar), reparameterisation, analytic KL; Adam (lr 1e-3);
- rfvae: the VAE with 10 amortised radial flows (heads mu | logvar | c (10 d) | b (10) | a (10)),
  per-sample log-det, KL warm-up factor 1; Adam (lr 1e-3).
FLOPs are counted as in `ugl_bench::repr::neural::flops_per_iteration`: 3 x 2 m n k per dense
layer.

Usage: python3 scripts/torch_train_step.py [--model vae] [--hidden 1200 1200] [--latents 10]
       [--threads 1] [--iters 30]
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


FLOWS = 10


class DenseNet(torch.nn.Module):
    def __init__(self, model, dim, h1, h2, d):
        super().__init__()
        self.model, self.d = model, d
        p = {"ae": d, "vae": 2 * d, "rfvae": 2 * d + FLOWS * d + 2 * FLOWS}[model]
        self.enc = torch.nn.Sequential(
            torch.nn.Linear(dim, h1), torch.nn.ReLU(), torch.nn.Linear(h1, h2), torch.nn.ReLU()
        )
        self.head = torch.nn.Linear(h2, p)
        self.dec = torch.nn.Sequential(
            torch.nn.Linear(d, h2),
            torch.nn.ReLU(),
            torch.nn.Linear(h2, h1),
            torch.nn.ReLU(),
            torch.nn.Linear(h1, dim),
        )
        for m in self.modules():
            if isinstance(m, torch.nn.Linear):
                torch.nn.init.trunc_normal_(m.weight, std=1e-3, a=-2e-3, b=2e-3)
                torch.nn.init.zeros_(m.bias)

    def heads(self):
        return self.head.out_features

    def loss(self, x):
        d = self.d
        h = self.head(self.enc(x))
        bce = torch.nn.functional.binary_cross_entropy_with_logits
        if self.model == "ae":
            z = torch.sigmoid(h)
            return bce(self.dec(z), x, reduction="none").sum(1).mean()
        mu, logvar = h[:, :d], h[:, d : 2 * d]
        z = mu + torch.randn_like(mu) * torch.exp(0.5 * logvar)
        kl = -0.5 * (1 + logvar - mu**2 - logvar.exp()).sum(1)
        logdet = torch.zeros(x.shape[0])
        if self.model == "rfvae":
            c = h[:, 2 * d : 2 * d + FLOWS * d]
            b = h[:, 2 * d + FLOWS * d : 2 * d + FLOWS * d + FLOWS]
            a = h[:, 2 * d + FLOWS * d + FLOWS :]
            for k in range(FLOWS):
                ck = c[:, k * d : (k + 1) * d]
                ak = a[:, k : k + 1].abs()
                beta = torch.nn.functional.softplus(b[:, k : k + 1]) - ak
                diff = z - ck
                r = diff.pow(2).sum(1, keepdim=True).sqrt()
                hk = 1.0 / (ak + r)
                bh = beta * hk
                z = z + bh * diff
                t = (1 + bh).pow(d - 1) * (1 + bh - beta * r / (ak + r) ** 2)
                logdet = logdet + t.clamp(1e-4, 1e6).log().squeeze(1)
        rec = bce(self.dec(z), x, reduction="none").sum(1)
        return (rec + kl - logdet).mean()


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--model", choices=["ae", "vae", "rfvae"], default="vae")
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
    net = DenseNet(a.model, dim, h1, h2, d)
    if a.model == "ae":
        opt = torch.optim.Adagrad(net.parameters(), lr=1e-3, initial_accumulator_value=0.1)
    else:
        opt = torch.optim.Adam(net.parameters(), lr=1e-3, betas=(0.9, 0.999), eps=1e-8)
    macs = dim * h1 + h1 * h2 + h2 * net.heads() + d * h2 + h2 * h1 + h1 * dim
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
        f"torch {torch.__version__} CPU, {a.threads} thread(s), {a.model.upper()} "
        f"4900-{h1}-{h2}-{d}, batch {m}: "
        f"median {med * 1e3:.1f} ms/iteration over {a.iters} (min {min(times) * 1e3:.1f}), "
        f"{flops / med / 1e9:.1f} GFLOP/s; final loss {loss.item():.1f}"
    )


if __name__ == "__main__":
    main()
