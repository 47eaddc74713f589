#!/usr/bin/env bash
# Isomap on 10,000 ArmArrow images (states uniform on [-1,1]^3, all distinct: the all-pairs
# Dijkstra cannot merge identical images), 5 neighbours, 3 latents: our fit (the ignored test
# `measure_fit_10k_arrows`, which prints its phases) and scikit-learn's `Isomap.fit` on the same
# images, alternating in the same minutes on an otherwise idle machine. Each side uses every core
# (ours: rayon; sklearn: n_jobs=-1 for the neighbours; scipy's shortest_path is single-threaded).
#
#   scripts/isomap_side_by_side.sh [rounds]      (needs numpy and scikit-learn)
set -euo pipefail
rounds=${1:-2}
images=${TMPDIR:-/tmp}/ugl_isomap_arrows.npy
cargo test -q -p ugl-bench --test isomap measure_fit_10k_arrows --no-run 2>/dev/null
run_ours() {
  cargo test -q -p ugl-bench --test isomap measure_fit_10k_arrows -- --ignored --nocapture 2>&1 |
    grep -E "^(fit|phases|embedding)"
}
UGL_ISOMAP_DUMP=$images cargo test -q -p ugl-bench --test isomap measure_fit_10k_arrows -- \
  --ignored --nocapture >/dev/null 2>&1
for r in $(seq "$rounds"); do
  echo "round $r: ugl-bench"
  run_ours
  echo "round $r: scikit-learn"
  python3 - "$images" <<'PY'
import sys, time
import numpy as np
from sklearn.manifold import Isomap
x = np.load(sys.argv[1]).astype(np.float64)
t = time.perf_counter()
Isomap(n_neighbors=5, n_components=3, n_jobs=-1).fit(x)
print(f"fit 10000 arrows, 3 latents: {time.perf_counter() - t:.2f}s (sklearn)")
PY
done
rm -f "$images"
