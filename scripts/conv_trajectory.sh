#!/usr/bin/env bash
# The path of a sweep's networks through their training (issue 44; docs/neural.md, "The sweep"):
# for each kept checkpoint of (SETTING, SEED) in OUT/models (scripts/conv_sweep.sh keeps them),
# `ugl embed --checkpoint N` measures the network after N iterations (per-latent KL, each latent's
# object, MIG, SAP, the training evidence), one JSON line per checkpoint, into
# OUT/TAG/checkpoints.sSEED.jsonl beside the run's manifest (TAG: the setting as conv_sweep.sh
# names its folder), then the finished network's own line where the model cache has it.
#
#   scripts/conv_trajectory.sh OUT SETTING SEED
#
# Environment: UGL (the binary; default target/debug/ugl, built first), CACHE (where the
# checkpoints are; default OUT/models).
set -euo pipefail
out="${1:?usage: scripts/conv_trajectory.sh OUT SETTING SEED}"
setting="${2:?give the SETTING, as given to scripts/conv_sweep.sh}"
seed="${3:?give the SEED}"
out="$(cd "$out" && pwd)"
cache="${CACHE:-$out/models}"
cache="$(cd "$cache" && pwd)"
. "$(dirname "$0")/enter_repository.sh"
enter_repository
tag="$(echo "$setting" | tr ',=' '_-')"
dir="$out/$tag"
[ -f "$dir/profile.toml" ] || { echo "error: $dir/profile.toml: train the setting first (scripts/conv_sweep.sh)" >&2; exit 2; }
case "$setting" in
  vae | vae,*) learner=conv-vae ;;
  *) learner=conv-bvae ;;
esac
embed() {
  "$ugl" embed --env armballs-corl --learner "$learner" --latents 10 --seed "$seed" \
    --profile "$dir/profile.toml" --cache "$cache" --out "$tmp/z.npy" --grid 2 "$@" | tail -n 1
}
tmp="$(mktemp -d)"
trap 'rm -rf "$tmp"' EXIT
# The run's manifest names its network's model-cache key, and with it the checkpoints.
manifest="$(ls "$dir"/*.s"$seed".json 2>/dev/null | head -n 1 || true)"
[ -n "$manifest" ] || { echo "error: no manifest of seed $seed in $dir: train it first (scripts/conv_sweep.sh)" >&2; exit 2; }
key="$(python3 -c 'import json, sys; print(json.load(open(sys.argv[1]))["train"]["key"])' "$manifest")"
held="$(ls -d "$cache/$key".ckpt.* 2>/dev/null | sed 's/.*\.ckpt\.//' | sort -n || true)"
[ -n "$held" ] || { echo "error: no checkpoint of $tag seed $seed in $cache" >&2; exit 2; }
file="$dir/checkpoints.s$seed.jsonl"
: > "$tmp/lines"
for n in $held; do
  echo "$tag seed $seed: iteration $n" >&2
  embed --checkpoint "$n" >> "$tmp/lines"
done
# The finished network, where the model cache has it (never trained here).
if [ -f "$cache/$key.model" ]; then embed >> "$tmp/lines"; fi
mv "$tmp/lines" "$file"
echo "$file"
