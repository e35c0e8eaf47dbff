#!/usr/bin/env bash
# The many-core scaling tables of issue #30 in one short script, for a machine with C cores
# (written for a 16-core machine; about 10 minutes there). Results under OUT, in this order:
#  1. check/costs.json: the per-sample costs measured here (bench/scaling_check.sh --costs-only), and
#     contention.txt: the cores' speed with the others busy (bench/core_contention.sh)
#  2. actors.txt: training fps on the first a cores, a = 1, 2, 4, 8, 12, 14 (a < C), with actors and
#     learner ranks split by the documented rule: the split of those a cores that the cost model
#     finds fastest on the costs of step 1 (bench/scaling_model.py plan, ppo.max_policy_lag 1: the
#     actors collect while the learner learns); each against the bound a / (t_env + t_learn)
#  3. ranks.txt: training fps against learner ranks L = 1, 2, 4, 8 at 8 actors sharing 8 cores
#  4. model.txt: the model beside every point of 2 and 3
#  5. learner_ranks.txt: the learner's update with ranks x threads = C (a1_beam, humanoid_tightrope)
#   bench/scaling_device.sh [--cores C] [--envs E] [--updates N] [--warmup W] [--costs FILE] [--out OUT]
#                           [--points "CORES:ACTORS:RANKS:ENVS:LAG ..."]
#                           (MASA_BUILD_DIR: the build, default build)
# --costs FILE: the costs.json of an earlier step 1 on the same machine: step 1 is skipped (its six
# end-to-end points take minutes when one learner core serves 15 actors).
# --points: only these splits (probe.txt, the model beside them in model.txt), to test a guess about
# the tables (cores of their own against shared ones, larger batches against fixed costs).
set -euo pipefail
cd "$(dirname "$0")/.."
cores=$(nproc) envs=128 updates=16 warmup=5 costs="" points="" out=${OUT:-/tmp/masa_scaling_device}
while [ $# -gt 0 ]; do
  case "$1" in
    --cores) cores=$2; shift 2 ;;
    --envs) envs=$2; shift 2 ;;
    --updates) updates=$2; shift 2 ;;
    --warmup) warmup=$2; shift 2 ;;
    --costs) costs=$2; shift 2 ;;
    --points) points=$2; shift 2 ;;
    --out) out=$2; shift 2 ;;
    *) echo "scaling_device.sh: unknown option '$1'" >&2; exit 2 ;;
  esac
done
mkdir -p "$out"
machine=$(bash experiments/machine.sh 2> /dev/null || hostname)
stamp() { echo "# $(date -u +%FT%TZ) $(git rev-parse --short HEAD 2> /dev/null || echo '?') on $machine: $*"; }

if [ -z "$costs" ]; then
  bench/scaling_check.sh --cores "$cores" --envs "$envs" --costs-only --out "$out/check"
  costs=$out/check/costs.json
fi
[ -f "$costs" ] || { echo "scaling_device.sh: no costs file '$costs'" >&2; exit 2; }
# Each core's speed with the others busy, and the slowest core's (a lockstep pipeline follows it;
# bench/results/2026-12-04_two_modes_local/): half a minute, printed into the session's log.
bench/core_contention.sh --counts "$(printf '%s\n' 1 $((cores / 2)) "$cores" | sort -un | tr '\n' ' ')" --rounds 2 | tee "$out/contention.txt" || true

: > "$out/points.txt"
run_on() {  # run_on CORES ACTORS RANKS LAG NAME [ENVS]: e2e_ranks.sh on the first CORES cores
  local c=$1 a=$2 l=$3 lag=$4 e=${6:-$envs} line fps
  line=$(taskset -c "0-$((c - 1))" bench/e2e_ranks.sh a1_beam --ranks "$l" --actors "$a" --envs "$e" \
    --updates "$updates" --warmup "$warmup" --lag "$lag" --out "$out/$5") || true
  fps=$(sed -n 's/.*: fps \([0-9.]*\) (wall clock.*/\1/p' <<< "$line")
  echo "$line (on $c cores)"
  [ -n "$fps" ] && echo "fps $fps $a $e 24 $l 1 $c $lag" >> "$out/points.txt"
  return 0
}
if [ -n "$points" ]; then
  {
    stamp "the splits asked for (--points)"
    i=0
    for p in $points; do
      i=$((i + 1))
      IFS=: read -r c a l e lag <<< "$p"
      [[ "$c:$a:$l:$e:$lag" =~ ^[0-9]+:[0-9]+:[0-9]+:[0-9]+:[0-9]+$ ]] || { echo "scaling_device.sh: bad point '$p' (CORES:ACTORS:RANKS:ENVS:LAG)"; continue; }
      run_on "$c" "$a" "$l" "$lag" "probe${i}_${c}_${a}_${l}_${e}_${lag}" "$e"  # a repeated point: a run of its own
    done
  } | tee "$out/probe.txt"
  python3 bench/scaling_model.py "$costs" check "$out/points.txt" | tee "$out/model.txt"
  exit 0
fi
{
  stamp "training fps on the first a cores, split by the model's plan (lag 1)"
  for a in 1 2 4 8 12 14; do
    (( a < cores || a == 1 )) || continue
    read -r na nl <<< "$(python3 bench/scaling_model.py "$costs" plan "$envs" 24 --cores "$a" --lag 1 --terse)"
    run_on "$a" "$na" "$nl" 1 "cores_$a"
  done
} | tee "$out/actors.txt"

{
  stamp "training fps against learner ranks, 8 actors sharing 8 cores with the ranks (lag 0)"
  for l in 1 2 4 8; do
    (( 8 <= cores )) || continue
    run_on 8 8 "$l" 0 "ranks_$l"
  done
} | tee "$out/ranks.txt"

python3 bench/scaling_model.py "$costs" check "$out/points.txt" | tee "$out/model.txt"
# Last: the learner alone, the table that matters least if the machine's time runs out.
{
  stamp "bench/learner_ranks.sh --cores $cores"
  bench/learner_ranks.sh a1_beam --cores "$cores" --updates 3 | grep -v '^#' || echo "learner_ranks.sh a1_beam failed"
  bench/learner_ranks.sh humanoid_tightrope --cores "$cores" --updates 2 | grep -v '^#' || echo "learner_ranks.sh humanoid_tightrope failed"
} | tee "$out/learner_ranks.txt"
echo "scaling_device.sh: tables in $out" >&2
