#!/usr/bin/env python3
"""Reference outputs from the follow-up's own code, as test fixtures for our port of its ArmBalls.

The follow-up (Laversanne-Finot, Pere, Oudeyer, CoRL 2018) published its code as the package
`latentgoalexplo` of flowersteam/Curiosity_Driven_Goal_Exploration (GPL-3.0). None of it is copied
here: this script imports it from a checkout given with --cdge, runs it, and writes what it
computed to benchmark/tests/fixtures/cdge_armballs.json:

  basis      the RbfController's 50 x 7 radial basis table (n_timesteps 50, n_rbf 7, sdev 10)
  rollouts   MyArmBallsObserved episodes as their explorer runs them (reset, then act(theta)),
             with the environment settings of their plotted runs (mge_representation.py,
             run_experiments: object size 0.1, distractor noise 0.1, 64 x 64 RGB, no arm):
             theta (49), the 50 x 2 standard normal draws of the distractor's walk, and the
             final state (arm pose, hand, distractor, ball) and whether the ball was caught
  images     the observer's final frame (ball drawn with radius 0.17, distractor 0.15) for some
             rollouts, and frames of the "observation phase" renderer (ArmBallsRenderer with the
             environment settings, so the ball is drawn with the physical size 0.1) of uniform
             random states; as the 8-bit RGB values cairo drew (the float image is their
             min-max normalisation, checked here to be value / 255)

Usage (see scripts/README-fixtures.md):
  git clone https://github.com/flowersteam/Curiosity_Driven_Goal_Exploration cdge
  git -C cdge checkout fafa7992b2b0f14b5544e3729440d529d5279224
  pip install numpy scipy gizeh matplotlib   # gizeh needs the cairo library (Debian: libcairo2)
  python3 scripts/followup_fixtures.py --cdge cdge

The three source files the fixtures depend on are checked against their SHA-256 before anything
runs, so a fixture always comes from the commit named in it.
"""

import argparse
import base64
import hashlib
import json
import os
import platform
import sys

import numpy as np

REPO_ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
OUT = os.path.join(REPO_ROOT, "benchmark", "tests", "fixtures", "cdge_armballs.json")

CDGE_REPO = "flowersteam/Curiosity_Driven_Goal_Exploration"
CDGE_COMMIT = "fafa7992b2b0f14b5544e3729440d529d5279224"
SOURCES = {
    "latentgoalexplo/environments/armballs.py":
        "8017befdf96d0eb8ec7a17b820b79335841e92d331e8128a0f57e48eeb342108",
    "latentgoalexplo/actors/controllers.py":
        "1ab6d317d3600347fa3c11d4fa3912dfd5f051f3b300c75fbc510eed1a16d804",
    "latentgoalexplo/environments/utils.py":
        "ac46ccb9d8cd46537a7b65d87995c03cae2d517b2ba1c8832d71cb562cf0eb11",
}

# The environment settings of their plotted runs (mge_representation.py, run_experiments, and the
# notebook's filter: object size 0.1, distractor noise 0.1).
ENV_CONFIG = dict(
    arm_lengths=np.array([0.3, 0.2, 0.2, 0.1, 0.1, 0.05, 0.05]),
    object_size=0.1, distract_size=0.15, distract_noise=0.1, env_noise=0.0,
    n_rbf=7, sdev=10.0, width=64, height=64, rgb=True, n_timesteps=50, render_arm=False,
    render=False,
)

SEED_RANDOM = 20180701     # random thetas, as their RPE draws them (uniform in [-1, 1]^49)
SEED_CAUGHT = 20180702     # stream searched for thetas that catch the ball
SEED_OBSERVATION = 20180703  # observation-phase states
N_RANDOM = 100
N_CAUGHT = 40
N_ROLLOUT_IMAGES = 12
N_OBSERVATION_IMAGES = 8


def check_sources(root):
    for rel, want in SOURCES.items():
        path = os.path.join(root, rel)
        with open(path, "rb") as f:
            got = hashlib.sha256(f.read()).hexdigest()
        if got != want:
            sys.exit(f"{path}: sha256 {got}, expected {want} (commit {CDGE_COMMIT})")


class RecordedNormal:
    """Stands in for np.random.randn while an episode runs, and keeps what it returned."""

    def __init__(self, original):
        self.original = original
        self.draws = []

    def __call__(self, *shape):
        v = self.original(*shape)
        self.draws.append(np.array(v, dtype=np.float64).ravel().tolist())
        return v


def raw_bytes(rendering):
    """The 8-bit RGB values behind a normalised frame (checked to be exactly value / 255)."""
    raw = np.rint(rendering.astype(np.float64) * 255.0)
    assert raw.min() == 0 and raw.max() == 255, "a frame whose min-max normalisation is not /255"
    assert np.array_equal(raw.astype(np.float32) / np.float32(255), rendering)
    return base64.b64encode(raw.astype(np.uint8).tobytes()).decode("ascii")


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--cdge", required=True, help="checkout of %s at %s" % (CDGE_REPO, CDGE_COMMIT))
    ap.add_argument("--out", default=OUT)
    args = ap.parse_args()
    root = os.path.abspath(args.cdge)
    check_sources(root)
    sys.path.insert(0, root)
    import scipy
    import gizeh  # noqa: F401  (their renderer draws with it)
    import cairocffi
    from latentgoalexplo.actors.controllers import RbfController
    from latentgoalexplo.environments import armballs

    controller = RbfController(n_timesteps=50, n_action_dims=7, n_rbf=7, sdev=10.0)
    table = controller._bfs_params
    assert all(np.array_equal(table[:, 0, :], table[:, j, :]) for j in range(7))
    basis = table[:, 0, :].tolist()

    env = armballs.MyArmBallsObserved(**ENV_CONFIG)
    original_randn = np.random.randn

    def episode(theta):
        rec = RecordedNormal(original_randn)
        np.random.randn = rec
        try:
            env.reset()
            env.act(theta, render=False)
        finally:
            np.random.randn = original_randn
        static = env._dynamic_environment._static_env
        final = env._dynamic_environment.observation_sequence[-1]
        assert len(rec.draws) == 50 and all(len(d) == 2 for d in rec.draws)
        assert np.array_equal(env.hidden_state, final[-2:])
        return {
            "theta": [float(v) for v in theta],
            "distractor_draws": rec.draws,
            "arm_pose": final[:7].tolist(),
            "hand": final[7:9].tolist(),
            "distractor": final[9:11].tolist(),
            "ball": final[11:13].tolist(),
            "caught": bool(static._object_handled),
        }, env.observation

    rollouts, images = [], []

    def add(kind, theta, keep_image):
        r, frame = episode(theta)
        r["kind"] = kind
        rollouts.append(r)
        if keep_image:
            images.append({"source": "observer", "rollout": len(rollouts) - 1,
                           "rgb": raw_bytes(frame)})

    rng = np.random.RandomState(SEED_RANDOM)
    for i in range(N_RANDOM):
        add(f"random_{i}", rng.uniform(-1.0, 1.0, 49), i < N_ROLLOUT_IMAGES // 2)
    rng = np.random.RandomState(SEED_CAUGHT)
    found, tries = 0, 0
    while found < N_CAUGHT:
        tries += 1
        # Small commands keep the hand near its start, large ones sweep: both catch.
        theta = rng.uniform(-1.0, 1.0, 49) * (0.3 if tries % 2 else 1.0)
        r, frame = episode(theta)
        if r["caught"]:
            r["kind"] = f"caught_{found}"
            rollouts.append(r)
            if found < N_ROLLOUT_IMAGES // 2:
                images.append({"source": "observer", "rollout": len(rollouts) - 1,
                               "rgb": raw_bytes(frame)})
            found += 1
    for kind, theta in [("zeros", np.zeros(49)), ("ones", np.ones(49)),
                        ("minus_ones", -np.ones(49)),
                        ("alternating", np.array([(-1.0) ** k for k in range(49)]))]:
        add(kind, theta, False)

    renderer = armballs.ArmBallsRenderer(**ENV_CONFIG)
    renderer.reset()
    rng = np.random.RandomState(SEED_OBSERVATION)
    for i in range(N_OBSERVATION_IMAGES):
        state = rng.uniform(-1.0, 1.0, renderer.action_space.shape[0])
        renderer.act(observation=state)
        images.append({"source": "observation", "state": state.tolist(),
                       "rgb": raw_bytes(renderer.rendering)})

    out = {
        "source": {"repository": CDGE_REPO, "commit": CDGE_COMMIT, "files_sha256": SOURCES},
        "versions": {"python": platform.python_version(), "numpy": np.__version__,
                     "scipy": scipy.__version__, "cairo": cairocffi.cairo_version_string()},
        "env_config": {k: (v.tolist() if isinstance(v, np.ndarray) else v)
                       for k, v in ENV_CONFIG.items()},
        "caught_search_tries": tries,
        "basis": basis,
        "rollouts": rollouts,
        "image_shape": [64, 64, 3],
        "images": images,
    }
    with open(args.out, "w") as f:
        json.dump(out, f, separators=(",", ":"))
        f.write("\n")
    print(f"wrote {args.out}: {len(rollouts)} rollouts ({sum(r['caught'] for r in rollouts)} "
          f"caught), {len(images)} images")


if __name__ == "__main__":
    main()
