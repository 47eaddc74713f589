#!/usr/bin/env bash
# Training speed side by side: one iteration of ugl-bench's default (host) engine, timed by the
# criterion bench `train_step`, and the same iteration in PyTorch (scripts/torch_train_step.py),
# alternating in the same minutes for every model (AE, VAE, RFVAE), architecture (4900-1200-1200,
# 4900-512-256) and thread count (1, 2). Prints the two medians and torch / ugl (> 1: ugl faster).
# Run it on an otherwise idle machine (no build, no campaign).
#
# Usage: scripts/train_step_side_by_side.sh [ROUNDS (default 2)] [MODELS (default "ae vae rfvae")]
# Needs python3 with torch and numpy; not used by CI or tests.
set -euo pipefail
cd "$(dirname "$0")/.."
rounds=${1:-2}
models=${2:-ae vae rfvae}
bench=$(cargo bench -p ugl-bench --profile dev --bench train_step --no-run 2>&1 |
  sed -n 's/.*Executable .*(\(.*\))$/\1/p' | tail -1)
[ -x "$bench" ] || { echo "could not build the train_step bench" >&2; exit 1; }

# Median of a criterion run, in ms.
ugl_ms() { # arch model threads
  RAYON_NUM_THREADS=$3 "$bench" --bench "^train_step/$1/$2/host\$" 2>/dev/null |
    awk '/time:/ { v = $4; u = $5; sub(/\]/, "", u);
                   if (u == "s") v *= 1000; else if (u == "µs" || u == "us") v /= 1000;
                   print v; exit }'
}
torch_ms() { # hidden1 hidden2 model threads
  python3 scripts/torch_train_step.py --model "$3" --hidden "$1" "$2" --threads "$4" --iters 30 |
    sed -n 's/.*median \([0-9.]*\) ms.*/\1/p'
}

printf '%-6s %-16s %7s %5s %10s %10s %8s\n' model network threads round ugl_ms torch_ms torch/ugl
for round in $(seq 1 "$rounds"); do
  for arch in paper-1200-1200 reduced-512-256; do
    case $arch in paper-1200-1200) h="1200 1200" ;; *) h="512 256" ;; esac
    for model in $models; do
      for threads in 1 2; do
        u=$(ugl_ms "$arch" "$model" "$threads")
        t=$(torch_ms $h "$model" "$threads")
        printf '%-6s %-16s %7s %5s %10.1f %10.1f %8.2f\n' "$model" "4900-${h/ /-}" "$threads" \
          "$round" "$u" "$t" "$(echo "$t / $u" | bc -l)"
      done
    done
  done
done
