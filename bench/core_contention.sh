#!/usr/bin/env bash
# Does one core stay as fast when the others are busy? K copies of bench_efficiency_bound, each
# pinned to its own core (0..K-1), measure t_env and t_learn at once; the medians against K = 1 say
# what a machine's shared parts (memory bandwidth, L3, turbo budget, a host's hyperthreads under a
# VM's "cores") take from a core when every core works, a term the cost model (which measures one
# core alone) does not have.
#   bench/core_contention.sh [--counts "1 8 16"] [--rounds R]   (MASA_BUILD_DIR: the build, default build)
set -euo pipefail
cd "$(dirname "$0")/.."
counts="1 $(nproc)" rounds=3
while [ $# -gt 0 ]; do
  case "$1" in
    --counts) counts=$2; shift 2 ;;
    --rounds) rounds=$2; shift 2 ;;
    *) echo "core_contention.sh: unknown option '$1'" >&2; exit 2 ;;
  esac
done
bench=${MASA_BUILD_DIR:-build}/bench/bench_efficiency_bound
[ -x "$bench" ] || { echo "core_contention.sh: no $bench (bash bench/build_benchmarks.sh)" >&2; exit 2; }
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
median() { sort -g | awk '{ v[NR] = $1 } END { print NR % 2 ? v[(NR + 1) / 2] : (v[NR / 2] + v[NR / 2 + 1]) / 2 }'; }
echo "# $(date -u +%FT%TZ) $(nproc) cores, $(grep -m1 'model name' /proc/cpuinfo | cut -d: -f2 | sed 's/^ //'); a1_beam, 128 envs x 24"
printf '%-6s %12s %12s %10s %10s %14s\n' busy t_env_us t_learn_us env_x learn_x slowest_env_us
base_env="" base_learn=""
for k in $counts; do
  (( k <= $(nproc) )) || continue
  for ((c = 0; c < k; c++)); do
    taskset -c "$c" env OMP_NUM_THREADS=1 "$bench" --set task=a1_beam --set method=masa --set ppo.num_envs=128 \
      --set ppo.horizon=24 --set ppo.minibatch_size=768 --rounds "$rounds" --cores 1 > "$tmp/$k.$c" 2>&1 &
  done
  wait
  env_us=$(cat "$tmp/$k".* | sed -n 's/^t_env *\([0-9.]*\) .*/\1/p' | median)
  learn_us=$(cat "$tmp/$k".* | sed -n 's/^t_learn *\([0-9.]*\) .*/\1/p' | median)
  # The slowest core's: a lockstep pipeline (every update waits for every actor) goes at its pace.
  slowest=$(cat "$tmp/$k".* | sed -n 's/^t_env *\([0-9.]*\) .*/\1/p' | sort -g | tail -n 1)
  base_env=${base_env:-$env_us} base_learn=${base_learn:-$learn_us}
  awk -v k="$k" -v e="$env_us" -v l="$learn_us" -v e0="$base_env" -v l0="$base_learn" -v m="$slowest" \
    'BEGIN { printf "%-6s %12.2f %12.2f %10.2f %10.2f %14.2f\n", k, e, l, e / e0, l / l0, m }'
done
