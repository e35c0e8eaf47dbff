#!/usr/bin/env bash
# The learner's update against data-parallel ranks on C cores: ranks x threads = C for ranks
# 1, 2, 4, ... (bench_learner_ranks under mpirun, a recipe's model and batch, synthetic samples).
# One row per split: the update's wall time, and the gradient allreduce per minibatch.
#   bench/learner_ranks.sh [recipe] [--cores C] [--updates N] [--out FILE]
set -euo pipefail
cd "$(dirname "$0")/.."
recipe=a1_beam
[ $# -gt 0 ] && [[ $1 != --* ]] && { recipe=$1; shift; }
cores=$(nproc) updates=5 out=""
while [ $# -gt 0 ]; do
  case "$1" in
    --cores) cores=$2; shift 2 ;;
    --updates) updates=$2; shift 2 ;;
    --out) out=$2; shift 2 ;;
    *) echo "learner_ranks.sh: unknown option '$1'" >&2; exit 2 ;;
  esac
done
bin=${MASA_BUILD_DIR:-build}/bench/bench_learner_ranks
bash "$(dirname "$0")/build_benchmarks.sh" "${MASA_BUILD_DIR:-build}"
{
  echo "# $(date -u +%FT%TZ) $(git rev-parse --short HEAD) on $(bash experiments/machine.sh 2> /dev/null || hostname)"
  echo "# bench/learner_ranks.sh $recipe --cores $cores --updates $updates"
  for ((r = 1; r <= cores; r *= 2)); do
    t=$((cores / r))
    OMP_NUM_THREADS=$t tests/mpi/mpirun.sh -np "$r" -x OMP_NUM_THREADS "$bin" --recipe "$recipe" --updates "$updates"
  done
} | tee ${out:+"$out"}
