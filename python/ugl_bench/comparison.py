"""`ugl_bench.compare`: rank a learner written as a Python object, as `ugl compare --command`
ranks a program.

The object is pickled (by value with cloudpickle where it is installed, so a class defined in a
notebook works) and served by `python -m ugl_bench.serve` through the external-learner protocol:
the same cells, repetitions, data sets and exploration streams as `ugl compare`, the same store
(`compare-NAME`) and the same summary page. Each fitted model is one process, started by the
command line for its cell and repetition.
"""

from __future__ import annotations

import json
import os
import shlex
import shutil
import subprocess
import sys
import tempfile
from dataclasses import dataclass, field
from pathlib import Path
from typing import List, Optional, Union

PathLike = Union[str, os.PathLike]


@dataclass
class CompareResult:
    """What `compare` produced: the store, the campaign's name, the summary page `ugl compare`
    printed (None when the main campaign's results are not beside the store, so nothing ranks
    it yet), and the manifests of its runs."""

    out: Path
    campaign: str
    page: Optional[str]
    manifests: List[dict] = field(default_factory=list)


def find_ugl(ugl: Optional[PathLike] = None) -> Path:
    """The `ugl` command line: `ugl`, else $UGL_BIN, else `ugl` on the PATH."""
    for candidate in (ugl, os.environ.get("UGL_BIN"), shutil.which("ugl")):
        if candidate and Path(candidate).is_file():
            return Path(candidate)
    raise FileNotFoundError(
        "compare needs the ugl command line: build it in the repository (cargo build --bin ugl, "
        "then pass ugl='target/debug/ugl' or set UGL_BIN) or install it (cargo install --path .)"
    )


def _pickle(learner, path: Path) -> str:
    try:
        import cloudpickle as pickler
    except ImportError:
        import pickle as pickler
    try:
        data = pickler.dumps(learner)
    except Exception as e:
        raise TypeError(
            f"compare runs the learner in a separate process, so it must be picklable: "
            f"{type(e).__name__}: {e}"
        ) from None
    path.write_bytes(data)
    return pickler.__name__


def compare(
    learner,
    name: str,
    config: PathLike = "data/campaigns/paper.toml",
    out: Optional[PathLike] = None,
    jobs: Optional[int] = None,
    gaussian: bool = False,
    ugl: Optional[PathLike] = None,
    cache: Optional[PathLike] = None,
    quiet: bool = True,
    cwd: Optional[PathLike] = None,
) -> CompareResult:
    """Run ``learner`` on the cells and repetitions of the campaign ``config`` and return the
    result (see :class:`CompareResult`).

    ``learner`` is any object with ``fit(images, latents, seed)`` and ``encode(images) -> (m,
    latents)`` (and optionally ``prior() -> (mean, std)``, which ``gaussian=True`` needs for the
    prior-goal runs). ``images`` are float32 (n, values) in [0, 1] (docs/external-learners.md
    gives the pixel order); ``seed`` is the run's learner seed: seed everything with it, and
    encode deterministically. ``name`` names the learner (``rge-NAME`` in the store). ``out``
    defaults to ``data/results/compare-NAME`` under ``cwd`` (the current directory), as for
    ``ugl compare``; ``jobs`` runs in parallel; ``cache`` is the model cache directory.
    """
    for method in ("fit", "encode"):
        if not callable(getattr(learner, method, None)):
            raise TypeError(f"learner: {type(learner).__name__} has no {method}() method")
    if not isinstance(name, str) or not name:
        raise ValueError("name: expected the learner's name, e.g. 'myvae'")
    if gaussian and not callable(getattr(learner, "prior", None)):
        raise ValueError("gaussian=True needs the learner's prior(): it has none")
    binary = find_ugl(ugl)
    work = Path(tempfile.mkdtemp(prefix="ugl-compare-"))
    try:
        pkl = work / "learner.pkl"
        _pickle(learner, pkl)
        command = f"{shlex.quote(sys.executable)} -m ugl_bench.serve {shlex.quote(str(pkl))}"
        argv = [str(binary), "compare", "--learner", name, "--command", command, "--config", str(config)]
        if out is not None:
            argv += ["--out", str(out)]
        if jobs is not None:
            argv += ["--jobs", str(int(jobs))]
        if gaussian:
            argv.append("--gaussian")
        if cache is not None:
            argv += ["--cache", str(cache)]
        if quiet:
            argv.append("--quiet")
        env = dict(os.environ)
        # The learner's process imports what this one can (a model class in a local module).
        paths = [p for p in sys.path if p and os.path.isdir(p)]
        env["PYTHONPATH"] = os.pathsep.join(paths + [env.get("PYTHONPATH", "")]).rstrip(os.pathsep)
        proc = subprocess.run(argv, cwd=cwd, env=env, capture_output=True, text=True)
        if proc.returncode != 0:
            tail = "\n".join(proc.stderr.strip().splitlines()[-25:])
            raise RuntimeError(f"ugl compare failed (exit {proc.returncode}):\n{tail}")
    finally:
        shutil.rmtree(work, ignore_errors=True)
    campaign = f"compare-{name}"
    store = Path(cwd or ".") / (out if out is not None else Path("data/results") / campaign)
    manifests = []
    for path in sorted(store.glob("*.json")):
        try:
            m = json.loads(path.read_text())
        except ValueError:
            continue
        if isinstance(m, dict) and "run_id" in m:
            manifests.append(m)
    page = proc.stdout.strip() or None
    return CompareResult(out=store, campaign=campaign, page=page, manifests=manifests)
