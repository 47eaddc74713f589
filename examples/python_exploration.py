# %% [markdown]
# # ugl-bench from Python: exploring ArmBall with a batched rollout
#
# A notebook in script form (cells marked `# %%`; run it whole with `python
# examples/python_exploration.py` after `pip install ./python`). It scores motor parameters
# with `ugl_bench.rollout`, the function a quality-diversity library calls, and compares random
# parameter exploration with a small MAP-Elites loop written in numpy; where pyribs is installed,
# the same loop runs through its scheduler.

# %%
import numpy as np

import ugl_bench

env = ugl_bench.environment("armball")
print(env["display"], "-", env["params"], "motor parameters, outcome", env["outcome_columns"])

# %% [markdown]
# ## Random parameter exploration (RPE), 10,000 episodes in one call
# The outcome is the ball's final (x, y). A rollout is deterministic on ArmBall (no distractor),
# so the batch runs on every core; `seed` matters only where a distractor walks.

# %%
rng = np.random.default_rng(0)
params = rng.uniform(-1.0, 1.0, size=(10_000, env["params"]))
outcomes = ugl_bench.rollout("armball", params, seed=0)


def cells(points, bins=30):
    """Cells of a bins x bins grid over [-1, 1]^2 holding at least one outcome."""
    idx = np.clip(((points + 1.0) / 2.0 * bins).astype(int), 0, bins - 1)
    return len({(i, j) for i, j in idx})


moved = np.any(np.abs(outcomes - np.array([0.6, 0.6])) > 1e-3, axis=1)
print(f"RPE: the ball moved in {moved.mean():.1%} of the episodes, {cells(outcomes)} cells reached")

# %% [markdown]
# ## MAP-Elites on the ball's position (numpy only)
# An archive keeps one parameter vector per cell of the outcome grid; each generation mutates
# archive members and keeps any that land in a new cell. The score of a batch is one call.

# %%
archive = {}


def insert(theta, outcome):
    key = tuple(np.clip(((outcome + 1.0) / 2.0 * 30).astype(int), 0, 29))
    archive.setdefault(key, theta)


for t, o in zip(params[:1000], outcomes[:1000]):
    insert(t, o)
for generation in range(90):
    parents = np.array(list(archive.values()))
    pick = parents[rng.integers(len(parents), size=100)]
    children = np.clip(pick + rng.normal(0.0, 0.1, size=pick.shape), -1.0, 1.0)
    for t, o in zip(children, ugl_bench.rollout("armball", children)):
        insert(t, o)
print(f"MAP-Elites: {len(archive)} cells after 10,000 episodes (RPE: {cells(outcomes)})")

# %% [markdown]
# ## The same loop with pyribs (if installed)
# `scheduler.ask()` gives the parameters, `ugl_bench.rollout` scores them, `scheduler.tell()`
# takes an objective (here 0: pure diversity) and the measures (the ball's position).

# %%
try:
    from ribs.archives import GridArchive
    from ribs.emitters import GaussianEmitter
    from ribs.schedulers import Scheduler
except ImportError:
    print("pyribs is not installed (pip install ribs): its part of the example is skipped")
else:
    grid = GridArchive(solution_dim=env["params"], dims=[30, 30], ranges=[(-1, 1), (-1, 1)])
    emitters = [GaussianEmitter(grid, sigma=0.1, x0=np.zeros(env["params"]), batch_size=100,
                                bounds=[(-1.0, 1.0)] * env["params"])]
    scheduler = Scheduler(grid, emitters)
    for _ in range(100):
        solutions = scheduler.ask()
        measures = ugl_bench.rollout("armball", solutions)
        scheduler.tell(np.zeros(len(solutions)), measures)
    print(f"pyribs MAP-Elites: {len(grid)} cells after 10,000 episodes")

# %% [markdown]
# ## One episode at a time, and Gymnasium
# `ugl_bench.Env` steps one episode per call; `gymnasium.make("ugl_bench/ArmBalls-v0")` is the
# same as a Gymnasium environment (one step = one rollout; `obs_type="image"` for the picture).

# %%
walker = ugl_bench.Env("armballs", seed=3)
outcome, caught, hand = walker.rollout(params[0])
print("ArmBalls episode:", outcome.round(3), "caught" if caught else "not caught")
try:
    import gymnasium
except ImportError:
    print("gymnasium is not installed (pip install gymnasium): its part of the example is skipped")
else:
    g = gymnasium.make("ugl_bench/ArmBalls-v0", obs_type="image")
    obs, _ = g.reset(seed=3)
    obs, reward, terminated, truncated, info = g.step(params[0])
    print("Gymnasium: picture", obs.shape, obs.dtype, "caught" if info["caught"] else "not caught")
