#!/usr/bin/env bash
# When does a network leave the mean-image plateau? Trains one network per line of the matrix
# below with `ugl run` (10,000 ArmBall/ArmArrow images, the product path, no model cache) and
# prints, from its manifest, the training loss every 4 x `log_every` iterations, the final
# reconstruction loss as a fraction of the plateau (the mean-image loss), and the latent quality.
#
#   scripts/init_escape.sh OUT_DIR "model hidden1 hidden2 init iterations lr env latents seed" ...
#
# Example: scripts/init_escape.sh /tmp/escape "vae 512 256 he 1500 0.001 armball 10 0"
set -euo pipefail
out=$1; shift
mkdir -p "$out"
UGL=${UGL:-./target/debug/ugl}
for line in "$@"; do
  read -r model h1 h2 init iters lr env latents seed <<<"$line"
  name="$env.$model.$h1-$h2.$init.lr$lr.it$iters.l$latents.s$seed"
  prof="$out/$name.toml"
  extra=""; [ "$model" = rfvae ] && extra="warmup = $((iters / 5))"
  cat >"$prof" <<TOML
[campaign]
name = "init-escape"
seed = 0
reps = 1
[matrix]
envs = ["$env"]
algos = ["rge-$model"]
latents = [$latents]
[ugl]
images = 10000
[explore]
epochs = 1
[learners.$model]
iterations = $iters
hidden = [$h1, $h2]
lr = $lr
init = "$init"
log_every = 25
$extra
TOML
  t0=$(date +%s)
  "$UGL" run --env "$env" --algo "rge-$model" --latents "$latents" --seed "$seed" \
    --profile "$prof" --out "$out/$name" --no-cache >/dev/null
  t1=$(date +%s)
  python3 - "$out/$name" "$name" $((t1 - t0)) <<'PY'
import json, glob, sys
m = json.load(open(glob.glob(sys.argv[1] + "/*.json")[0]))
losses = m["train"]["losses"]
ev = m["train"].get("evidence") or {}
q = m.get("latent_quality") or {}
print(sys.argv[2], f"({sys.argv[3]} s):", " ".join(f"{i}:{l:.0f}" for i, l in losses[::4]),
      f"| reconstruction/plateau {ev.get('loss_fraction', float('nan')):.3f}",
      f"R2 lin {q.get('linear_r2_mean', float('nan')):.3f} knn {q.get('knn_r2_mean', float('nan')):.3f}", flush=True)
PY
done
