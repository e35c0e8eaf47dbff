#!/usr/bin/env bash
# Runner latency at a 500 Hz state rate: masa_deploy answers a stream of A1 states
# (bench/deploy_state_source.cpp) over loopback LCM, in several scheduling variants run back to back
# in one invocation, SECONDS each; optionally a training run (masa_train, pinned to the runner's
# core) loads that core. For each variant it prints masa_deploy's own figure (state received ->
# command published, p50 / p99, and its parts) and the source's round trip (state published ->
# command received). MASA_BENCH_AUTH (default "insecure") lists the robot links to measure, each
# variant run once per link: insecure (unsigned state, the runner --insecure: the figures recorded
# before the robot channels were signed by default are of that path) and signed (the default
# deployment: a roster made by masa_roster in a temporary directory, the source signs its states
# as the robot and checks the runner's signature on each command, the runner verifies each state
# and signs each command).
#   bench/deploy_latency.sh [SECONDS] [--load]
# Variants (MASA_BENCH_VARIANTS, default all): before (chrt -f 50 + taskset, the first recorded
# setting), warm (before + realtime.warm_up_us), busy (before + realtime.busy_poll_us), after (the
# realtime section: pinned, SCHED_FIFO 50, memory locked, warm-up and busy poll). Real-time
# priority needs root or CAP_SYS_NICE (else masa_deploy says so and runs without).
# MASA_BENCH_CORE picks the runner's core (default 1); the source (the robot) runs pinned to
# MASA_BENCH_SOURCE_CORE (default 0): unpinned, the scheduler may queue it behind a spinning
# real-time runner for tens of milliseconds, and the runner's watchdog then trips.
# MASA_BENCH_SOURCE_RT=1 runs the source at SCHED_FIFO 50 too, as a robot's SDK bridge would run:
# its round trip then shows the runner's wakeups rather than the source's own queueing.
set -euo pipefail
seconds=${1:-20}
load=${2:-}
src=$(cd "$(dirname "$0")/.." && pwd)
build=${MASA_BUILD_DIR:-$src/build}
bash "$src/bench/build_benchmarks.sh" "$build"
core=${MASA_BENCH_CORE:-1}
source_core=${MASA_BENCH_SOURCE_CORE:-0}
variants=${MASA_BENCH_VARIANTS:-before warm busy after}
export LCM_DEFAULT_URL="udpm://239.255.76.67:7689?ttl=0"
log=$(mktemp)
pids=()
if [ "$load" = "--load" ]; then
  OMP_NUM_THREADS=1 taskset -c "$core" "$build/tools/masa_train" --set task=a1_beam --updates 100000 --quiet \
    --run-dir "$(mktemp -d)/run" > /dev/null 2>&1 & pids+=($!)
  sleep 2
fi
auths=${MASA_BENCH_AUTH:-insecure}
keys=$(mktemp -d)
trap 'for p in "${pids[@]}"; do kill "$p" 2>/dev/null || true; done; rm -f "$log"; rm -rf "$keys"' EXIT
case " $auths " in
  *" signed "*) "$build/tools/masa_roster" make "$keys/run" --actors 0 --runner --robot > /dev/null ;;
esac
warm=(--set realtime.warm_up_us=1000)
busy=(--set realtime.busy_poll_us=300)
for auth in $auths; do
case $auth in
  insecure) deploy_auth=(--insecure); source_auth=() ;;
  signed) deploy_auth=(--roster "$keys/run/roster" --signing-key "$keys/run/keys/runner0.key")
          source_auth=(--roster "$keys/run/roster" --signing-key "$keys/run/keys/robot0.key") ;;
  *) echo "unknown link $auth (insecure, signed)"; exit 2 ;;
esac
for v in $variants; do
  case $v in
    before) run=(chrt -f 50 taskset -c "$core"); sets=() ;;
    warm) run=(chrt -f 50 taskset -c "$core"); sets=("${warm[@]}") ;;
    busy) run=(chrt -f 50 taskset -c "$core"); sets=("${busy[@]}") ;;
    after) run=(); sets=(--set realtime.cpu="$core" --set realtime.priority=50 --set realtime.lock_memory=true "${warm[@]}" "${busy[@]}") ;;
    *) echo "unknown variant $v"; exit 2 ;;
  esac
  "${run[@]}" "$build/deploy/masa_deploy" "$src/tasks/a1_beam/policy/policy.bin" \
    --config "$src/configs/deploy/a1_beam_sim.yaml" "${deploy_auth[@]}" --set emergency.max_roll=3 --set emergency.max_pitch=3 \
    "${sets[@]}" --duration $((seconds + 2)) --quiet 2> "$log" & pids+=($!)
  sleep 0.5
  source_rt=()
  [ "${MASA_BENCH_SOURCE_RT:-0}" = 1 ] && source_rt=(chrt -f 50)
  rtt=$("${source_rt[@]}" taskset -c "$source_core" "$build/bench/deploy_state_source" --rate-hz 500 --seconds "$seconds" "${source_auth[@]}" |
    sed 's/.*round trip/round trip/; s/^deploy_state_source: //')
  wait "${pids[-1]}" || true
  echo "$auth $v: $(grep -o "latency.*" "$log")"
  grep -o "stopped in mode [a-z ]*" "$log" | sed "s/^/$auth $v: /"
  echo "$rtt" | sed "s/^/$auth $v: /"
  grep -o "id [0-9]*; .*" "$log" | sed "s/^id [0-9]*; /$auth $v: scheduling: /"
done
done
