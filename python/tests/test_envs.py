"""The Python package against the command line and Gymnasium's checker (`make test-python`)."""

import json
import os
import subprocess
from pathlib import Path

import numpy as np
import pytest

import ugl_bench

gymnasium = pytest.importorskip("gymnasium")
from gymnasium.utils.env_checker import check_env  # noqa: E402

import ugl_bench.gym as ugl_gym  # noqa: E402

REPO = Path(__file__).resolve().parents[2]


def ugl_binary():
    """The command line built by `cargo test` / `cargo build` (or $UGL_BIN)."""
    path = Path(os.environ.get("UGL_BIN", REPO / "target" / "debug" / "ugl"))
    if not path.exists():
        pytest.skip(f"no ugl binary at {path}: build it (cargo build --bin ugl) or set UGL_BIN")
    return path


def params_for(name, n, seed):
    p = ugl_bench.environment(name)["params"]
    return np.random.default_rng(seed).uniform(-1.2, 1.2, size=(n, p))


@pytest.mark.parametrize("name", ugl_bench.ENV_NAMES)
def test_batched_rollouts_are_the_command_lines_byte_for_byte(name, tmp_path):
    x = params_for(name, 40, 1)
    path = tmp_path / "params.json"
    path.write_text(json.dumps(x.tolist()))
    out = subprocess.run(
        [str(ugl_binary()), "rollout", "--env", name, "--params", str(path), "--seed", "5"],
        check=True,
        capture_output=True,
        text=True,
    ).stdout
    cli = np.array([r["object"] for r in json.loads(out)])
    ours = ugl_bench.rollout(name, x, seed=5)
    assert ours.dtype == np.float64 and ours.shape == cli.shape
    assert np.array_equal(ours, cli), np.abs(ours - cli).max()
    # The step-by-step view draws the same stream in the same order.
    env = ugl_bench.Env(name, seed=5)
    steps = np.array([env.rollout(row)[0] for row in x])
    assert np.array_equal(steps, cli)


@pytest.mark.parametrize("name", ugl_bench.ENV_NAMES)
def test_pictures_are_the_command_lines(name, tmp_path):
    x = params_for(name, 3, 2)
    outcomes, pictures = ugl_bench.rollout(name, x, seed=0, images=True)
    shape = tuple(ugl_bench.environment(name)["image_shape"])
    assert pictures.shape == (3,) + shape and pictures.dtype == np.float32
    for k, state in enumerate(outcomes):
        npy = tmp_path / f"{k}.npy"
        subprocess.run(
            [
                str(ugl_binary()),
                "render",
                "--env",
                name,
                "--state",
                ",".join(repr(float(v)) for v in state),
                "--out",
                str(npy),
            ],
            check=True,
            capture_output=True,
        )
        assert np.array_equal(np.load(npy), pictures[k])
        assert np.array_equal(ugl_bench.Env(name).render(state), pictures[k])


def test_seeds_choose_the_distractors_walk_and_nothing_else():
    x = params_for("armballs", 30, 3)
    a = ugl_bench.rollout("armballs", x, seed=1)
    assert np.array_equal(a, ugl_bench.rollout("armballs", x, seed=1))
    b = ugl_bench.rollout("armballs", x, seed=2)
    assert np.array_equal(a[:, :2], b[:, :2])  # the ball: the arm's alone
    assert not np.array_equal(a[:, 2:], b[:, 2:])  # the distractor: the seed's walk
    # Without a distractor the seed changes nothing, and the parallel batch equals the episodes.
    y = params_for("armball", 500, 4)
    c = ugl_bench.rollout("armball", y, seed=1)
    assert np.array_equal(c, ugl_bench.rollout("armball", y, seed=9))
    env = ugl_bench.Env("armball")
    assert np.array_equal(c, np.array([env.rollout(r)[0] for r in y]))


def test_config_sets_env_constants_and_is_checked():
    x = params_for("armballs", 10, 5)
    still = ugl_bench.rollout("armballs", x, seed=1, config={"distractor_noise": 0.0})
    assert np.all(still[:, 2:] == np.array([0.7, -0.45]))
    # The environment's own table: the same episodes; another environment's table leaves it be.
    own = ugl_bench.rollout("armballs", x, seed=1, config={"armballs": {"distractor_noise": 0.0}})
    assert np.array_equal(own, still)
    other = ugl_bench.rollout("armballs", x, seed=1, config={"armballs-corl": {"distractor_noise": 0.0}})
    assert np.array_equal(other, ugl_bench.rollout("armballs", x, seed=1))
    assert not np.array_equal(other, still)
    with pytest.raises(ValueError, match="distractor_noise"):
        ugl_bench.rollout("armballs", x, config={"distractor_noise": -1.0})
    with pytest.raises(ValueError, match="env.armball.distractor_noise is not a constant of ArmBall"):
        ugl_bench.rollout("armball", params_for("armball", 10, 1), config={"armball": {"distractor_noise": 0.0}})
    with pytest.raises(ValueError, match="bogus"):
        ugl_bench.Env("armballs", config={"bogus": 1})


@pytest.mark.parametrize(
    "call, message",
    [
        (lambda: ugl_bench.rollout("nope", np.zeros((1, 21))), "unknown environment 'nope'"),
        (lambda: ugl_bench.rollout("armball", np.zeros((2, 20))), r"shape \(N, P\) with P = 21"),
        (lambda: ugl_bench.rollout("armball", np.zeros(21)), r"got shape \(21,\)"),
        (lambda: ugl_bench.rollout("armball", [[np.nan] * 21]), "is NaN"),
        (lambda: ugl_bench.rollout("armball", [["a"] * 21]), "expected numbers"),
        (lambda: ugl_bench.rollout("armball", np.zeros((1, 21)), seed=-1), "seed"),
        (lambda: ugl_bench.Env("armballs-corl").rollout(np.zeros(21)), "P = 49"),
        (lambda: ugl_bench.Env("armball").rollout([0.0] * 20 + [np.inf]), "is inf"),
        (lambda: ugl_bench.Env("armball").render([0.0, 0.0, 0.0]), "2 values"),
        (lambda: ugl_bench.Env("armball").render([np.nan, 0.0]), "is NaN"),
        (lambda: gymnasium.make("ugl_bench/ArmBall-v0", obs_type="pixels"), "obs_type"),
    ],
)
def test_bad_input_raises_one_clear_exception(call, message):
    with pytest.raises((ValueError, TypeError), match=message):
        call()


def test_an_empty_batch_is_an_empty_result():
    out = ugl_bench.rollout("armball", np.zeros((0, 21)))
    assert out.shape == (0, 2)


@pytest.mark.parametrize("gid", sorted(ugl_gym.env_ids()))
@pytest.mark.parametrize("obs_type", ["state", "image"])
def test_gymnasium_env_checker_passes(gid, obs_type):
    env = gymnasium.make(gid, obs_type=obs_type, render_mode="rgb_array")
    check_env(env.unwrapped, skip_render_check=False)
    env.close()


def test_goal_env_layout_passes_the_checker_and_rewards_by_distance():
    env = gymnasium.make("ugl_bench/ArmBalls-v0", goal_env=True)
    check_env(env.unwrapped)
    obs, _ = env.reset(seed=0)
    assert set(obs) == {"observation", "achieved_goal", "desired_goal"}
    obs, reward, terminated, truncated, info = env.step(np.zeros(21))
    assert not terminated and not truncated and isinstance(info["caught"], bool)
    want = -np.linalg.norm(obs["achieved_goal"] - obs["desired_goal"])
    assert reward == pytest.approx(want)
    batch = env.unwrapped.compute_reward(np.zeros((5, 4)), np.ones((5, 4)), {})
    assert batch.shape == (5,) and np.allclose(batch, -2.0)


def test_gymnasium_steps_are_the_command_lines_after_a_seeded_reset():
    x = params_for("armballs-corl", 12, 6)
    env = gymnasium.make("ugl_bench/ArmBallsCoRL-v0")
    env.reset(seed=11)
    steps = np.array([env.step(a)[0] for a in x])
    assert np.array_equal(steps, ugl_bench.rollout("armballs-corl", x, seed=11))
    # A reset without a seed continues the stream; a seeded one starts it again.
    env.reset()
    again = np.array([env.step(a)[0] for a in x])
    assert not np.array_equal(again[:, 2:], steps[:, 2:])
    env.reset(seed=11)
    assert np.array_equal(np.array([env.step(a)[0] for a in x]), steps)


def test_the_example_runs():
    """examples/python_exploration.py, whole (its pyribs part is skipped without pyribs)."""
    import sys

    out = subprocess.run(
        [sys.executable, str(REPO / "examples" / "python_exploration.py")],
        check=True,
        capture_output=True,
        text=True,
        timeout=300,
    ).stdout
    assert "MAP-Elites:" in out and "Gymnasium: picture (70, 70) float32" in out, out
