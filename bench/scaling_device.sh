#!/usr/bin/env bash
# The many-core scaling tables of issue #30 in one short script, for a machine with C cores
# (written for the 16-core device machine; about 8 minutes there). Results under OUT:
#  1. learner_ranks.txt: the learner's update with ranks x threads = C (a1_beam, humanoid_tightrope)
#  2. actors.txt: training fps against actor cores a = 1, 2, 4, 8, 12, 14 with L learner ranks by the
#     rule "the divisor of a nearest 0.37 a (the measured learner/actor cost ratio, 43 us / 115 us
#     per env step), with a + L <= C", each process on one core
#  3. ranks.txt: training fps against L = 1, 2, 4 at a fixed 8 actors
#   bench/scaling_device.sh [--cores C] [--out OUT]      (MASA_BUILD_DIR: the build, default build)
set -euo pipefail
cd "$(dirname "$0")/.."
cores=$(nproc) out=${OUT:-/tmp/masa_scaling_device}
while [ $# -gt 0 ]; do
  case "$1" in
    --cores) cores=$2; shift 2 ;;
    --out) out=$2; shift 2 ;;
    *) echo "scaling_device.sh: unknown option '$1'" >&2; exit 2 ;;
  esac
done
mkdir -p "$out"
machine=$(bash experiments/machine.sh 2> /dev/null || hostname)
stamp() { echo "# $(date -u +%FT%TZ) $(git rev-parse --short HEAD 2> /dev/null || echo '?') on $machine: $*"; }

rule() {  # rule A: learner ranks for A actors
  local a=$1 best=1 d
  for ((d = 1; d <= a; d++)); do
    (( a % d == 0 && a + d <= cores )) || continue
    awk -v d="$d" -v b="$best" -v a="$a" 'BEGIN { t = 0.37 * a; exit !((d - t)^2 < (b - t)^2) }' && best=$d
  done
  echo "$best"
}

{
  stamp "bench/learner_ranks.sh --cores $cores"
  bench/learner_ranks.sh a1_beam --cores "$cores" --updates 3 | grep -v '^#'
  bench/learner_ranks.sh humanoid_tightrope --cores "$cores" --updates 2 | grep -v '^#'
} | tee "$out/learner_ranks.txt"

{
  stamp "training fps against actor cores (a1_beam, 32 envs an actor, horizon 24)"
  for a in 1 2 4 8 12 14; do
    (( a + 1 <= cores )) || continue
    bench/e2e_ranks.sh a1_beam --ranks "$(rule "$a")" --actors "$a" --updates 16 --warmup 4 --out "$out/actors_$a" || true
  done
} | tee "$out/actors.txt"

{
  stamp "training fps against learner ranks at 8 actors"
  for l in 1 2 4; do
    (( 8 + l <= cores )) || continue
    bench/e2e_ranks.sh a1_beam --ranks "$l" --actors 8 --updates 16 --warmup 4 --out "$out/ranks_$l" || true
  done
} | tee "$out/ranks.txt"
echo "scaling_device.sh: tables in $out" >&2
