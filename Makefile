# ugl-bench — the two commands a new user types: `make report` and `make test`.
# One build profile everywhere (cargo's dev profile, with the science crates optimised; see
# Cargo.toml), so tests, campaigns and the report share one build.

SHELL := /bin/bash
CARGO ?= cargo
PROFILE ?= baselines
RESULTS ?= data/results
REPORT_OUT ?= report/out
JOBS ?=
MIN_RUST := 1.95
UGL := $(CARGO) run --quiet --bin ugl --

.PHONY: help report test test-cargo test-python test-slurm lint campaign bench verify verify-update verify-store check-toolchain check-shared-build

help:
	@echo "make report              regenerate report/out/REPORT.md and its SVG figures from data/results"
	@echo "make test                the test suite (what CI runs): test-cargo, check-shared-build, test-python, test-slurm, verify-store"
	@echo "make test-cargo          cargo test --workspace, but the Python extension (no cluster needed)"
	@echo "make test-python         build the Python package into a virtual environment (target/py-venv) and run pytest"
	@echo "make test-slurm          the cluster path on a private single-node Slurm (root; slurm-wlm, munge)"
	@echo "make lint                cargo fmt --check and cargo clippy -D warnings (CI runs it first)"
	@echo "make campaign PROFILE=p  run data/campaigns/p.toml into data/results/p (resumable)"
	@echo "make bench               criterion benchmarks (rollout, render, NN query, KLC, Isomap)"
	@echo "make verify              rerun the smoke campaign on every kernel path; compare bytes with data/checksums/smoke.sha256"
	@echo "make verify-store        rerun a stratified sample of the committed runs (ugl verify) and compare bytes"

lint: check-toolchain
	$(CARGO) fmt --all -- --check
	$(CARGO) clippy --workspace --all-targets --quiet -- -D warnings

check-toolchain:
	@command -v $(CARGO) >/dev/null 2>&1 || { echo "error: cargo not found. Install Rust $(MIN_RUST) or newer: https://rustup.rs" >&2; exit 1; }
	@v=$$(rustc --version | awk '{print $$2}'); \
	if [ "$$(printf '%s\n%s\n' "$(MIN_RUST)" "$$v" | sort -V | head -1)" != "$(MIN_RUST)" ]; then \
	  echo "error: rustc $$v is too old; ugl-bench needs Rust $(MIN_RUST) or newer (rustup update)" >&2; exit 1; fi

# The report renders from the committed results of the MAIN campaign (default: paper) plus the
# budget-* campaigns. Without results, run `make campaign PROFILE=paper` first (about 2-2.5 h on 2
# cores; `make report MAIN=quick` after `make campaign PROFILE=quick` for an 11-minute look).
MAIN ?= paper
report: check-toolchain
	@if ! ls $(RESULTS)/$(MAIN)/*.json >/dev/null 2>&1; then \
	  echo "error: no results in $(RESULTS)/$(MAIN): run 'make campaign PROFILE=$(MAIN)' first" >&2; exit 2; fi
	$(UGL) report --results $(RESULTS) --out $(REPORT_OUT) --main $(MAIN)
	@echo "report: $(REPORT_OUT)/REPORT.md"

test: test-cargo check-shared-build test-python test-slurm verify-store

# The Python extension (python/) is left out here and built by test-python: its macros turn on a
# feature of a shared build dependency (syn's visit-mut, for pyo3's macros), and with it in the
# same build every derive macro, and all that uses them (burn, polars), would be compiled in a
# variant that `cargo run --bin ugl` does not share (check-shared-build).
test-cargo: check-toolchain
	$(CARGO) test --workspace --exclude ugl-python

# The Python package (python/, docs/python.md): a virtual environment under target/, the package
# built by maturin in the workspace's one build profile (so it reuses target/), and its pytest
# cases, which compare it with the command line's rollouts and pictures (the ugl binary).
PYTHON ?= python3
PY_VENV ?= target/py-venv
test-python: check-toolchain
	@$(PYTHON) -m venv --help >/dev/null 2>&1 || { echo "error: $(PYTHON) has no venv module (Debian: apt-get install python3-venv)" >&2; exit 1; }
	$(CARGO) build --bin ugl --quiet
	$(PYTHON) -m venv $(PY_VENV)
	$(PY_VENV)/bin/python -m pip install --quiet --disable-pip-version-check "maturin>=1.8,<2" "numpy>=1.21" "gymnasium>=0.29" "pytest>=7" "cloudpickle>=2"
	PATH="$(CURDIR)/$(PY_VENV)/bin:$$PATH" $(PY_VENV)/bin/python -m pip install --quiet --disable-pip-version-check --no-build-isolation --force-reinstall --no-deps ./python
	UGL_BIN=$(CURDIR)/target/debug/ugl $(PY_VENV)/bin/python -m pytest -q -p no:cacheprovider python/tests

# The cluster path on a real Slurm: a private single-node cluster started and stopped by the
# test (tests/slurm/real_cluster.sh). Needs root and Debian's slurm-wlm + munge (.ci/run installs
# them); without them it fails and says so.
test-slurm: check-toolchain
	bash tests/slurm/real_cluster.sh

# The committed results themselves, not only the smoke campaign: `ugl verify` checks every run's
# files against its manifest, then reruns VERIFY_SAMPLE runs (stratified over the conditions, a
# trained network among them) from the campaign's profile and compares their bytes. The main
# store, of the current results version (a rerun fills data/results-pending/ first), and the
# `ugl compare` example of a Rust learner (its runs all trained networks: one is rerun). Each
# entry is DIR or DIR:N (N runs instead of VERIFY_SAMPLE). Not `compare-random-projection`: its
# learner is a Python program whose numpy products depend on the machine's BLAS. And the
# follow-up's `followup-still` (the authors' ArmBalls, no network: RPE, RGE-EFR and MGE-EFR with
# learning progress, one run each), complete while `followup` is still running.
VERIFY_STORES ?= data/results/paper data/results/compare-bvae:1 data/results-pending/followup-still
# Stores whose networks take too long to retrain in CI (the follow-up's convolutional VAEs and
# β-VAEs, about 20 min each on 2 cores): their network-free runs are rerun
# (`ugl verify --without-networks`), their networks checked against their digests only.
VERIFY_STORES_WITHOUT_NETWORKS ?= data/results-pending/followup
VERIFY_SAMPLE ?= 3
verify-store: check-toolchain
	@for e in $(VERIFY_STORES); do d=$${e%%:*}; n=$${e#*:}; [ "$$n" = "$$e" ] && n=$(VERIFY_SAMPLE); \
	  $(UGL) verify --results $$d --sample $$n || exit 1; done
	@for e in $(VERIFY_STORES_WITHOUT_NETWORKS); do d=$${e%%:*}; n=$${e#*:}; [ "$$n" = "$$e" ] && n=$(VERIFY_SAMPLE); \
	  $(UGL) verify --results $$d --sample $$n --without-networks || exit 1; done

campaign: check-toolchain
	$(UGL) campaign --config data/campaigns/$(PROFILE).toml --out $(RESULTS)/$(PROFILE) $(if $(JOBS),--jobs $(JOBS))

bench: check-toolchain
	$(CARGO) bench -p ugl-bench --profile dev  # rollout, render, nn_query, klc, isomap

# Reproducibility check: on every kernel path the CPU has (UGL_SIMD), the smoke campaign's result
# files must hash to the committed checksums
# (`tests/verify_smoke.rs`, also part of `make test`, so CI builds the binary once). A change that
# alters results shows up here, and in review as a change of data/checksums/smoke.sha256
# (`make verify-update`).
verify: check-toolchain
	$(CARGO) test --test verify_smoke

# `make report` / `make campaign` (cargo run) must reuse the artifacts of `make test` (cargo test
# --workspace): one feature resolution for both (root Cargo.toml, "Feature unification"). `make
# test` runs it right after test-cargo (before test-python and test-slurm build the binary, which
# would hide a divergence); it fails if building the binary would compile any crate again.
check-shared-build: check-toolchain
	@rebuilt=$$($(CARGO) build --bin ugl --message-format=json 2>/dev/null | grep -c '"fresh":false' || true); \
	if [ "$$rebuilt" != "0" ]; then \
	  echo "error: cargo run --bin ugl recompiles $$rebuilt crates after cargo test --workspace: the feature sets differ (see Cargo.toml, Feature unification)" >&2; exit 1; fi; \
	echo "check-shared-build: make report reuses the test build (0 crates recompiled)"

verify-update: check-toolchain
	UGL_VERIFY_UPDATE=1 $(CARGO) test --test verify_smoke -- --nocapture
