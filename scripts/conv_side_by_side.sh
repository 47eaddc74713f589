#!/usr/bin/env bash
# The follow-up's convolutions side by side with PyTorch, the same layers and batch (64),
# alternating, at 1 and 2 threads. Prints both medians and torch / ugl (> 1: ours faster). Run it
# on an otherwise idle machine (no build, no campaign).
#   stack (default): the eight convolution layers, forward and every gradient (criterion bench
#                    `conv` of ugl-kernels; scripts/torch_conv_stack.py);
#   step:            one training iteration of the convolutional beta-VAE (criterion bench
#                    `conv_step` of ugl-bench; scripts/torch_conv_vae_step.py).
#
# Usage: scripts/conv_side_by_side.sh [stack|step] [ROUNDS (default 2)]. Needs a Python with torch:
# $PYTHON (default python3).
set -euo pipefail
cd "$(dirname "$0")/.."
what=stack
case ${1:-} in stack|step) what=$1; shift ;; esac
rounds=${1:-2}
case $what in
  stack) crate=ugl-kernels bench_name=conv torch_script=scripts/torch_conv_stack.py iters=20 ;;
  step) crate=ugl-bench bench_name=conv_step torch_script=scripts/torch_conv_vae_step.py iters=30 ;;
esac
bench=$(cargo bench -p "$crate" --profile dev --bench "$bench_name" --no-run 2>&1 |
  sed -n 's/.*Executable .*(\(.*\))$/\1/p' | tail -1)
[ -x "$bench" ] || { echo "could not build the $bench_name bench" >&2; exit 1; }
ugl_ms() {
  RAYON_NUM_THREADS=$1 "$bench" --bench 2>/dev/null |
    awk '/time:/ { v = $4; u = $5; sub(/\]/, "", u);
                   if (u == "s") v *= 1000; else if (u == "µs" || u == "us") v /= 1000;
                   print v; exit }'
}
torch_ms() {
  "${PYTHON:-python3}" "$torch_script" --threads "$1" --iters "$iters" | sed -n 's/.*median \([0-9.]*\) ms.*/\1/p'
}
printf '%7s %5s %10s %10s %9s\n' threads round ugl_ms torch_ms torch/ugl
for r in $(seq 1 "$rounds"); do
  for t in 1 2; do
    u=$(ugl_ms "$t"); p=$(torch_ms "$t")
    printf '%7s %5s %10s %10s %9.2f\n' "$t" "$r" "$u" "$p" "$(echo "$p / $u" | bc -l)"
  done
done
