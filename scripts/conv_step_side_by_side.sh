#!/usr/bin/env bash
# The follow-up's training step side by side: one iteration of our convolutional beta-VAE (the
# criterion bench `conv_step` of ugl-bench) and PyTorch's (scripts/torch_conv_vae_step.py), the
# same architecture and batch (64), alternating at 1 and 2 threads. Prints both medians and
# torch / ugl (> 1: ours faster). Run it on an otherwise idle machine (no build, no campaign).
#
# Usage: scripts/conv_step_side_by_side.sh [ROUNDS (default 2)]. Needs python3 with torch.
set -euo pipefail
cd "$(dirname "$0")/.."
rounds=${1:-2}
bench=$(cargo bench -p ugl-bench --profile dev --bench conv_step --no-run 2>&1 |
  sed -n 's/.*Executable .*(\(.*\))$/\1/p' | tail -1)
[ -x "$bench" ] || { echo "could not build the conv_step bench" >&2; exit 1; }
ugl_ms() {
  RAYON_NUM_THREADS=$1 "$bench" --bench 2>/dev/null |
    awk '/time:/ { v = $4; u = $5; sub(/\]/, "", u);
                   if (u == "s") v *= 1000; else if (u == "µs" || u == "us") v /= 1000;
                   print v; exit }'
}
torch_ms() {
  python3 scripts/torch_conv_vae_step.py --threads "$1" --iters 30 |
    sed -n 's/.*median \([0-9.]*\) ms.*/\1/p'
}
printf '%7s %5s %10s %10s %9s\n' threads round ugl_ms torch_ms torch/ugl
for r in $(seq 1 "$rounds"); do
  for t in 1 2; do
    u=$(ugl_ms "$t"); p=$(torch_ms "$t")
    printf '%7s %5s %10s %10s %9.2f\n' "$t" "$r" "$u" "$p" "$(echo "$p / $u" | bc -l)"
  done
done
