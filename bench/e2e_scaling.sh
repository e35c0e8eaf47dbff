#!/usr/bin/env bash
# End-to-end training throughput against the number of actors, on a machine with many cores: runs
# bench/e2e_train.sh --pin (actor a on core a, the learner on the cores left) once per actor count
# and prints one table row per run, with the broadcast latency seen by masa_lcm_probe.
#   bench/e2e_scaling.sh [task] [--actors-list "1 2 4 8 14"] [--updates N] [--warmup W] [--out DIR]
# Every actor count must leave at least one core to the learner. MASA_BUILD_DIR and MASA_LCM_URL
# are passed on to e2e_train.sh.
set -euo pipefail
cd "$(dirname "$0")/.."

task=humanoid_tightrope
[ $# -gt 0 ] && [[ $1 != --* ]] && { task=$1; shift; }
list="1 2 4 8 14" updates=40 warmup=5 out=""
while [ $# -gt 0 ]; do
  case "$1" in
    --actors-list) list=$2; shift 2 ;;
    --updates) updates=$2; shift 2 ;;
    --warmup) warmup=$2; shift 2 ;;
    --out) out=$2; shift 2 ;;
    *) echo "e2e_scaling.sh: unknown option '$1'" >&2; exit 2 ;;
  esac
done
out=${out:-$(mktemp -d /tmp/masa_scaling.XXXXXX)}
mkdir -p "$out"

for k in $list; do
  bench/e2e_train.sh "$task" --actors "$k" --updates "$updates" --warmup "$warmup" --probe --pin \
    --out "$out/actors_$k" || echo "e2e: task $task actors $k FAILED (see $out/actors_$k/train.log)"
done | tee "$out/summary.txt"
echo "e2e_scaling.sh: files in $out" >&2
