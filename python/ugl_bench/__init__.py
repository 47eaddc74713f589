"""ugl-bench from Python.

The environments of ugl-bench (ArmBall, ArmArrow, ArmBalls and the follow-up's ArmBalls), run by
the same Rust code as the ``ugl`` command line, so their outcomes are byte-identical to
``ugl rollout``:

* :func:`rollout` scores a batch of motor parameters (a quality-diversity library's
  ``scheduler.ask()``) in one call, without the GIL and on every core;
* :class:`Env` runs one episode at a time;
* :func:`compare` ranks a learner written as a Python object (``fit``, ``encode``) as
  ``ugl compare --command`` ranks a program;
* :mod:`ugl_bench.gym` registers the Gymnasium environments ``ugl_bench/ArmBall-v0``,
  ``ugl_bench/ArmArrow-v0``, ``ugl_bench/ArmBalls-v0`` and ``ugl_bench/ArmBallsCoRL-v0``
  (``import ugl_bench`` registers them when gymnasium is installed).

The guide is docs/python.md in the repository.
"""

from __future__ import annotations

import json
from typing import Any, Mapping, Optional, Tuple, Union

import numpy as np

from . import _native
from ._native import Env as _NativeEnv

__all__ = ["Env", "environments", "environment", "rollout", "ENV_NAMES", "compare", "CompareResult"]


def environments() -> list:
    """The registered environments, one dict each: ``name``, ``display``, ``description``,
    ``params`` (motor parameters per episode), ``state_dim`` and ``outcome_columns`` (the
    outcome), ``objects`` (name, first and one-past-last outcome coordinate, whether the arm can
    move it), ``image_shape`` (the picture a learner sees) and ``in_paper``."""
    return _native.environments()


ENV_NAMES = tuple(e["name"] for e in environments())


def environment(name: str) -> dict:
    """The description of one environment (see :func:`environments`)."""
    for e in environments():
        if e["name"] == name:
            return e
    raise ValueError(f"unknown environment {name!r} (expected one of {', '.join(ENV_NAMES)})")


def _config_json(config: Optional[Mapping[str, Any]]) -> Optional[str]:
    """The ``[env]`` constants (the keys of a campaign file's ``[env]`` table) as the native
    module reads them."""
    if config is None:
        return None
    if not isinstance(config, Mapping):
        raise TypeError(f"config: expected a mapping of [env] keys, got {type(config).__name__}")
    return json.dumps(dict(config))


class Env:
    """One environment and its distractor's random stream; one :meth:`rollout` is one episode.

    ``Env("armballs", seed=3)`` draws the distractor's walk from seed 3's stream, episode after
    episode, as ``ugl rollout --env armballs --seed 3`` does. ``config`` sets ``[env]`` constants
    (``{"distractor_noise": 0.0}``); they are checked as a campaign file's are.
    """

    def __init__(self, name: str, seed: int = 0, config: Optional[Mapping[str, Any]] = None):
        _check_seed(seed)
        self._env = _NativeEnv(name, seed, _config_json(config))
        self.name: str = self._env.name
        self.params: int = self._env.params
        self.state_dim: int = self._env.state_dim
        self.image_shape: Tuple[int, ...] = tuple(self._env.image_shape)

    def reseed(self, seed: int) -> None:
        """Restart the distractor's stream at the beginning of ``seed``'s."""
        _check_seed(seed)
        self._env.reseed(seed)

    def initial_state(self) -> np.ndarray:
        """The objects' state before any episode (float64)."""
        return self._env.initial_state()

    def rollout(self, params) -> Tuple[np.ndarray, bool, Tuple[float, float]]:
        """One episode: (outcome float64[state_dim], whether the object was caught, hand
        (x, y)). ``params``: ``self.params`` finite numbers, clipped to [-1, 1]."""
        p = _as_params(params, self.params, one=True)
        return self._env.rollout(p)

    def render(self, state) -> np.ndarray:
        """The picture of an outcome, as a learner sees it (float32 in [0, 1],
        ``self.image_shape``)."""
        s = np.ascontiguousarray(state, dtype=np.float64)
        if s.ndim != 1:
            raise ValueError(f"state: expected one outcome of {self.state_dim} values, got shape {s.shape}")
        return self._env.render(s)

    def __repr__(self) -> str:
        return f"ugl_bench.Env({self.name!r})"


def _check_seed(seed) -> None:
    if isinstance(seed, bool) or not isinstance(seed, (int, np.integer)):
        raise TypeError(f"seed: expected an integer, got {type(seed).__name__}")
    if not 0 <= int(seed) < 2**64:
        raise ValueError(f"seed: expected an integer in [0, 2**64), got {seed}")


def _as_params(params, p: int, one: bool) -> np.ndarray:
    """Motor parameters as a C-contiguous float64 array of the right shape, or a ValueError."""
    try:
        a = np.ascontiguousarray(params, dtype=np.float64)
    except (TypeError, ValueError) as e:
        raise ValueError(f"params: expected numbers, got {type(params).__name__} ({e})") from None
    want = "(P,)" if one else "(N, P)"
    if (one and a.ndim != 1) or (not one and a.ndim != 2):
        raise ValueError(f"params: expected shape {want} with P = {p}, got shape {a.shape}")
    if a.shape[-1] != p:
        raise ValueError(f"params: expected shape {want} with P = {p}, got shape {a.shape}")
    return a


def rollout(
    env: Union[str, "Env"],
    params,
    seed: int = 0,
    images: bool = False,
    config: Optional[Mapping[str, Any]] = None,
):
    """Run one episode per row of ``params`` (float[N, P]) and return the outcomes
    (float64[N, state_dim]); with ``images=True`` return ``(outcomes, pictures)``, the pictures
    float32[N, *image_shape].

    Row ``i`` gives the ``i``-th episode of ``ugl rollout --env ENV --seed SEED`` on the same
    parameters, byte for byte: with a distractor (armballs, armballs-corl) the episodes draw its
    walk from the seed's stream in order; without one they run on every core. The GIL is released
    while they run. ``env`` is an environment name or an :class:`Env` (its name; its stream is not
    used: ``seed`` chooses the stream).
    """
    name = env.name if isinstance(env, Env) else env
    if not isinstance(name, str):
        raise TypeError(f"env: expected an environment name or ugl_bench.Env, got {type(env).__name__}")
    _check_seed(seed)
    p = environment(name)["params"]
    a = _as_params(params, p, one=False)
    return _native.rollout(name, a, int(seed), bool(images), _config_json(config))


from .comparison import CompareResult, compare  # noqa: E402

# The Gymnasium environments, registered on import when gymnasium is installed (Gymnasium 1.x
# has no plugin hook; `gymnasium.make("ugl_bench.gym:ugl_bench/ArmBall-v0")` also works).
try:
    import gymnasium as _gymnasium  # noqa: F401
except ImportError:
    pass
else:
    from . import gym as _gym  # noqa: F401
