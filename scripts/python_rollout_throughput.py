"""Throughput of the Python package's rollouts (issue: ugl-bench from Python, item 3).

Episodes per second on ArmBall (and ArmBalls, whose distractor makes the episodes run in order),
for:
  * `ugl_bench.rollout` on a batch, with rayon's pool at 1 and at 2 threads (one child process
    per setting: the pool's size is fixed when it starts);
  * a Python loop calling `ugl_bench.Env.rollout` once per episode;
  * the original code's ArmBall (explauto 1.3.0's DMP and DynamicEnvironment, executed from the
    PyPI sdist by scripts/original_fixtures.py), where that sdist can be fetched.
The settings alternate, ROUNDS times, so that they share the same minutes; the median is printed.

    python scripts/python_rollout_throughput.py [--episodes 20000] [--rounds 3] [--original 2000]

Needs the package installed (`pip install ./python`). Nothing else may run on the cores.
"""

import argparse
import json
import os
import statistics
import subprocess
import sys
import time
from pathlib import Path

import numpy as np

HERE = Path(__file__).resolve().parent


def batch_child(env, episodes, images):
    import ugl_bench

    p = ugl_bench.environment(env)["params"]
    x = np.random.default_rng(0).uniform(-1, 1, size=(episodes, p))
    ugl_bench.rollout(env, x[:100], images=images)  # warm the pool
    t = time.perf_counter()
    ugl_bench.rollout(env, x, seed=1, images=images)
    return episodes / (time.perf_counter() - t)


def batch(env, episodes, threads, images=False):
    code = (
        "import sys; sys.path.insert(0, %r); import python_rollout_throughput as m; "
        "print(m.batch_child(%r, %d, %r))" % (str(HERE), env, episodes, images)
    )
    out = subprocess.run(
        [sys.executable, "-c", code],
        env=dict(os.environ, RAYON_NUM_THREADS=str(threads)),
        check=True,
        capture_output=True,
        text=True,
    ).stdout
    return float(out.strip().splitlines()[-1])


def python_loop(env, episodes):
    import ugl_bench

    e = ugl_bench.Env(env, seed=1)
    x = np.random.default_rng(0).uniform(-1, 1, size=(episodes, e.params))
    t = time.perf_counter()
    for row in x:
        e.rollout(row)
    return episodes / (time.perf_counter() - t)


def original_env(sdist_dir):
    sys.path.insert(0, str(HERE))
    import original_fixtures as of

    of.load_explauto(of.fetch_sdist(sdist_dir))
    armball, _ = of.make_env_classes()
    return armball()


def original(env, episodes):
    x = np.random.default_rng(0).uniform(-1, 1, size=(episodes, 21))
    t = time.perf_counter()
    for row in x:
        env.update(row)
    return episodes / (time.perf_counter() - t)


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--episodes", type=int, default=20000)
    ap.add_argument("--rounds", type=int, default=3)
    ap.add_argument("--original", type=int, default=2000, help="episodes of the original code (0: skip it)")
    ap.add_argument("--sdist-dir", default="/tmp/explauto-1.3.0-sdist")
    args = ap.parse_args()
    orig = None
    if args.original:
        try:
            orig = original_env(args.sdist_dir)
        except Exception as e:  # the sdist could not be fetched or loaded: say so
            print(f"original code: not measured ({type(e).__name__}: {e})")
    settings = {
        "armball batch, 1 thread": lambda: batch("armball", args.episodes, 1),
        "armball batch, 2 threads": lambda: batch("armball", args.episodes, 2),
        "armball Python loop over Env.rollout": lambda: python_loop("armball", args.episodes),
        "armballs batch (in order: distractor)": lambda: batch("armballs", args.episodes, 2),
        "armball batch with pictures, 1 thread": lambda: batch("armball", args.episodes // 4, 1, True),
        "armball batch with pictures, 2 threads": lambda: batch("armball", args.episodes // 4, 2, True),
    }
    if orig is not None:
        settings["armball original code (explauto 1.3.0 + UGSL)"] = lambda: original(orig, args.original)
    rates = {k: [] for k in settings}
    for _ in range(args.rounds):
        for k, f in settings.items():
            rates[k].append(f())
    result = {k: statistics.median(v) for k, v in rates.items()}
    for k, v in result.items():
        print(f"{k:48s} {v:12.0f} episodes/s")
    print(json.dumps(result))


if __name__ == "__main__":
    main()
