#!/usr/bin/env bash
# End-to-end training throughput of one MPI job (deploy/cluster/mpirun_train.sh): L learner ranks
# and A actors of E environments (ppo.num_envs = A x E, horizon 24, 4 minibatches) for N updates;
# prints one line with the median fps after the warm-up (the learner's metrics.csv).
#   bench/e2e_ranks.sh [task] --ranks L --actors A [--envs E] [--threads T] [--updates N] [--warmup W] [--out DIR]
#                      [--lag G] [--set key=value ...]
# --lag G: ppo.max_policy_lag (1: actors collect the next rollout while the learner learns).
# MASA_LCM_URL: the URL (default: loopback multicast on a random port).
set -euo pipefail
cd "$(dirname "$0")/.."
task=a1_beam
[ $# -gt 0 ] && [[ $1 != --* ]] && { task=$1; shift; }
ranks=1 actors=1 envs=32 threads=1 updates=20 warmup=5 out="" lag=0 sets=()
while [ $# -gt 0 ]; do
  case "$1" in
    --ranks) ranks=$2; shift 2 ;;
    --actors) actors=$2; shift 2 ;;
    --envs) envs=$2; shift 2 ;;
    --threads) threads=$2; shift 2 ;;
    --updates) updates=$2; shift 2 ;;
    --warmup) warmup=$2; shift 2 ;;
    --out) out=$2; shift 2 ;;
    --lag) lag=$2; shift 2 ;;
    --set) sets+=(--set "$2"); shift 2 ;;
    *) echo "e2e_ranks.sh: unknown option '$1'" >&2; exit 2 ;;
  esac
done
out=${out:-$(mktemp -d /tmp/masa_e2e_ranks.XXXXXX)}
mkdir -p "$out"
samples=$((actors * envs * 24))
MASA_LCM_URL="${MASA_LCM_URL:-udpm://239.255.76.67:$((7600 + RANDOM % 50 * 8))?ttl=0&recv_buf_size=8388608}" \
  deploy/cluster/mpirun_train.sh "$task" masa --ranks "$ranks" --actors "$actors" --envs "$envs" --threads "$threads" \
  --updates "$updates" --run-dir "$out/run" --set ppo.horizon=24 --set ppo.minibatch_size=$((samples / 4)) \
  --set runner.eval_every=0 --set runner.plot_every=0 --set "ppo.max_policy_lag=$lag" "${sets[@]+"${sets[@]}"}" \
  > "$out/train.log" 2>&1 ||
  { echo "e2e_ranks: $task ranks $ranks actors $actors FAILED (see $out/train.log)"; exit 1; }
median() { sort -g | awk '{ v[NR] = $1 } END { print NR ? (NR % 2 ? v[(NR + 1) / 2] : (v[NR / 2] + v[NR / 2 + 1]) / 2) : "nan" }'; }
fps=$(awk -F, -v w="$warmup" 'NR == 1 { for (i = 1; i <= NF; i++) if ($i == "fps") c = i; next } $1 > w { print $c }' \
  "$out/run/metrics.csv" | median)
# The wall-clock rate over the measured updates: the honest number when update times alternate
# (with ppo.max_policy_lag 1 a short update follows a long one); the median of per-update fps is
# kept beside it.
mean=$(awk -F, -v w="$warmup" 'NR == 1 { for (i = 1; i <= NF; i++) { if ($i == "env_steps") s = i; if ($i == "wall_time_s") t = i }; next }
  $1 == w { s0 = $s; t0 = $t } { s1 = $s; t1 = $t } END { print (t1 > t0) ? (s1 - s0) / (t1 - t0) : "nan" }' "$out/run/metrics.csv")
dropped=$(tail -n 1 "$out/run/metrics.csv" | awk -F, -v h="$(head -n 1 "$out/run/metrics.csv")" \
  'BEGIN { n = split(h, c, ","); for (i = 1; i <= n; i++) if (c[i] == "dropped_chunks") k = i } { print k ? $k : "?" }')
# Rank 0's progress lines: how long each measured update learned and waited for its batch (a
# learner that mostly waits is short of actors; two modes of a lag-1 pipeline show as two sizes).
measured=$(sed -n 's|^update \([0-9]*\)/.* learn \([0-9.]*\)s waited \([0-9.]*\)s.*|\1 \2 \3|p' "$out/train.log" |
  awk -v w="$warmup" '$1 > w { print $2, $3 }')
timing=""
[ -n "$measured" ] && timing=$(printf '; learner: learn %.3fs, waited %.3fs an update (medians)' \
  "$(cut -d' ' -f1 <<< "$measured" | median)" "$(cut -d' ' -f2 <<< "$measured" | median)")
printf 'e2e_ranks: %s ranks %d actors %d x %d envs, threads %d, lag %d: fps %.0f (wall clock, updates %d-%d; median of updates %.0f), chunks dropped %s%s\n' \
  "$task" "$ranks" "$actors" "$envs" "$threads" "$lag" "$mean" "$warmup" "$updates" "$fps" "$dropped" "$timing"
