"""`ugl_bench.compare`: a learner object ranked as `ugl compare --command` ranks a program."""

import subprocess
import sys
import threading
from pathlib import Path

import pytest

import ugl_bench

REPO = Path(__file__).resolve().parents[2]
sys.path.insert(0, str(REPO / "examples"))
from python_learner_numpy import RandomProjection  # noqa: E402

BASE = (
    '[campaign]\nname = "base"\nreps = 2\n[matrix]\nenvs = ["armball"]\n'
    'algos = ["rpe", "rge-pca"]\nsamplers = ["kde"]\nlatents = ["true"]\n'
    "[ugl]\nimages = 200\n[explore]\nepochs = 200\n"
)


def ugl_binary():
    import os

    path = Path(os.environ.get("UGL_BIN", REPO / "target" / "debug" / "ugl"))
    if not path.exists():
        pytest.skip(f"no ugl binary at {path}: build it (cargo build --bin ugl) or set UGL_BIN")
    return path


@pytest.fixture
def base(tmp_path):
    path = tmp_path / "base.toml"
    path.write_text(BASE)
    return path


def test_an_object_gives_the_bytes_of_the_same_model_as_a_program(base, tmp_path):
    ugl = ugl_binary()
    ours = ugl_bench.compare(RandomProjection(), name="rp", config=base, out=tmp_path / "obj", ugl=ugl)
    program = REPO / "scripts" / "external_learners" / "random_projection.py"
    subprocess.run(
        [
            str(ugl),
            "compare",
            "--learner",
            "rp",
            "--command",
            f"{sys.executable} {program}",
            "--config",
            str(base),
            "--out",
            str(tmp_path / "prog"),
            "--quiet",
        ],
        check=True,
        capture_output=True,
    )
    assert ours.campaign == "compare-rp"
    # The base campaign's cells (armball, its 2 true latents, KDE goals) and 2 repetitions.
    ids = sorted(m["run_id"] for m in ours.manifests)
    assert len(ids) == 2 and all(i.startswith("armball.") and ".kde.l2.s" in i for i in ids), ids
    assert {m["campaign"] for m in ours.manifests} == {"compare-rp"}
    files = sorted(p.name for p in (tmp_path / "prog").glob("*.parquet"))
    assert files and files == sorted(p.name for p in ours.out.glob("*.parquet"))
    for name in files:
        assert (tmp_path / "obj" / name).read_bytes() == (tmp_path / "prog" / name).read_bytes(), name
    # No main campaign beside the store: no page, and the result says so with None.
    assert ours.page is None


class Boom:
    def fit(self, images, latents, seed):
        raise ValueError("boom: this learner cannot fit")

    def encode(self, images):
        return images[:, :2]


class Locked(RandomProjection):
    def __init__(self):
        self.lock = threading.Lock()


def test_a_learner_that_raises_fails_with_its_message(base, tmp_path):
    with pytest.raises(RuntimeError, match="boom: this learner cannot fit"):
        ugl_bench.compare(Boom(), name="boom", config=base, out=tmp_path / "b", ugl=ugl_binary())


@pytest.mark.parametrize(
    "call, error, message",
    [
        (lambda b: ugl_bench.compare(object(), name="x", config=b), TypeError, "no fit"),
        (lambda b: ugl_bench.compare(Locked(), name="x", config=b, ugl=ugl_binary()), TypeError, "picklable"),
        (lambda b: ugl_bench.compare(RandomProjection(), name="", config=b), ValueError, "name"),
        (lambda b: ugl_bench.compare(RandomProjection(), name="x", config=b, gaussian=True), ValueError, "prior"),
        (lambda b: ugl_bench.compare(RandomProjection(), name="x", config=b, ugl="/nonexistent/ugl"), FileNotFoundError, "ugl command line"),
        (lambda b: ugl_bench.compare(RandomProjection(), name="Bad Name", config=b, ugl=ugl_binary()), RuntimeError, "--learner"),
    ],
)
def test_bad_input_raises_one_clear_exception(base, call, error, message, monkeypatch):
    monkeypatch.delenv("UGL_BIN", raising=False)
    monkeypatch.setenv("PATH", "/nonexistent")
    with pytest.raises(error, match=message):
        call(base)


def test_the_torch_example_runs_where_torch_is_installed(base, tmp_path):
    torch = pytest.importorskip("torch", reason="torch is not installed: the PyTorch example is skipped")
    assert torch
    from python_learner_torch import TorchAutoEncoder

    r = ugl_bench.compare(TorchAutoEncoder(iterations=20), name="tae", config=base, out=tmp_path / "t", ugl=ugl_binary())
    assert len(r.manifests) == 2
    again = ugl_bench.compare(TorchAutoEncoder(iterations=20), name="tae", config=base, out=tmp_path / "u", ugl=ugl_binary())
    for m in r.manifests:
        name = m["run_id"] + ".parquet"
        assert (r.out / name).read_bytes() == (again.out / name).read_bytes(), name
