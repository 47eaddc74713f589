#!/usr/bin/env bash
# A long rerun in resumable chunks (docs/running.md, "A long rerun"): copy the finished runs of
# a rerun checkout's data/results-pending/ into this checkout's, to be committed.
#   scripts/rerun_collect.sh RERUN_CHECKOUT [CAMPAIGN...]   (default: every campaign there)
# The rerun checkout is a clean worktree at the rerun's commit (its runs record that revision);
# only complete run files are copied (each is written to a temporary name, then renamed), never
# the model cache, checkpoints or the store's lock, nor the files this checkout's git ignores
# (the outcomes files kept only for some replicates: copied, a report rendered here would check
# more records than a fresh clone's). `ugl status` then counts what is done.
set -euo pipefail
src="${1:?usage: scripts/rerun_collect.sh RERUN_CHECKOUT [CAMPAIGN...]}"
shift
cd "$(dirname "$0")/.."
[ -d "$src/data/results-pending" ] || { echo "error: $src/data/results-pending: no such directory" >&2; exit 2; }
if [ $# -eq 0 ]; then
  set -- $(ls "$src/data/results-pending")
fi
ignored_list="$(mktemp)"
trap 'rm -f "$ignored_list"' EXIT
for name in "$@"; do
  from="$src/data/results-pending/$name"
  [ -f "$from/campaign.toml" ] || { echo "error: $from: no campaign.toml" >&2; exit 2; }
  mkdir -p "data/results-pending/$name"
  (cd "$from" && find . -path ./models -prune -o -type f ! -name '*.tmp' ! -name .ugl-store.lock \
    ! -name '*.learner.log' -print0) |
    while IFS= read -r -d '' f; do
      to="data/results-pending/$name/${f#./}"
      if git check-ignore -q "$to"; then
        echo "$to" >> "$ignored_list"
        continue
      fi
      mkdir -p "$(dirname "$to")"
      cp -p "$from/$f" "$to"
    done
  echo "$name: $(ls "data/results-pending/$name"/*.json 2>/dev/null | wc -l) runs" \
    "($(grep -c "^data/results-pending/$name/" "$ignored_list" || true) files git ignores left out)"
done
