"""The ugl-bench external-learner protocol, version 1, for Python learners (numpy only).

`from ugl_bench.protocol import serve` once the package is installed; without it, copy this file
beside your learner (it needs only numpy; `scripts/external_learners/ugl_protocol.py` loads it by
path). Hand it two functions; it does all the I/O:

    from ugl_bench.protocol import serve

    def fit(train, latents, seed):        # train: float32 (n, 4900); returns your model
        ...
    def encode(model, x):                 # x: float32 (m, 4900); returns (m, latents)
        ...
    serve(fit, encode)                    # optional: prior=lambda model: (mean, std)

`serve` checks UGL_PROTOCOL, reserves stdout for the protocol (print() goes to stderr), reads
UGL_TRAIN, times your fit, writes UGL_TRAIN_LATENTS (and UGL_PRIOR when `prior` is given),
prints `READY fit_s=<seconds>`, then answers every npy request on stdin until stdin closes.
The specification is docs/external-learners.md.
"""
import ast
import os
import sys
import time

import numpy as np

MAGIC = b"\x93NUMPY"
_HEADERS = {}


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
    """Read one npy array from a binary stream; None at end of stream. (`np.load` cannot: it
    needs a seekable file.)"""
    magic = read_exact(f, 6, eof_ok=True)
    if magic is None:
        return None
    if magic != MAGIC:
        raise ValueError(f"not an npy array: {magic!r}")
    major, _minor = read_exact(f, 2)
    hlen = int.from_bytes(read_exact(f, 2 if major == 1 else 4), "little")
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


def write_npy(f, a):
    """Write one npy array (version 1.0, C order) to a binary stream and flush it."""
    a = np.ascontiguousarray(a)
    header = "{'descr': %r, 'fortran_order': False, 'shape': %r, }" % (a.dtype.str, a.shape)
    pad = -(10 + len(header) + 1) % 64
    header = (header + " " * pad + "\n").encode("latin1")
    f.write(MAGIC + b"\x01\x00" + len(header).to_bytes(2, "little") + header)
    f.write(a.tobytes())
    f.flush()


def serve(fit, encode, prior=None):
    """Run the whole protocol with `fit(train, latents, seed) -> model` and
    `encode(model, x) -> (m, latents)`; `prior(model) -> (mean, std)` writes UGL_PRIOR."""
    if os.environ.get("UGL_PROTOCOL") != "1":
        sys.exit(f"unsupported UGL_PROTOCOL {os.environ.get('UGL_PROTOCOL')!r} (this program speaks 1)")
    out = sys.stdout.buffer  # the protocol channel
    sys.stdout = sys.stderr  # every print(), and libraries that print, now go to stderr
    inp = sys.stdin.buffer
    train = np.load(os.environ["UGL_TRAIN"])
    latents = int(os.environ["UGL_LATENTS"])
    seed = int(os.environ["UGL_SEED"])
    t0 = time.perf_counter()
    model = fit(train, latents, seed)
    fit_s = time.perf_counter() - t0
    np.save(os.environ["UGL_TRAIN_LATENTS"], np.asarray(encode(model, train), dtype=np.float64))
    if prior is not None:
        mean, std = prior(model)
        np.save(os.environ["UGL_PRIOR"], np.stack([np.asarray(mean, np.float64), np.asarray(std, np.float64)]))
    out.write(f"READY fit_s={fit_s:.6f}\n".encode())
    out.flush()
    while (x := read_npy(inp)) is not None:  # stdin closed: shut down
        write_npy(out, encode(model, x))


def serve_object(learner):
    """Run the whole protocol for a learner object: `learner.fit(train, latents, seed)` (its
    return value is ignored: the object is the model), `learner.encode(x) -> (m, latents)`, and,
    if it has one, `learner.prior() -> (mean, std)` for UGL_PRIOR (`ugl_bench.compare`'s
    learners)."""
    for method in ("fit", "encode"):
        if not callable(getattr(learner, method, None)):
            sys.exit(f"the learner {learner!r} has no {method}() method")
    prior = getattr(learner, "prior", None)
    serve(
        lambda train, latents, seed: learner.fit(train, latents, seed),
        lambda _model, x: learner.encode(x),
        prior=(lambda _model: prior()) if callable(prior) else None,
    )
