"""Gymnasium environments: the IMGEP view of ugl-bench's environments.

One step is one rollout: the action is the motor parameters (a Box in [-1, 1]^P, float64), the
observation is the outcome, the objects' final state (``obs_type="state"``, float64 in [-1, 1]),
or its picture (``obs_type="image"``, float32 in [0, 1], the picture a learner sees). The arm starts
every rollout from rest, so a Gymnasium episode is a sequence of rollouts that never terminates on
its own; give ``max_episode_steps`` to ``gymnasium.make`` to cut it.

``reset(seed=S)`` restarts the distractor's walk (ArmBalls, ArmBallsCoRL) at the beginning of seed
S's stream, the one ``ugl rollout --seed S`` and a run of that seed draw from: after
``reset(seed=S)`` the outcomes of the steps are those of ``ugl rollout --seed S`` on the same
actions, byte for byte. ``reset()`` without a seed keeps the stream where it is (the first reset
without a seed takes one from Gymnasium's ``np_random``).

With ``goal_env=True`` the observation is a dict in the ``GoalEnv`` layout: ``observation`` (the
outcome or picture), ``achieved_goal`` (the outcome) and ``desired_goal`` (a goal drawn uniformly
in [-1, 1]^d at each reset, from ``np_random``); the reward is ``compute_reward(achieved,
desired, info)`` = minus the Euclidean distance. Otherwise the reward is 0: exploration has none.

Ids: ``ugl_bench/<Name>-v0``, Name the environment's display name without spaces, brackets or
digits: ArmBall, ArmArrow, ArmBalls, ArmBallsCoRL (the follow-up's, CoRL 2018).
"""

from __future__ import annotations

import re
from typing import Any, Dict, Optional

import numpy as np

try:
    import gymnasium
    from gymnasium import spaces
except ImportError as e:  # pragma: no cover - exercised only without gymnasium
    raise ImportError(
        "ugl_bench.gym needs gymnasium: pip install 'gymnasium>=0.29' "
        "(or install ugl-bench with the [gymnasium] extra)"
    ) from e

from . import Env, _check_seed, environments

NAMESPACE = "ugl_bench"
VERSION = 0


def env_id(description: dict) -> str:
    """The Gymnasium id of an environment description (see :func:`ugl_bench.environments`)."""
    name = re.sub(r"[^A-Za-z]", "", description["display"])
    return f"{NAMESPACE}/{name}-v{VERSION}"


def env_ids() -> Dict[str, str]:
    """Gymnasium id -> environment name, for every registered environment."""
    return {env_id(d): d["name"] for d in environments()}


class UglBenchEnv(gymnasium.Env):
    """A ugl-bench environment as a Gymnasium environment (see the module's help)."""

    metadata = {"render_modes": ["rgb_array"], "render_fps": 4}

    def __init__(
        self,
        env: str = "armball",
        obs_type: str = "state",
        goal_env: bool = False,
        config: Optional[Dict[str, Any]] = None,
        render_mode: Optional[str] = None,
    ):
        if obs_type not in ("state", "image"):
            raise ValueError(f"obs_type: expected 'state' or 'image', got {obs_type!r}")
        if render_mode is not None and render_mode not in self.metadata["render_modes"]:
            raise ValueError(f"render_mode: expected None or 'rgb_array', got {render_mode!r}")
        self._env = Env(env, seed=0, config=config)
        self._name = self._env.name
        self.obs_type = obs_type
        self.goal_env = bool(goal_env)
        self.render_mode = render_mode
        d, p = self._env.state_dim, self._env.params
        self.action_space = spaces.Box(-1.0, 1.0, shape=(p,), dtype=np.float64)
        outcome = spaces.Box(-1.0, 1.0, shape=(d,), dtype=np.float64)
        if obs_type == "state":
            observation = outcome
        else:
            observation = spaces.Box(0.0, 1.0, shape=self._env.image_shape, dtype=np.float32)
        if self.goal_env:
            self.observation_space = spaces.Dict(
                {"observation": observation, "achieved_goal": outcome, "desired_goal": outcome}
            )
        else:
            self.observation_space = observation
        self._seeded = False
        self._state = self._env.initial_state()
        self._goal = np.zeros(d)

    @property
    def ugl_env(self) -> Env:
        """The underlying :class:`ugl_bench.Env`."""
        return self._env

    def _observe(self) -> Any:
        obs = self._state if self.obs_type == "state" else self._env.render(self._state)
        if not self.goal_env:
            return obs
        return {"observation": obs, "achieved_goal": self._state.copy(), "desired_goal": self._goal.copy()}

    def reset(self, *, seed: Optional[int] = None, options: Optional[dict] = None):
        super().reset(seed=seed)
        if seed is not None:
            _check_seed(seed)
            self._env.reseed(seed)
            self._seeded = True
        elif not self._seeded:
            self._env.reseed(int(self.np_random.integers(0, 2**63)))
            self._seeded = True
        self._state = self._env.initial_state()
        if self.goal_env:
            self._goal = self.np_random.uniform(-1.0, 1.0, size=self._env.state_dim)
        return self._observe(), {}

    def step(self, action):
        outcome, caught, hand = self._env.rollout(action)
        self._state = outcome
        info = {"caught": caught, "hand": np.array(hand)}
        reward = float(self.compute_reward(outcome, self._goal, info)) if self.goal_env else 0.0
        return self._observe(), reward, False, False, info

    def compute_reward(self, achieved_goal, desired_goal, info) -> Any:
        """Minus the Euclidean distance between outcome and goal (vectorised over a leading
        batch axis, as hindsight relabelling asks)."""
        diff = np.asarray(achieved_goal, dtype=np.float64) - np.asarray(desired_goal, dtype=np.float64)
        return -np.linalg.norm(diff, axis=-1)

    def render(self):
        if self.render_mode != "rgb_array":
            return None
        pic = self._env.render(self._state)
        if pic.ndim == 2:
            # The paper's pictures are indexed [x][y]; show y upwards, x to the right.
            pic = np.repeat(pic.T[::-1, :, None], 3, axis=2)
        else:
            pic = pic[::-1]
        return (np.clip(pic, 0.0, 1.0) * 255).round().astype(np.uint8)

    def __repr__(self) -> str:
        return f"UglBenchEnv({self._name!r}, obs_type={self.obs_type!r}, goal_env={self.goal_env})"


def register_envs() -> None:
    """Register every environment with Gymnasium (idempotent; importing ugl_bench calls it)."""
    for gid, name in env_ids().items():
        if gid in gymnasium.registry:
            continue
        gymnasium.register(id=gid, entry_point=UglBenchEnv, kwargs={"env": name})


register_envs()

__all__ = ["UglBenchEnv", "register_envs", "env_id", "env_ids", "NAMESPACE"]
