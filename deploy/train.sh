#!/usr/bin/env bash
# Trains on this machine: one learner and K actor processes over loopback LCM (udpm, ttl=0).
# Ctrl-C stops everything cleanly; the learner checkpoints, so the run directory is resumable.
#   deploy/train.sh [task] [method] [--actors K] [--envs E] [--updates N] [--set key=value ...]
# MASA_BUILD_DIR (default build) and MASA_RUNS_DIR (default runs) choose the folders, MASA_LCM_URL
# the LCM URL (default: loopback multicast with the largest receive buffer the kernel allows).
# Defaults are sized for a 2-core machine (the paper's 4096 x 32 batches are GPU-scale):
# 2 actors x 32 environments, horizon 32, minibatch 1024. Override anything with --set.
set -euo pipefail
cd "$(dirname "$0")/.."

task=${1:-humanoid_tightrope}
method=${2:-masa}
shift $(( $# < 2 ? $# : 2 ))
actors=2 envs=32 updates=200
sets=()
while [ $# -gt 0 ]; do
  case "$1" in
    --actors) actors=$2; shift 2 ;;
    --envs) envs=$2; shift 2 ;;
    --updates) updates=$2; shift 2 ;;
    --set) sets+=(--set "$2"); shift 2 ;;
    *) echo "train.sh: unknown option '$1'" >&2; exit 2 ;;
  esac
done

build=${MASA_BUILD_DIR:-build}
for bin in "$build/learner/masa_learner" "$build/actors/masa_actor"; do
  [ -x "$bin" ] || { echo "train.sh: $bin is missing: run deploy/build.sh first" >&2; exit 2; }
done

# Ask for the receive buffer the kernel allows (LCM drops large messages with a small one).
rmem=$(cat /proc/sys/net/core/rmem_max 2>/dev/null || echo 2097152)
buf=$(( rmem < 8388608 ? rmem : 8388608 ))
url=${MASA_LCM_URL:-"udpm://239.255.76.67:7667?ttl=0&recv_buf_size=$buf"}
run_id=$(( ($(date +%s%N) / 1000) % 2000000000 + 1 ))
run_dir="${MASA_RUNS_DIR:-runs}/${task}_${method}_$(date +%Y%m%d_%H%M%S)"
mkdir -p "$run_dir"

common=(--set task="$task" --set method="$method" --set ppo.num_envs=$((actors * envs))
        --set ppo.horizon=32 --set ppo.minibatch_size=1024 "${sets[@]}")

echo "train.sh: $task / $method, $actors actors x $envs envs, $updates updates, run dir $run_dir"
"$build/learner/masa_learner" "${common[@]}" --url "$url" --run-id "$run_id" --run-dir "$run_dir" \
  --max-updates "$updates" &
learner=$!
pids=()
for ((a = 0; a < actors; ++a)); do
  OMP_NUM_THREADS=1 "$build/actors/masa_actor" "${common[@]}" --url "$url" --run-id "$run_id" --actor-id "$a" \
    --num-envs "$envs" > "$run_dir/actor$a.log" 2>&1 &
  pids+=($!)
done

stop() {
  kill -INT "$learner" 2>/dev/null || true
  wait "$learner" 2>/dev/null || true
  kill -TERM "${pids[@]}" 2>/dev/null || true
  wait "${pids[@]}" 2>/dev/null || true
}
trap 'echo "train.sh: stopping"; stop; exit 130' INT TERM
wait "$learner" || true
kill -TERM "${pids[@]}" 2>/dev/null || true
wait "${pids[@]}" 2>/dev/null || true
echo "train.sh: done. Metrics: $run_dir/metrics.csv. Resume: $build/learner/masa_learner --resume $run_dir (with the same --set options)"
