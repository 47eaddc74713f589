#!/usr/bin/env bash
# The sweep that chooses the follow-up's convolutional β-VAE settings (issue 44, item 3; its
# measurements and the choice: docs/neural.md). Each SETTING is a comma-separated list of
# [learners.conv-bvae] keys, or `vae` followed by [learners.conv-vae] keys (`vae`: the conv-vae at
# its defaults; `vae,lr=0.01,batch=128`); each is trained on the
# repetition seeds SEEDS (default 1000 1001 1002: seeds the campaigns do not use, so nothing is
# tuned on a campaign's own repetitions) with `ugl run` on armballs-corl, 10 latents, and
# `ugl sweep-table OUT` tabulates what each network's manifest records: its loss fraction, the
# per-latent KL, the latents active and which object each encodes, MIG and SAP.
#
#   scripts/conv_sweep.sh OUT SETTING...
#   e.g. scripts/conv_sweep.sh /tmp/sweep beta=100,capacity=12,iterations=5000 vae vae,lr=0.01
#
# Resumable: a (setting, seed) whose manifest exists is skipped. Environment: UGL (the binary,
# a path from the caller's directory or a command on PATH; default target/debug/ugl, built first), SEEDS, IMAGES (training pictures, default 10000),
# EPOCHS (exploration epochs of each run, default 200: the exploration is not what is measured),
# KEEP_CHECKPOINTS (default 1: keep every checkpoint, for `ugl embed --checkpoint`; 0: not).
set -euo pipefail
out="${1:?usage: scripts/conv_sweep.sh OUT SETTING...}"
shift
[ $# -gt 0 ] || { echo "error: give at least one SETTING (e.g. beta=100,capacity=12)" >&2; exit 2; }
# OUT and a UGL given as a path are read from the caller's directory, before the script moves to
# the repository's root.
mkdir -p "$out"
out="$(cd "$out" && pwd)"
. "$(dirname "$0")/enter_repository.sh"
enter_repository
seeds="${SEEDS:-1000 1001 1002}"
images="${IMAGES:-10000}"
epochs="${EPOCHS:-200}"
# Every checkpoint of each training is kept in OUT/models (5 MB per 1000 iterations) for
# `ugl embed --checkpoint N`: the network part-way (docs/running.md, "Checkpoints").
keep="--keep-checkpoints"
[ "${KEEP_CHECKPOINTS:-1}" = 0 ] && keep=""
mkdir -p "$out"
for setting in "$@"; do
  tag="$(echo "$setting" | tr ',=' '_-')"
  dir="$out/$tag"
  mkdir -p "$dir"
  case "$setting" in
    vae | vae,*) algo=rge-conv-vae table="[learners.conv-vae]" keys="${setting#vae}" ;;
    *) algo=rge-conv-bvae table="[learners.conv-bvae]" keys="$setting" ;;
  esac
  keys="${keys#,}"
  {
    printf '[campaign]\nname = "conv-sweep"\nseed = 0\nreps = 1\n'
    printf '[matrix]\nenvs = ["armballs-corl"]\nalgos = ["%s"]\nlatents = [10]\n' "$algo"
    printf '[ugl]\nimages = %s\n[explore]\nepochs = %s\neval_every = %s\n' "$images" "$epochs" "$epochs"
    printf '%s\n' "$table"
    if [ -n "$keys" ]; then
      # Numbers and booleans as they are, anything else (init=torch) as a TOML string.
      echo "$keys" | tr ',' '\n' | awk -F= '{
        v = $2
        if (v !~ /^(true|false|[-+0-9.eE]+)$/) v = "\"" v "\""
        print $1 " = " v
      }'
    fi
  } > "$dir/profile.toml"
  for seed in $seeds; do
    if ls "$dir"/*.s"$seed".json >/dev/null 2>&1; then
      echo "$tag seed $seed: done"
      continue
    fi
    echo "$tag seed $seed: training ($(date +%H:%M))"
    "$ugl" run --env armballs-corl --algo "$algo" --latents 10 --seed "$seed" \
      --profile "$dir/profile.toml" --out "$dir" --cache "$out/models" $keep > "$dir/s$seed.log"
  done
done
"$ugl" sweep-table "$out"
