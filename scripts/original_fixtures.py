#!/usr/bin/env python3
"""Reference outputs from the ORIGINAL code (explauto 1.3.0 + UGSL environments), as test fixtures.

Writes (deterministically, fixed seeds):
  benchmark/tests/fixtures/orig_rollouts.json   ArmBall / ArmArrow rollouts
  benchmark/tests/fixtures/orig_klc.json        KL-coverage (notebook computation)

See scripts/README-fixtures.md for how to run this and exactly what is original code and
what is re-expressed here.

Nothing of explauto is copied into this repository: the DMP (explauto/models/dmp.py,
explauto/models/pydmps/{cs,dmp,dmp_discrete,dmp_rhythmic}.py), DynamicEnvironment
(explauto/environment/dynamic_environment.py), Environment (explauto/environment/environment.py)
and the helpers in explauto/utils/{utils,config,observer}.py are executed straight from the
PyPI sdist explauto-1.3.0.tar.gz, with a few textual Python-2 -> Python-3 patches applied at
load time (listed in EXPLAUTO_MODULES below; every patch must match, or the script stops).

The UGSL environment classes (flowersteam/Unsupervised_Goal_Space_Learning, commit 6da622e,
src/environments.py, classes ArmBallStatic/ArmBallDynamic/ArmArrowStatic/ArmArrowDynamic) are not
on PyPI; their compute_sensori_effect logic is re-expressed below with the same numpy operations
in the same order (see _ugsl_forward / _UGSLArmBallStatic / _UGSLArmArrowStatic).
"""

import argparse
import hashlib
import io
import json
import math
import os
import platform
import subprocess
import sys
import tarfile
import tempfile
import types
from fractions import Fraction

import numpy as np
import scipy
import scipy.stats

REPO_ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
FIXTURE_DIR = os.path.join(REPO_ROOT, "benchmark", "tests", "fixtures")

EXPLAUTO_VERSION = "1.3.0"
EXPLAUTO_SDIST = "explauto-1.3.0.tar.gz"
EXPLAUTO_SHA256 = "f13be9f074bcea286bb3c1e6360a015e83dacf4a391e3491a798173aff919015"
UGSL_REPO = "flowersteam/Unsupervised_Goal_Space_Learning"
UGSL_COMMIT = "6da622e66f029b5273c5f9bb37f4fd5d03528e7d"

# Seeds (numpy legacy global MT19937, the generator explauto's rand_bounds uses).
SEED_RANDOM_THETAS = 20180430      # the ~300 plain random cases per env
SEED_CATCH_SEARCH = 20180501       # stream searched for caught cases
SEED_EDGE = 20180502               # out-of-range thetas
SEED_CATCH_RATE = 20180503         # catch-rate estimate (not written to the fixtures)
SEED_KLC = 20180504                # random KLC point sets
SEED_MC_MASK = 20180505            # Monte-Carlo attainable mask, as in the notebook

N_RANDOM = 300
N_CAUGHT_MIN = 45                  # caught cases per env (brief: >= 40)
N_BINS = 30

# ----------------------------------------------------------------------------------------------
# 1. Load the original explauto 1.3.0 sources from the sdist (py2 -> py3 patches at load time)
# ----------------------------------------------------------------------------------------------

# (module name, path inside explauto/ or None for a bare package, [(old, new), ...])
EXPLAUTO_MODULES = [
    ("explauto", None, []),
    ("explauto.utils.utils", "utils/utils.py", []),
    ("explauto.utils", "utils/__init__.py", []),
    ("explauto.utils.config", "utils/config.py", [
        # numpy 2 has no np.product
        ("ravel_multi_index, product", "ravel_multi_index, prod as product"),
        # py3 ranges cannot be added
        ("dims = m_dims + s_dims", "dims = list(m_dims) + list(s_dims)"),
    ]),
    ("explauto.utils.observer", "utils/observer.py", [
        ("from Queue import Queue", "from queue import Queue"),
        ("""print 'new event on topic "{}": "{}"'.format(topic, message)""",
         """print('new event on topic "{}": "{}"'.format(topic, message))"""),
    ]),
    ("explauto.environment", None, []),
    ("explauto.environment.environment", "environment/environment.py", [
        # only used by uniform_sensor / from_configuration, which pull in every environment
        ("from .testcase import Lattice", ""),
        ("from . import environments", ""),
    ]),
    ("explauto.models", None, []),
    ("explauto.models.pydmps", None, []),
    ("explauto.models.pydmps.cs", "models/pydmps/cs.py", [
        ("kwargs.has_key('tau')", "('tau' in kwargs)"),
    ]),
    ("explauto.models.pydmps.dmp", "models/pydmps/dmp.py", [
        ("from cs import CanonicalSystem", "from .cs import CanonicalSystem"),
        ("kwargs.has_key('tau')", "('tau' in kwargs)"),
    ]),
    ("explauto.models.pydmps.dmp_discrete", "models/pydmps/dmp_discrete.py", [
        ("from dmp import DMPs", "from .dmp import DMPs"),
    ]),
    ("explauto.models.pydmps.dmp_rhythmic", "models/pydmps/dmp_rhythmic.py", [
        ("from dmp import DMPs", "from .dmp import DMPs"),
    ]),
    ("explauto.models.dmp", "models/dmp.py", []),
    ("explauto.environment.dynamic_environment", "environment/dynamic_environment.py", [
        # plotting only (DynamicEnvironment.plot)
        ("from matplotlib import animation, rc", ""),
        ("from IPython.display import HTML", ""),
    ]),
]


def _sha256(path):
    h = hashlib.sha256()
    with open(path, "rb") as f:
        for chunk in iter(lambda: f.read(1 << 20), b""):
            h.update(chunk)
    return h.hexdigest()


def fetch_sdist(dest_dir):
    """Return the path of explauto-1.3.0.tar.gz, downloading it with pip if needed."""
    os.makedirs(dest_dir, exist_ok=True)
    path = os.path.join(dest_dir, EXPLAUTO_SDIST)
    if not os.path.exists(path):
        cmd = [sys.executable, "-m", "pip", "download", "--no-deps", "--no-binary", ":all:",
               "explauto==%s" % EXPLAUTO_VERSION, "-d", dest_dir]
        r = subprocess.run(cmd, capture_output=True, text=True)
        if not os.path.exists(path):
            # pip saves the sdist only after building its metadata, and explauto's setup.py uses
            # use_2to3, which setuptools >= 58 rejects: retry from a venv with an old setuptools.
            print("plain pip download failed (exit %d; explauto's setup.py needs setuptools<58); "
                  "retrying from a venv with setuptools<58" % r.returncode, file=sys.stderr)
            venv = os.path.join(dest_dir, "venv-setuptools57")
            subprocess.run([sys.executable, "-m", "venv", venv], check=True)
            vpip = os.path.join(venv, "bin", "pip")
            subprocess.run([vpip, "install", "-q", "setuptools<58", "wheel"], check=True)
            subprocess.run([vpip, "download", "--no-deps", "--no-binary", ":all:",
                            "--no-build-isolation", "explauto==%s" % EXPLAUTO_VERSION,
                            "-d", dest_dir], check=True)
    digest = _sha256(path)
    if digest != EXPLAUTO_SHA256:
        raise SystemExit("unexpected sha256 for %s: %s" % (path, digest))
    return path


def load_explauto(sdist_path):
    """Execute the needed explauto modules from the sdist into sys.modules; return their sources."""
    sources = {}
    # first create every (package) module, then execute the sources in list order
    for modname, rel, _ in EXPLAUTO_MODULES:
        mod = types.ModuleType(modname)
        if rel is None or rel.endswith("__init__.py"):
            mod.__path__ = []
            mod.__package__ = modname
        else:
            mod.__package__ = modname.rpartition(".")[0]
        sys.modules[modname] = mod
    for modname, _, _ in EXPLAUTO_MODULES:
        parent, _, child = modname.rpartition(".")
        if parent:
            setattr(sys.modules[parent], child, sys.modules[modname])
    with tarfile.open(sdist_path, "r:gz") as tar:
        for modname, rel, patches in EXPLAUTO_MODULES:
            mod = sys.modules[modname]
            if rel is None:
                continue
            member = "explauto-%s/explauto/%s" % (EXPLAUTO_VERSION, rel)
            src = tar.extractfile(member).read().decode("utf-8")
            sources[rel] = src
            for old, new in patches:
                if old not in src:
                    raise SystemExit("patch target %r not found in %s" % (old, rel))
                src = src.replace(old, new)
            mod.__file__ = member
            exec(compile(src, member, "exec"), mod.__dict__)
    return sources


# ----------------------------------------------------------------------------------------------
# 2. UGSL environments (re-expressed from flowersteam/Unsupervised_Goal_Space_Learning@6da622e,
#    src/environments.py). Numerical expressions and their order are kept exactly:
#      a = arm_angle_shift + np.cumsum(np.array(m))        (shift added AFTER the cumsum)
#      a_pi = np.pi * a
#      hand = [np.sum(np.cos(a_pi) * L), np.sum(np.sin(a_pi) * L)]
#      angle = np.mod(a[-1] + 1, 2) - 1
#      catch: moving or (hx - ox) ** 2 + (hy - oy) ** 2 < size * size   (size_sq precomputed)
#      ArmBall: ball_pos = hand; returns list(ball_pos) (no per-step clip)
#      ArmArrow: arrow_pos = concatenate([hand, [angle]]); returns np.clip(arrow_pos, -1, 1)
#    The configuration is the one of rpe.py / rge_efr.py / rge_rep.py.
# ----------------------------------------------------------------------------------------------

ARM_CFG = dict(m_mins=[-1.] * 7, m_maxs=[1.] * 7,
               arm_lengths=[0.3, 0.2, 0.2, 0.1, 0.1, 0.05, 0.05],
               arm_angle_shift=0.5, arm_rest_state=[0.] * 7)


def _ugsl_forward(arm_angle_shift, arm_lengths, m):
    a = arm_angle_shift + np.cumsum(np.array(m))
    a_pi = np.pi * a
    hand_pos = np.array([np.sum(np.cos(a_pi) * arm_lengths), np.sum(np.sin(a_pi) * arm_lengths)])
    angle = np.mod(a[-1] + 1, 2) - 1
    return hand_pos, angle


def _track_margin(st, hand_pos, obj_pos):
    """Instrumentation only: smallest |d^2 - size^2| over the steps before the catch."""
    d2 = (hand_pos[0] - obj_pos[0]) ** 2 + (hand_pos[1] - obj_pos[1]) ** 2
    st.catch_margin = min(st.catch_margin, float(abs(d2 - st.size_sq)))


def make_env_classes():
    from explauto.environment.environment import Environment
    from explauto.environment.dynamic_environment import DynamicEnvironment
    from explauto.utils import bounds_min_max

    class _UGSLArmBallStatic(Environment):
        def __init__(self, m_mins, m_maxs, s_mins, s_maxs, arm_lengths, arm_angle_shift,
                     arm_rest_state, ball_size, ball_initial_position):
            Environment.__init__(self, m_mins, m_maxs, s_mins, s_maxs)
            self.arm_lengths = arm_lengths
            self.arm_angle_shift = arm_angle_shift
            self.arm_rest_state = arm_rest_state
            self.ball_size = ball_size
            self.size_sq = ball_size * ball_size
            self.ball_initial_position = ball_initial_position
            self.reset()

        def reset(self):
            self.ball_move = False
            self.ball_pos = np.array(self.ball_initial_position)
            self.trajectory = list()
            # instrumentation (not in the original)
            self.catch_step = None
            self.hand_traj = list()
            self.catch_margin = float("inf")

        def compute_motor_command(self, m):
            return bounds_min_max(m, self.conf.m_mins, self.conf.m_maxs)

        def compute_sensori_effect(self, m):
            hand_pos, angle = _ugsl_forward(self.arm_angle_shift, self.arm_lengths, m)
            self.hand_traj.append(hand_pos)
            if not self.ball_move:
                _track_margin(self, hand_pos, self.ball_pos)
            if self.ball_move or ((hand_pos[0] - self.ball_pos[0]) ** 2
                                  + (hand_pos[1] - self.ball_pos[1]) ** 2 < self.size_sq):
                if not self.ball_move:
                    self.catch_step = len(self.hand_traj) - 1
                self.ball_pos = hand_pos
                self.ball_move = 1
            self.trajectory.append(self.ball_pos)
            return list(self.ball_pos)

    class _UGSLArmArrowStatic(Environment):
        def __init__(self, m_mins, m_maxs, s_mins, s_maxs, arm_lengths, arm_angle_shift,
                     arm_rest_state, arrow_size, arrow_initial_pose):
            Environment.__init__(self, m_mins, m_maxs, s_mins, s_maxs)
            self.arm_lengths = arm_lengths
            self.arm_angle_shift = arm_angle_shift
            self.arm_rest_state = arm_rest_state
            self.arrow_size = arrow_size
            self.size_sq = arrow_size * arrow_size
            self.arrow_initial_pose = arrow_initial_pose
            self.initial_pose = arrow_initial_pose
            self.reset()

        def reset(self):
            self.arrow_move = False
            self.arrow_pos = np.array(self.arrow_initial_pose)
            self.trajectory = list()
            self.catch_step = None
            self.hand_traj = list()
            self.catch_margin = float("inf")

        def compute_motor_command(self, m):
            return bounds_min_max(m, self.conf.m_mins, self.conf.m_maxs)

        def compute_sensori_effect(self, m):
            hand_pos, angle = _ugsl_forward(self.arm_angle_shift, self.arm_lengths, m)
            self.hand_traj.append(hand_pos)
            if not self.arrow_move:
                _track_margin(self, hand_pos, self.arrow_pos)
            cond_grip = ((hand_pos[0] - self.arrow_pos[0]) ** 2
                         + (hand_pos[1] - self.arrow_pos[1]) ** 2 < self.size_sq)
            if self.arrow_move or cond_grip:
                if not self.arrow_move:
                    self.catch_step = len(self.hand_traj) - 1
                self.arrow_pos = np.concatenate([hand_pos, [angle]])
                self.arrow_move = True
            effect = np.clip(self.arrow_pos, -1, 1)
            self.trajectory.append(effect.tolist())
            return effect.tolist()

    def _dyn_cfg(static_cfg, env_cls, s_dim):
        n_joints = len(static_cfg["m_mins"])
        n_dmp_basis = 3
        goal_size = 1.
        return dict(env_cfg=static_cfg, env_cls=env_cls,
                    m_mins=[-1.] * n_joints * n_dmp_basis, m_maxs=[1.] * n_joints * n_dmp_basis,
                    s_mins=[-goal_size] * s_dim, s_maxs=[goal_size] * s_dim,
                    n_bfs=n_dmp_basis, move_steps=50, n_dynamic_motor_dims=n_joints,
                    n_dynamic_sensori_dims=2, sensori_traj_type="end_point", max_params=1000)

    def armball():
        cfg = dict(ARM_CFG, s_mins=[-1.] * 2, s_maxs=[1.] * 2,
                   ball_size=0.1, ball_initial_position=[0.6, 0.6])
        env = DynamicEnvironment(**_dyn_cfg(cfg, _UGSLArmBallStatic, 2))
        env.initial_pose = cfg["ball_initial_position"]
        return env

    def armarrow():
        cfg = dict(ARM_CFG, s_mins=[-1.] * 3, s_maxs=[1.] * 3,
                   arrow_size=0.1, arrow_initial_pose=[0.6, 0.6, 0.6])
        env = DynamicEnvironment(**_dyn_cfg(cfg, _UGSLArmArrowStatic, 3))
        env.initial_pose = cfg["arrow_initial_pose"]
        return env

    return armball, armarrow


# ----------------------------------------------------------------------------------------------
# Independent re-implementation of docs/original-code.md section 1 (pure Python floats, math.exp, sequential
# sums) -- used only to cross-check the original code path and report the deviation.
# ----------------------------------------------------------------------------------------------

def notes_dmp(theta):
    th = [min(max(float(t), -1.0), 1.0) for t in theta]
    w = [[1000.0 * th[3 * j + b] for b in range(3)] for j in range(7)]
    c = [-math.log(v) for v in (0.4, 0.6000000000000001, 0.8)]  # linspace(0.4, 0.8, 3)
    h = [3 ** 1.5 / ci for ci in c]
    dt = 2.0 / 50
    x = 1.0
    y = [0.0] * 7
    dy = [0.0] * 7
    out = []
    for _ in range(50):
        x += (-1.0 * x * 1.0) * 1.0 * dt
        psi = [math.exp(-h[b] * (x - c[b]) ** 2) for b in range(3)]
        spsi = psi[0] + psi[1] + psi[2]
        for j in range(7):
            f = x * (psi[0] * w[j][0] + psi[1] * w[j][1] + psi[2] * w[j][2]) / spsi
            ddy = 25.0 * (6.25 * (0.0 - y[j]) - dy[j]) + f
            dy[j] += ddy * dt
            y[j] += dy[j] * dt
        out.append(list(y))
    return out


def notes_rollout(theta, arrow):
    L = ARM_CFG["arm_lengths"]
    obj = [0.6, 0.6, 0.6] if arrow else [0.6, 0.6]
    moving = False
    hand = None
    for q in notes_dmp(theta):
        q = [min(max(v, -1.0), 1.0) for v in q]
        a, s = [], 0.0
        for v in q:
            s += v
            a.append(0.5 + s)
        hx = sum(l * math.cos(math.pi * ak) for l, ak in zip(L, a))
        hy = sum(l * math.sin(math.pi * ak) for l, ak in zip(L, a))
        hand = [hx, hy]
        if moving or (hx - obj[0]) ** 2 + (hy - obj[1]) ** 2 < 0.1 * 0.1:
            moving = True
            obj = [hx, hy] + ([((a[-1] + 1) % 2) - 1] if arrow else [])
    return [min(max(v, -1.0), 1.0) for v in obj], moving, hand


# ----------------------------------------------------------------------------------------------
# Rollouts
# ----------------------------------------------------------------------------------------------

def rollout(env, theta):
    theta = np.asarray(theta, dtype=float)
    s = env.update(theta)                      # DynamicEnvironment.update(reset=True) -- original path
    st = env.env
    moved = bool(st.catch_step is not None)
    return dict(theta=[float(v) for v in theta],
                object=[float(v) for v in s],
                moved=moved,
                catch_step=st.catch_step,
                catch_margin=st.catch_margin,
                hand=[float(v) for v in st.hand_traj[-1]])


def joint_trajectories(env, theta):
    """50x7 joint commands from the DMP (before clipping) and as the static env sees them."""
    from explauto.utils import bounds_min_max
    m_traj = env.compute_motor_command(np.asarray(theta, dtype=float))   # original DMP path
    raw = [[float(v) for v in row] for row in m_traj]
    clipped = [[float(v) for v in bounds_min_max(row, env.env.conf.m_mins, env.env.conf.m_maxs)]
               for row in m_traj]
    return raw, clipped


def draw_thetas(env, seed, n):
    np.random.seed(seed)
    return env.random_motors(n)                # explauto rand_bounds: 2*rand + (-1), in [-1, 1)


def edge_thetas():
    rs = np.random.RandomState(SEED_EDGE)
    cases = [
        ("zeros", np.zeros(21)),
        ("ones", np.ones(21)),
        ("minus_ones", -np.ones(21)),
        ("alternating_pm1", np.array([1.0 if i % 2 == 0 else -1.0 for i in range(21)])),
        ("only_joint0_basis0_1", np.eye(21)[0]),
        ("only_joint6_basis2_-1", -np.eye(21)[20]),
        ("tiny_1e-3", np.full(21, 1e-3)),
        ("out_of_range_x3_uniform", 3.0 * (2.0 * rs.rand(21) - 1.0)),
        ("out_of_range_x3_uniform_b", 3.0 * (2.0 * rs.rand(21) - 1.0)),
        ("out_of_range_big", np.array([7.0, -7.0, 1.5] * 7)),
        ("out_of_range_just_above", np.full(21, 1.0000001)),
        ("out_of_range_just_below", np.full(21, -1.0000001)),
        ("ones_scaled_1.5", np.full(21, 1.5)),
        ("minus_ones_scaled_-2", np.full(21, -2.0)),
    ]
    return cases


def build_rollouts(armball, armarrow, n_catch_rate):
    envs = {"armball": armball(), "armarrow": armarrow()}
    out = {"armball": [], "armarrow": [], "trajectories": []}
    random_thetas = draw_thetas(envs["armball"], SEED_RANDOM_THETAS, N_RANDOM)

    # search for caught cases in a separate stream; the catch test uses only the hand position and the
    # object's initial (x, y) = (0.6, 0.6) with size 0.1 in both environments, so the same thetas
    # are caught in both.
    caught, searched = [], 0
    np.random.seed(SEED_CATCH_SEARCH)
    while len(caught) < N_CAUGHT_MIN:
        th = envs["armball"].random_motors(1)[0]
        searched += 1
        r = rollout(envs["armball"], th)
        if r["moved"]:
            caught.append(th)

    stats = {}
    for name, env in envs.items():
        n_moved_random = 0
        for i, th in enumerate(random_thetas):
            r = rollout(env, th)
            r["kind"] = "random_seed%d_%d" % (SEED_RANDOM_THETAS, i)
            n_moved_random += r["moved"]
            out[name].append(r)
        for i, th in enumerate(caught):
            r = rollout(env, th)
            assert r["moved"]
            r["kind"] = "caught_seed%d_%d" % (SEED_CATCH_SEARCH, i)
            out[name].append(r)
        for label, th in edge_thetas():
            r = rollout(env, th)
            r["kind"] = "edge_" + label
            out[name].append(r)
        stats[name] = dict(n_random=N_RANDOM, n_moved_random=n_moved_random)
    stats["catch_search"] = dict(seed=SEED_CATCH_SEARCH, draws=searched, caught=len(caught),
                                 rate=len(caught) / searched)

    # Trajectories for 5 thetas: 2 caught, the first random, all-ones (saturating), out-of-range.
    edge = dict(edge_thetas())
    for label, th in [("caught_0", caught[0]), ("caught_1", caught[1]),
                      ("random_0", random_thetas[0]), ("edge_ones", edge["ones"]),
                      ("edge_out_of_range_x3_uniform", edge["out_of_range_x3_uniform"])]:
        raw, clipped = joint_trajectories(envs["armball"], th)
        out["trajectories"].append(dict(label=label, theta=[float(v) for v in th],
                                        dmp_output=raw, clipped=clipped))

    # Catch rate under uniform theta (independent stream, same for both envs).
    if n_catch_rate > 0:
        np.random.seed(SEED_CATCH_RATE)
        thetas = envs["armball"].random_motors(n_catch_rate)
        hits = [rollout(envs["armball"], th)["moved"] for th in thetas]
        first = next((i for i, hh in enumerate(hits) if hh), None)
        stats["catch_rate"] = dict(seed=SEED_CATCH_RATE, n=n_catch_rate, caught=int(sum(hits)),
                                   rate=sum(hits) / n_catch_rate, first_catch_index=first)
    return out, stats, envs


def cross_check(out):
    """Compare the original code path with the re-implementation of docs/original-code.md section 1."""
    max_obj, max_hand, flips = 0.0, 0.0, 0
    for name in ("armball", "armarrow"):
        for r in out[name]:
            obj, moved, hand = notes_rollout(r["theta"], name == "armarrow")
            if moved != r["moved"]:
                flips += 1
                continue
            max_obj = max(max_obj, max(abs(a - b) for a, b in zip(obj, r["object"])))
            max_hand = max(max_hand, max(abs(a - b) for a, b in zip(hand, r["hand"])))
    max_traj = 0.0
    for t in out["trajectories"]:
        ref = notes_dmp(t["theta"])
        max_traj = max(max_traj, max(abs(a - b) for ra, rb in zip(ref, t["dmp_output"])
                                     for a, b in zip(ra, rb)))
    min_margin = min(r["catch_margin"] for n in ("armball", "armarrow") for r in out[n])
    return dict(max_abs_object=max_obj, max_abs_hand=max_hand, max_abs_dmp=max_traj,
                moved_flips=flips, min_catch_margin=min_margin)


# ----------------------------------------------------------------------------------------------
# KL-coverage (Performance_Comparison.ipynb cell 2 / Experiment_Visualization.ipynb cell 17)
# ----------------------------------------------------------------------------------------------

def exact_disk_mask():
    """Bins of the 30x30 grid over [-1,1]^2 whose interior meets the open unit disk (exact)."""
    edges = [Fraction(k - 15, 15) for k in range(31)]
    mask = np.zeros((N_BINS, N_BINS))

    def closest(lo, hi):
        return Fraction(0) if lo <= 0 <= hi else min(abs(lo), abs(hi))

    for i in range(N_BINS):
        for j in range(N_BINS):
            cx = closest(edges[i], edges[i + 1])
            cy = closest(edges[j], edges[j + 1])
            mask[i, j] = 1.0 if cx * cx + cy * cy < 1 else 0.0
    return mask


def mc_disk_mask(seed, n_points=1000000):
    """The notebook's way: 1e6 uniform points in the disk by rejection, histogramdd, bool."""
    np.random.seed(seed)
    acc = []
    got = 0
    while got < n_points:
        # np.random.uniform(-1, 1, 2) per trial in the notebook; drawing them in blocks gives the
        # same stream of doubles in the same order.
        s = np.random.uniform(-1, 1, (2 * n_points, 2))
        keep = s[np.linalg.norm(s, ord=2, axis=1) <= 1.0]
        acc.append(keep)
        got += len(keep)
    circ_samp = np.concatenate(acc)[:n_points]
    hist_ab, _ = np.histogramdd(circ_samp, bins=N_BINS, range=np.array([[-1] * 2, [1] * 2]).T)
    return hist_ab.astype(bool).astype(float)


def kl_cov(X_s, hist_q):
    X_s = np.asarray(X_s, dtype=float)
    n_samples, n_dim = X_s.shape
    histp, _ = np.histogramdd(X_s, bins=N_BINS, range=np.array([[-1] * n_dim, [1] * n_dim]).T)
    klc = scipy.stats.entropy(histp.ravel(), hist_q.ravel())
    return float(klc), int(np.count_nonzero(histp)), int(histp.sum())


def uniform_disk(rs, n):
    pts = []
    while len(pts) < n:
        p = rs.uniform(-1, 1, 2)
        if np.linalg.norm(p) < 1.0:
            pts.append(p)
    return np.array(pts)


def build_klc(rollouts):
    mask_exact = exact_disk_mask()
    mask_mc = mc_disk_mask(SEED_MC_MASK)
    n_exact = int(mask_exact.sum())
    n_mc = int(mask_mc.sum())
    if n_exact != 756 or not np.array_equal(mask_exact, mask_mc):
        raise SystemExit("attainable mask mismatch: exact %d, MC %d" % (n_exact, n_mc))
    hist_ab = mask_exact
    hist_aa = np.tile(hist_ab.reshape(30, 30, 1), 30)
    rs = np.random.RandomState(SEED_KLC)
    edges_np = np.linspace(-1, 1, N_BINS + 1)

    sets = {"armball": [], "armarrow": []}
    for name in ("armball", "armarrow"):
        d = 2 if name == "armball" else 3
        rows = rollouts[name]
        rand_rows = [r for r in rows if r["kind"].startswith("random")]
        caught_rows = [r for r in rows if r["kind"].startswith("caught")]
        edge_rows = [r for r in rows if r["kind"].startswith("edge")]
        objs = lambda rr: [r["object"] for r in rr]
        ext = lambda p2: [list(p) + [ang] for p, ang in zip(p2, rs.uniform(-1, 1, len(p2)))] \
            if d == 3 else [list(p) for p in p2]
        cases = []
        for n in (1, 2, 10, 50, 100, 300):
            cases.append(("rollouts_random_first_%d" % n, objs(rand_rows[:n])))
        cases.append(("rollouts_caught_all", objs(caught_rows)))
        cases.append(("rollouts_all", objs(rows)))
        cases.append(("rollouts_edge_cases", objs(edge_rows)))
        f16 = [[float(np.float16(v)) for v in p] for p in objs(caught_rows + rand_rows[:50])]
        cases.append(("rollouts_caught_plus_50_random_float16", f16))
        cases.append(("initial_pose_only", [[0.6, 0.6] + ([0.6] if d == 3 else [])]))
        for n in (7, 100, 1000, 5000):
            cases.append(("uniform_disk_%d" % n, ext(uniform_disk(rs, n))))
        lit = [0.0, -1.0, 1.0, 1 / 15, -1 / 15, 2 / 15, 14 / 15, -14 / 15, 0.5, -0.5]
        pts = [[a, b] for a in lit for b in lit if a * a + b * b < 0.75]
        pts += [[1.0, 0.0], [0.0, 1.0], [-1.0, 0.0], [0.0, -1.0], [1 / 15, 1.0], [-1.0, 1 / 15]]
        if d == 3:
            angs = [0.0, -1.0, 1.0, 1 / 15, -1 / 15, 14 / 15]
            pts = [p + [angs[k % len(angs)]] for k, p in enumerate(pts)]
        cases.append(("bin_edges_literal", pts))
        ne = [float(v) for v in edges_np]
        pts = [[a, b] for a in ne for b in ne[::3] if a * a + b * b < 0.9]
        if d == 3:
            pts = [p + [ne[k % len(ne)]] for k, p in enumerate(pts)]
        cases.append(("bin_edges_numpy_linspace", pts))
        # coordinates just below/above interior edges
        nb = []
        for k in (1, 7, 15, 16, 23):
            e = ne[k]
            for v in (np.nextafter(e, -2.0), e, np.nextafter(e, 2.0)):
                p = [float(v), 0.3] + ([float(v)] if d == 3 else [])
                nb.append(p)
        cases.append(("bin_edges_nextafter", nb))
        base = ext(uniform_disk(rs, 40))
        out_rng = [list(p) for p in base] + \
            [[1.5, 0.0] + ([0.0] if d == 3 else []), [0.0, -2.0] + ([0.5] if d == 3 else []),
             ([0.2, 0.2, 3.0] if d == 3 else [0.2, -1.5]), [-1.25, -1.25] + ([0.1] if d == 3 else [])]
        cases.append(("some_points_outside_range_ignored", out_rng))
        bad = ext(uniform_disk(rs, 30)) + [[0.95, 0.95] + ([0.0] if d == 3 else [])]
        cases.append(("one_point_outside_disk_inf", bad))
        cases.append(("corner_bin_inf", [[-1.0, -1.0] + ([0.0] if d == 3 else [])]))

        for label, pts in cases:
            klc, nonempty, n_in = kl_cov(pts, hist_ab if d == 2 else hist_aa)
            sets[name].append(dict(label=label, points=[[float(v) for v in p] for p in pts],
                                   klc="inf" if math.isinf(klc) else klc,
                                   nonempty_bins=nonempty, n_in_range=n_in, n_points=len(pts)))
    mask_idx = [int(i) for i in np.flatnonzero(hist_ab.ravel())]
    return sets, dict(n_exact=n_exact, n_mc=n_mc, mc_equal=True), mask_idx


# ----------------------------------------------------------------------------------------------

def describe_dmp():
    from explauto.models.pydmps.dmp_discrete import DMPs_discrete
    d = DMPs_discrete(dmps=7, bfs=3, dt=2. / 50, run_time=2.)
    return dict(h=[float(v) for v in d.h], c=[float(v) for v in d.c], dt=float(d.dt),
                ay=float(d.ay[0]), by=float(d.by[0]), ax=float(d.cs.ax))


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--sdist-dir", default=os.path.join(tempfile.gettempdir(), "explauto-1.3.0-sdist"),
                    help="where explauto-1.3.0.tar.gz is (downloaded with pip if absent)")
    ap.add_argument("--out-dir", default=FIXTURE_DIR)
    ap.add_argument("--catch-rate", type=int, default=0,
                    help="also estimate the catch rate on this many uniform thetas (report only)")
    args = ap.parse_args()

    sdist = fetch_sdist(args.sdist_dir)
    sources = load_explauto(sdist)
    armball, armarrow = make_env_classes()
    dmp_info = describe_dmp()

    rollouts, stats, envs = build_rollouts(armball, armarrow, args.catch_rate)
    check = cross_check(rollouts)
    klc_sets, mask_info, mask_idx = build_klc(rollouts)

    versions = "python %s, numpy %s, scipy %s" % (platform.python_version(), np.__version__,
                                                   scipy.__version__)
    source = ("Produced by scripts/original_fixtures.py. DMP, DynamicEnvironment, Environment and "
              "explauto.utils executed from the PyPI sdist explauto-%s (sha256 %s) with textual "
              "py2->py3 load-time patches; ArmBall/ArmArrow compute_sensori_effect re-expressed "
              "operation-for-operation from %s@%s src/environments.py with the rpe.py/rge_*.py "
              "configuration. %s." % (EXPLAUTO_VERSION, EXPLAUTO_SHA256, UGSL_REPO, UGSL_COMMIT[:7],
                                      versions))
    doc = {
        "source": source,
        "seeds": {"random_thetas": SEED_RANDOM_THETAS, "catch_search": SEED_CATCH_SEARCH,
                  "edge": SEED_EDGE, "rng": "numpy legacy global MT19937, explauto rand_bounds"},
        "dmp": dmp_info,
        "notes": ("object = DynamicEnvironment.update(theta) (end point, step index 49, clipped to "
                  "[-1,1]^d); moved = object attached at some step; catch_step = first 0-based step "
                  "index where it got attached (null if never); catch_margin = min over the steps "
                  "before the catch (all 50 if none) of |(hx-ox)**2 + (hy-oy)**2 - 0.1*0.1|, to spot "
                  "cases a ULP-level difference could flip; hand = hand position computed at "
                  "step index 49 (not clipped). kind: random_* (first 300 of seed random_thetas), "
                  "caught_* (caught thetas found in seed catch_search), edge_*. trajectories: "
                  "dmp_output = 50x7 joint commands from the DMP (after the theta clip and x1000), "
                  "clipped = the same after clipping to [-1,1] (what the arm uses)."),
        "stats": stats,
        "cross_check_vs_paper_notes_reimplementation": check,
        "armball": rollouts["armball"],
        "armarrow": rollouts["armarrow"],
        "trajectories": rollouts["trajectories"],
    }
    os.makedirs(args.out_dir, exist_ok=True)
    p1 = os.path.join(args.out_dir, "orig_rollouts.json")
    with open(p1, "w") as f:
        json.dump(doc, f, indent=1, allow_nan=False)
        f.write("\n")

    kdoc = {
        "source": ("Produced by scripts/original_fixtures.py: the KL-coverage of UGSL "
                   "Performance_Comparison.ipynb cell 2 (np.histogramdd, 30 bins/dim over [-1,1]; "
                   "q = attainable mask; klc = scipy.stats.entropy(p.ravel(), q.ravel())). "
                   + versions + "."),
        "n_bins": N_BINS,
        "attainable_mask": dict(mask_info, note=(
            "exact set of 30x30 bins whose interior meets the open unit disk; identical to the "
            "notebook's Monte-Carlo mask (1e6 rejection samples, np.random.seed(%d)). "
            "ArmArrow mask = np.tile(mask.reshape(30,30,1), 30). Indices are into the C-order "
            "ravel (ix*30 + iy)." % SEED_MC_MASK), nonzero_indices=mask_idx),
        "ln_756": math.log(756), "ln_22680": math.log(22680),
        "notes": ("klc is repr of a float64, or the string \"inf\". nonempty_bins = number of "
                  "non-zero bins of p; n_in_range = number of points counted by histogramdd "
                  "(points outside [-1,1] in any coordinate are dropped; a value equal to 1.0 "
                  "goes to the last bin)."),
        "armball": klc_sets["armball"],
        "armarrow": klc_sets["armarrow"],
    }
    p2 = os.path.join(args.out_dir, "orig_klc.json")
    with open(p2, "w") as f:
        json.dump(kdoc, f, indent=None, separators=(",", ":"), allow_nan=False)
        f.write("\n")

    print(json.dumps({"dmp": dmp_info, "stats": stats, "cross_check": check, "mask": mask_info,
                      "written": [p1, p2],
                      "sizes": [os.path.getsize(p1), os.path.getsize(p2)]}, indent=1))
    fr = sources["models/pydmps/dmp_discrete.py"]
    print("gen_front_term body:", [l.strip() for l in fr.splitlines() if "return x" in l])
    print("width line:", [l.strip() for l in fr.splitlines() if "self.h =" in l])


if __name__ == "__main__":
    main()
