#!/usr/bin/env bash
# End-to-end training throughput on this machine: runs deploy/train.sh (learner + K actors over
# loopback LCM) for a fixed number of updates and reports the learner's steady-state fps, the
# median over the updates after the warm-up, from the run's metrics.csv. With --probe,
# masa_lcm_probe listens on MASA_POLICY meanwhile and the parameter broadcast latency (publication
# to reception, median / p99 / max over the broadcasts after the warm-up) is reported too.
#   bench/e2e_train.sh [task] [method] [--actors K] [--envs E] [--updates N] [--warmup W]
#                      [--probe] [--pin] [--learner-threads T] [--out DIR] [--set key=value ...]
# --pin: actor a on core a, the learner on the remaining cores with as many OpenMP threads (for
#        machines with more cores than actors; without it the kernel places everything).
# --learner-threads: OMP_NUM_THREADS of the learner (default: inherited; --pin: the cores left).
# MASA_BUILD_DIR (default build) chooses the binaries. MASA_LCM_URL defaults to a port of its own
# (7690), so that a benchmark never mixes with a training run on the default port.
# Output: one "e2e:" summary line on stdout; metrics.csv, logs and the probe's files under --out.
set -euo pipefail
cd "$(dirname "$0")/.."

task=humanoid_tightrope method=masa
[ $# -gt 0 ] && [[ $1 != --* ]] && { task=$1; shift; }
[ $# -gt 0 ] && [[ $1 != --* ]] && { method=$1; shift; }
actors=2 envs=32 updates=30 warmup=5 probe=0 pin=0 out="" learner_threads=""
sets=()
while [ $# -gt 0 ]; do
  case "$1" in
    --actors) actors=$2; shift 2 ;;
    --envs) envs=$2; shift 2 ;;
    --updates) updates=$2; shift 2 ;;
    --warmup) warmup=$2; shift 2 ;;
    --probe) probe=1; shift ;;
    --pin) pin=1; shift ;;
    --learner-threads) learner_threads=$2; shift 2 ;;
    --out) out=$2; shift 2 ;;
    --set) sets+=(--set "$2"); shift 2 ;;
    *) echo "e2e_train.sh: unknown option '$1'" >&2; exit 2 ;;
  esac
done
[ "$updates" -gt "$warmup" ] || { echo "e2e_train.sh: --updates must exceed --warmup" >&2; exit 2; }

build=${MASA_BUILD_DIR:-build}
probe_bin="$build/tools/masa_lcm_probe"
[ "$probe" = 0 ] || [ -x "$probe_bin" ] || { echo "e2e_train.sh: $probe_bin is missing" >&2; exit 2; }
rmem=$(cat /proc/sys/net/core/rmem_max 2>/dev/null || echo 2097152)
buf=$(( rmem < 8388608 ? rmem : 8388608 ))
export MASA_LCM_URL=${MASA_LCM_URL:-"udpm://239.255.76.67:7690?ttl=0&recv_buf_size=$buf"}
out=${out:-$(mktemp -d /tmp/masa_e2e.XXXXXX)}
mkdir -p "$out"
export MASA_RUNS_DIR="$out/runs"  # fresh, so the run directory is the only one in it
rm -rf "$MASA_RUNS_DIR"
ncores=$(nproc)

probe_pid=""
if [ "$probe" = 1 ]; then
  "$probe_bin" --url "$MASA_LCM_URL" --channel MASA_POLICY --quiet --csv "$out/policy_latency.csv" \
    > "$out/probe.txt" 2> "$out/probe.err" &
  probe_pid=$!
fi

learner_env=()
if [ "$pin" = 1 ]; then
  [ "$actors" -lt "$ncores" ] || { echo "e2e_train.sh: --pin needs fewer actors than cores ($ncores)" >&2; exit 2; }
  learner_env=(OMP_NUM_THREADS=$(( ncores - actors )))
fi
[ -z "$learner_threads" ] || learner_env=(OMP_NUM_THREADS="$learner_threads")

# All descendants of process $1 (train.sh may start the binaries through wrappers).
descendants() {
  local p
  for p in $(pgrep -P "$1" || true); do echo "$p"; descendants "$p"; done
}

# Pins the learner and actor binaries under train.sh (process $1) once they have all started.
pin_children() {
  local parent=$1 tries=0 pid exe cmd a pinned
  while [ $tries -lt 400 ]; do
    pinned=0
    : > "$out/affinity.txt"
    for pid in $(descendants "$parent"); do
      exe=$(basename "$(readlink "/proc/$pid/exe" 2>/dev/null)" 2>/dev/null || true)
      cmd=$( { tr '\0' ' ' < "/proc/$pid/cmdline"; } 2>/dev/null || true)
      case "$exe" in
        masa_learner) taskset -a -cp "$actors-$(( ncores - 1 ))" "$pid" > /dev/null 2>&1 && pinned=$((pinned + 1)) ;;
        masa_actor)
          a=$(sed -n 's/.*--actor-id \([0-9]*\).*/\1/p' <<< "$cmd")
          taskset -a -cp "$a" "$pid" > /dev/null 2>&1 && pinned=$((pinned + 1)) ;;
        *) continue ;;
      esac
      echo "$exe $(taskset -cp "$pid" 2>/dev/null)" >> "$out/affinity.txt"
    done
    [ "$pinned" -ge $(( actors + 1 )) ] && return 0
    sleep 0.05; tries=$(( tries + 1 ))
  done
  echo "e2e_train.sh: pinned only $pinned of $(( actors + 1 )) processes" >&2
}

load_before=$(cut -d' ' -f1-3 /proc/loadavg)
start_ns=$(date +%s%N)
env "${learner_env[@]}" deploy/train.sh "$task" "$method" --actors "$actors" --envs "$envs" --updates "$updates" \
  "${sets[@]}" > "$out/train.log" 2>&1 &
train_pid=$!
[ "$pin" = 1 ] && pin_children "$train_pid"
train_rc=0
wait "$train_pid" || train_rc=$?
elapsed=$(( ($(date +%s%N) - start_ns) / 1000000000 ))
if [ -n "$probe_pid" ]; then
  kill -INT "$probe_pid" 2>/dev/null || true
  wait "$probe_pid" 2>/dev/null || true
fi

run_dir=$(find "$MASA_RUNS_DIR" -mindepth 1 -maxdepth 1 -type d | head -1)
metrics="$run_dir/metrics.csv"
if [ "$train_rc" != 0 ] || [ ! -s "$metrics" ]; then
  echo "e2e_train.sh: the run failed (status $train_rc); see $out/train.log" >&2
  tail -5 "$out/train.log" >&2
  exit 1
fi
cp "$metrics" "$out/metrics.csv"

# Median of the numbers on stdin (one per line).
median() { sort -g | awk '{ v[NR] = $1 } END { if (NR == 0) print "nan"; else if (NR % 2) print v[(NR + 1) / 2]; else print (v[NR / 2] + v[NR / 2 + 1]) / 2 }'; }
# Nearest-rank percentile $1 of the numbers on stdin.
pctl() { sort -g | awk -v p="$1" '{ v[NR] = $1 } END { if (NR == 0) { print "nan"; exit } r = int(p / 100 * NR); if (r < p / 100 * NR) r++; if (r < 1) r = 1; print v[r] }'; }

col() { head -1 "$metrics" | tr ',' '\n' | grep -nx "$1" | cut -d: -f1; }
fps_col=$(col fps) update_col=$(col update) drop_col=$(col dropped_chunks)
steady() { awk -F, -v c="$1" -v u="$update_col" -v w="$warmup" 'NR > 1 && $u > w { print $c }' "$metrics"; }
fps_median=$(steady "$fps_col" | median)
fps_min=$(steady "$fps_col" | sort -g | head -1)
fps_max=$(steady "$fps_col" | sort -g | tail -1)
n_updates=$(( $(wc -l < "$metrics") - 1 ))
dropped=$(tail -1 "$metrics" | cut -d, -f"$drop_col")

summary="e2e: task $task method $method actors $actors envs/actor $envs updates $n_updates (warm-up $warmup)"
summary+=" fps median $(printf %.0f "$fps_median") min $(printf %.0f "$fps_min") max $(printf %.0f "$fps_max")"
summary+=" dropped $dropped wall ${elapsed}s load before $load_before after $(cut -d' ' -f1-3 /proc/loadavg)"
if [ -n "$probe_pid" ] && [ -s "$out/policy_latency.csv" ]; then
  # Broadcasts of the steady state: versions after the warm-up (version v follows update v).
  lat() { awk -F, -v w="$warmup" 'NR > 1 && $6 > w { print $4 / 1000 }' "$out/policy_latency.csv"; }
  n_lat=$(lat | wc -l)
  bytes=$(awk -F, 'NR == 2 { print $5 }' "$out/policy_latency.csv")
  summary+=" | broadcast latency ms median $(lat | median) p99 $(lat | pctl 99) max $(lat | sort -g | tail -1)"
  summary+=" over $n_lat messages of $bytes B"
fi
echo "$summary" | tee "$out/summary.txt"
echo "e2e_train.sh: files in $out" >&2
