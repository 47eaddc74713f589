#!/usr/bin/env python3
"""Example external representation learner for ugl-bench (protocol v1, numpy only).

A Gaussian random projection of the 4900 pixels to UGL_LATENTS dimensions, seeded by UGL_SEED,
so it is deterministic. It shows every part of the protocol (docs/external-learners.md):

  1. read UGL_TRAIN (float32, (n, 4900)), "fit", write UGL_TRAIN_LATENTS ((n, d)), print READY;
  2. answer each npy array (float32, (m, 4900)) read from stdin with an npy array (m, d) on stdout;
  3. exit 0 when stdin is closed.

Replace `fit` and `encode` with your model (PyTorch: torch.from_numpy(x), model.eval(),
torch.no_grad(), .cpu().numpy()).
"""
import ast
import os
import sys

import numpy as np

MAGIC = b"\x93NUMPY"


def read_exact(f, n, eof_ok=False):
    """Read exactly n bytes from a binary stream (a pipe may return fewer per read).
    Returns None on end of stream before the first byte if eof_ok."""
    chunks, got = [], 0
    while got < n:
        b = f.read(n - got)
        if not b:
            if got == 0 and eof_ok:
                return None
            raise EOFError("stream ended in the middle of an npy array")
        chunks.append(b)
        got += len(b)
    return b"".join(chunks)


def read_npy(f):
    """Read one npy array from a binary stream; None at end of stream."""
    magic = read_exact(f, 6, eof_ok=True)
    if magic is None:
        return None
    if magic != MAGIC:
        raise ValueError(f"not an npy array: {magic!r}")
    major, _minor = read_exact(f, 2)
    hlen_bytes = read_exact(f, 2 if major == 1 else 4)
    hlen = int.from_bytes(hlen_bytes, "little")
    raw = read_exact(f, hlen)
    parsed = _HEADERS.get(raw)
    if parsed is None:  # parse each distinct header once (saves ~25 us per request)
        header = ast.literal_eval(raw.decode("latin1"))
        shape = tuple(header["shape"])
        order = "F" if header["fortran_order"] else "C"
        parsed = _HEADERS[raw] = (np.dtype(header["descr"]), shape, int(np.prod(shape)), order)
    dtype, shape, count, order = parsed
    data = read_exact(f, count * dtype.itemsize) if count else b""
    return np.frombuffer(data, dtype=dtype).reshape(shape, order=order)


_HEADERS = {}


def write_npy(f, a):
    """Write one npy array (version 1.0, C order) to a binary stream and flush it."""
    a = np.ascontiguousarray(a)
    header = "{'descr': %r, 'fortran_order': False, 'shape': %r, }" % (a.dtype.str, a.shape)
    pad = -(10 + len(header) + 1) % 64
    header = (header + " " * pad + "\n").encode("latin1")
    f.write(MAGIC + b"\x01\x00" + len(header).to_bytes(2, "little") + header)
    f.write(a.tobytes())
    f.flush()


def fit(train, latents, seed):
    """The 'model': a (4900, d) Gaussian matrix scaled by 1/sqrt(d)."""
    rng = np.random.default_rng(seed)
    return rng.standard_normal((train.shape[1], latents)) / np.sqrt(latents)


def encode(model, x):
    """x: float32 (m, 4900), pixel (px, py) at column px*70 + py. Returns float64 (m, d)."""
    return x.astype(np.float64) @ model


def main():
    if os.environ.get("UGL_PROTOCOL") != "1":
        sys.exit(f"unsupported UGL_PROTOCOL {os.environ.get('UGL_PROTOCOL')!r} (this program speaks 1)")
    # stdout carries the protocol only: keep its binary handle, send every print() to stderr.
    out = sys.stdout.buffer
    sys.stdout = sys.stderr
    inp = sys.stdin.buffer

    train = np.load(os.environ["UGL_TRAIN"])
    latents = int(os.environ["UGL_LATENTS"])
    seed = int(os.environ["UGL_SEED"])
    model = fit(train, latents, seed)
    np.save(os.environ["UGL_TRAIN_LATENTS"], encode(model, train))
    print(f"random projection: {train.shape[0]} images -> {latents} dims (seed {seed})")
    out.write(b"READY\n")
    out.flush()

    while True:
        x = read_npy(inp)
        if x is None:  # stdin closed: shut down
            return
        write_npy(out, encode(model, x))


if __name__ == "__main__":
    main()
