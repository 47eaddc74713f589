#!/usr/bin/env python3
"""The follow-up's convolution stack in PyTorch (kernels/benches/conv.rs does the same in ours):
its encoder's 4 Conv2d (kernel 4, stride 2, padding 1; 3->32->32->32->32, 64->4 px) and its
decoder's 4 ConvTranspose2d (32->32->32->32->3, 4->64 px), batch 64, each layer's forward pass,
input gradient and weight and bias gradients. Prints the median of --iters runs in ms."""
import argparse
import time

import torch

ap = argparse.ArgumentParser()
ap.add_argument("--threads", type=int, default=1)
ap.add_argument("--iters", type=int, default=20)
args = ap.parse_args()
torch.set_num_threads(args.threads)
torch.manual_seed(0)
B = 64
enc = [torch.nn.Conv2d(c, 32, 4, 2, 1) for c in (3, 32, 32, 32)]
dec = [torch.nn.ConvTranspose2d(32, c, 4, 2, 1) for c in (32, 32, 32, 3)]
enc_in = [torch.rand(B, c, s, s, requires_grad=True) for c, s in ((3, 64), (32, 32), (32, 16), (32, 8))]
dec_in = [torch.rand(B, 32, s, s, requires_grad=True) for s in (4, 8, 16, 32)]


def step():
    for layer, x in list(zip(enc, enc_in)) + list(zip(dec, dec_in)):
        y = layer(x)
        g = torch.ones_like(y)
        # Input, weight and bias gradients, as the Rust bench computes them.
        torch.autograd.grad(y, [x, layer.weight, layer.bias], g)


for _ in range(3):
    step()
times = []
for _ in range(args.iters):
    t0 = time.perf_counter()
    step()
    times.append((time.perf_counter() - t0) * 1000)
times.sort()
print(f"torch {torch.__version__} threads {args.threads}: median {times[len(times) // 2]:.2f} ms")
