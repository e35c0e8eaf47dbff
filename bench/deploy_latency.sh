#!/usr/bin/env bash
# Runner latency at a 500 Hz state rate: masa_deploy (pinned to one core) answers a stream of A1
# states (bench/deploy_state_source.cpp) over loopback LCM; optionally a training run (masa_train,
# pinned to the same core) loads that core. Prints masa_deploy's own figure (state received ->
# command published, p50 / p99) and the source's round trip (state published -> command received).
#   bench/deploy_latency.sh [SECONDS] [--load]
# MASA_BENCH_RT=1 runs masa_deploy with a real-time priority (chrt -f 50; root or CAP_SYS_NICE), as
# a robot's runner would run; MASA_BENCH_CORE picks the core (default 1).
set -euo pipefail
seconds=${1:-20}
load=${2:-}
src=$(cd "$(dirname "$0")/.." && pwd)
build=${MASA_BUILD_DIR:-$src/build}
core=${MASA_BENCH_CORE:-1}
export LCM_DEFAULT_URL="udpm://239.255.76.67:7689?ttl=0"
pids=()
trap 'for p in "${pids[@]}"; do kill "$p" 2>/dev/null || true; done' EXIT
if [ "$load" = "--load" ]; then
  OMP_NUM_THREADS=1 taskset -c "$core" "$build/tools/masa_train" --set task=a1_beam --updates 100000 --quiet \
    --run-dir "$(mktemp -d)/run" > /dev/null 2>&1 & pids+=($!)
  sleep 2
fi
rt=()
[ "${MASA_BENCH_RT:-0}" = 1 ] && rt=(chrt -f 50)
"${rt[@]}" taskset -c "$core" "$build/deploy/masa_deploy" "$src/tasks/a1_beam/policy/policy.bin" \
  --config "$src/configs/deploy/a1_beam_sim.yaml" --set emergency.max_roll=3 --set emergency.max_pitch=3 \
  --duration $((seconds + 2)) --quiet 2> deploy.log & pids+=($!)
sleep 0.5
"$build/bench/deploy_state_source" --rate-hz 500 --seconds "$seconds"
wait "${pids[-1]}" || true
grep "latency" deploy.log | sed 's/.*latency/masa_deploy: latency/'
rm -f deploy.log
