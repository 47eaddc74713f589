#!/usr/bin/env bash
# The cluster path on a real Slurm (`make test-slurm`, part of `make test`): a private single-node
# cluster (tests/slurm/cluster.sh) runs the scripts `ugl slurm` writes, with the real sbatch.
# It checks that
#   1. the sharded results are byte-identical to a single-process `ugl campaign` of the config;
#   2. the report step's output lands next to the results, never in the checkout, and the
#      checkout's `git status` is the same afterwards;
#   3. an array task cancelled mid-run (scancel) cancels the report step of that submission
#      (no report from partial results), and resubmitting the task resumes it to the same bytes.
# Every daemon it started is stopped by pid, on success and on failure; a cluster that cannot
# start fails the test with the daemons' log tails. Needs root and Slurm + munge installed
# (Debian: apt-get install slurm-wlm munge; .ci/run installs them).
set -euo pipefail
cd "$(dirname "$0")/../.."
checkout=$(pwd)
# shellcheck source=cluster.sh
source tests/slurm/cluster.sh

T=$(mktemp -d /tmp/ugl-slurm.XXXXXX)
trap 'cluster_stop; rm -rf "$T"' EXIT
step() { echo "slurm test: $*"; }

# Bounded wait until no job of ours is left in the queue.
wait_queue_empty() {
  local what=$1 limit=$2 i
  for i in $(seq 1 $((limit * 5))); do
    [ -z "$(squeue -h -o %i 2>/dev/null)" ] && return 0
    sleep 0.2
  done
  squeue >&2 || true
  cluster_fail "$what: jobs still queued after ${limit} s"
}

# sha256 of every result file (curves, outcomes, interest tables) of a results directory.
digests() { (cd "$1" && sha256sum -- *.parquet | sort -k 2); }

# The checkout's state, before and after. A campaign may be filling data/results-pending/ in this
# checkout meanwhile (its results are kept there until complete): that directory is left out.
checkout_state() { git status --porcelain --untracked-files=all -- . ':!data/results-pending' 2>/dev/null || true; }
git_before=$(checkout_state)
step "building ugl"
ugl=$(cargo build --quiet --bin ugl --message-format=json-render-diagnostics |
  sed -n 's/.*"executable":"\([^"]*\/ugl\)".*/\1/p' | tail -n 1)
[ -x "$ugl" ] || { echo "slurm test: FAILED: cargo build did not report the ugl binary" >&2; exit 1; }

step "starting a private cluster in $T/cluster"
cluster_start "$T/cluster"
step "$(sinfo -h -o '%P %D node(s), %c CPUs, %T') (Slurm $(sinfo -V | awk '{print $2}'))"

# Small, but long enough for a task to be caught mid-run: 18 runs (RPE and RGE-EFR per seed, PCA
# per seed and sampler; PCA's two samplers share a fit), 9 in each of 2 shards.
cat > "$T/slurm-test.toml" <<'TOML'
[campaign]
name = "slurm-test"
reps = 3
description = "The real-Slurm test's campaign (tests/slurm/real_cluster.sh)."
[matrix]
envs = ["armball", "armarrow"]
algos = ["rpe", "rge-efr", "rge-pca"]
samplers = ["kde", "gaussian"]
latents = [3]
[ugl]
images = 200
[explore]
epochs = 4000
eval_every = 1000
TOML
cfg="$T/slurm-test.toml"

step "the same campaign in one process (the reference)"
"$ugl" campaign --config "$cfg" --out "$T/single/slurm-test" --jobs 2 --quiet

# --- 1 and 2: a submission runs to the end ------------------------------------------------------
out="$T/results/slurm-test"
"$ugl" slurm --config "$cfg" --out "$out" --shards 3 --cpus 1 --time 00:10:00 ||
  cluster_fail "ugl slurm refused the job"
step "submitting (3 tasks and the report step)"
bash "$out/slurm/submit.sh" || cluster_fail "submit.sh failed"
wait_queue_empty "the first submission" 240
[ -f "$out/report/REPORT.md" ] || {
  cat "$out"/slurm/logs/*.log >&2 || true
  cluster_fail "the report step wrote no $out/report/REPORT.md"
}
grep -q "slurm-test" "$out/report/REPORT.md" || cluster_fail "the report does not draw on the campaign"
[ "$(digests "$out")" = "$(digests "$T/single/slurm-test")" ] ||
  cluster_fail "the sharded results differ from the single-process campaign's"
step "the sharded results are byte-identical to the single-process campaign ($(digests "$out" | wc -l) files)"
[ "$(checkout_state)" = "$git_before" ] ||
  cluster_fail "the cluster path changed the checkout: $(diff <(echo "$git_before") <(checkout_state) | head -5)"
[ ! -e "$checkout/report/out/slurm-test.md" ] && [ ! -e "$checkout/data/results/slurm-test" ] ||
  cluster_fail "the cluster path wrote into the checkout"
step "the report is in $out/report; the checkout is untouched"

# --- 3: a task cancelled mid-run, resubmitted ------------------------------------------------------
out2="$T/results2/slurm-test"
"$ugl" slurm --config "$cfg" --out "$out2" --shards 2 --cpus 1 --time 00:10:00 ||
  cluster_fail "ugl slurm refused the second job"
submitted=$(bash "$out2/slurm/submit.sh") || cluster_fail "submit.sh failed"
jid=$(sed -n 's/^submitted array job \([0-9]*\) .*/\1/p' <<<"$submitted")
rid=$(sed -n 's/.*and its report step \([0-9]*\)$/\1/p' <<<"$submitted")
[ -n "$jid" ] && [ -n "$rid" ] || cluster_fail "submit.sh did not name its jobs: $submitted"
# Cancel task 1 once it has finished some of its runs but not all.
cancelled=""
for i in $(seq 1 1200); do
  state=$(squeue -h -j "${jid}_1" -o %T 2>/dev/null || true)
  shard=$("$ugl" status --config "$cfg" --out "$out2" --shards 2 | sed -n 's/^  shard 1\/2: //p')
  done_n=$(sed -n 's/^\([0-9]*\) runs: \([0-9]*\) complete.*/\2/p' <<<"$shard")
  total_n=$(sed -n 's/^\([0-9]*\) runs: .*/\1/p' <<<"$shard")
  if [ "$state" = RUNNING ] && [ "${done_n:-0}" -ge 1 ] && [ "${done_n:-0}" -lt "${total_n:-0}" ]; then
    scancel "${jid}_1"
    cancelled="after $done_n of $total_n runs"
    break
  fi
  [ -z "$state" ] && [ "${done_n:-0}" = "${total_n:-x}" ] && break
  sleep 0.1
done
[ -n "$cancelled" ] || cluster_fail "task 1 was never caught mid-run (shard 1: $shard)"
step "cancelled task ${jid}_1 $cancelled"
wait_queue_empty "the cancelled submission" 240
[ ! -e "$out2/report" ] || cluster_fail "the report step of the cancelled submission rendered partial results"
"$ugl" status --config "$cfg" --out "$out2" --require-complete >/dev/null 2>&1 &&
  cluster_fail "the campaign is complete although a task was cancelled mid-run"
step "the report step $rid did not run; resubmitting task 1"
bash "$out2/slurm/submit.sh" 1 >/dev/null || cluster_fail "resubmitting task 1 failed"
wait_queue_empty "the resubmission" 240
[ -f "$out2/report/REPORT.md" ] || {
  cat "$out2"/slurm/logs/*.log >&2 || true
  cluster_fail "the resubmission's report step wrote no report"
}
[ "$(digests "$out2")" = "$(digests "$T/single/slurm-test")" ] ||
  cluster_fail "the resumed results differ from the single-process campaign's"
step "the resumed results are byte-identical to the single-process campaign's"
cluster_stop
step "passed"
