#!/usr/bin/env bash
# Learning smoke check: PPO must lift a task's mean episode return clearly above what the random
# initial policy gets (last layer scaled by 0.01: mean ~0, std 1, i.e. Gaussian noise).
#   learning_smoke.sh MASA_TRAIN TASK METHOD UPDATES MARGIN [--set k=v ...]
# Trains with masa_train (learner + one actor in one process: no loss, deterministic per seed), then
# compares the mean return of the first 5 updates (the random policy's episodes) with the mean of
# the last 10. Passes when the rise is at least MARGIN; prints both either way.
set -euo pipefail
train=$1 task=$2 method=$3 updates=$4 margin=$5
shift 5
dir=$(mktemp -d "${TMPDIR:-/tmp}/masa_smoke_${task}_${method}_XXXX")
trap 'rm -rf "$dir"' EXIT

start=$(date +%s)
"$train" --quiet --updates "$updates" --run-dir "$dir/run" --set task="$task" --set method="$method" "$@"
elapsed=$(( $(date +%s) - start ))

# metrics.csv: the return is the column named "return"; updates in which no episode ended say nan.
awk -F, -v n="$updates" -v margin="$margin" -v task="$task" -v method="$method" -v secs="$elapsed" '
  NR == 1 { for (i = 1; i <= NF; ++i) if ($i == "return") col = i; next }
  $col != "nan" && $col != "" {
    row = NR - 1
    if (row <= 5) { first += $col; nf++ }
    if (row > n - 10) { last += $col; nl++ }
  }
  END {
    if (!col || nf == 0 || nl == 0) { print "learning_smoke: no returns in metrics.csv"; exit 1 }
    first /= nf; last /= nl
    printf "learning_smoke: %s / %s, %d updates in %d s: random-policy return %.2f, final return %.2f, rise %.2f (need %.2f)\n",
           task, method, n, secs, first, last, last - first, margin
    if (last - first >= margin) print "LEARNED"; else { print "DID NOT LEARN"; exit 1 }
  }' "$dir/run/metrics.csv"
