#!/usr/bin/env bash
# The cost model of docs/scaling.md (bench/scaling_model.py) checked on this machine, in one run:
#  1. the per-sample costs: t_env and t_learn on one core each, the rollout bytes per env step and
#     the parameter message (bench_efficiency_bound), the gradient allreduce per minibatch at 2
#     ranks (bench_learner_ranks), written to OUT/costs.json;
#  2. training fps (bench/e2e_ranks.sh, a1_beam, E environments an actor, horizon 24, 4 minibatches)
#     at points on C cores: actors and learner ranks on cores of their own (A + L = C) with
#     ppo.max_policy_lag 0 (they take turns) and 1 (they overlap), and C actors sharing the cores
#     with the ranks;
#  3. the model's prediction beside each measured point (OUT/check.txt).
#   bench/scaling_check.sh [--cores C] [--envs E] [--updates N] [--costs-only] [--out DIR]   (MASA_BUILD_DIR: the build)
# --costs-only: step 1 alone (scaling_device.sh's tables put the model beside their own points).
set -euo pipefail
cd "$(dirname "$0")/.."
cores=$(nproc) envs=64 updates=16 warmup=5 costs_only=0 out=/tmp/masa_scaling_check
while [ $# -gt 0 ]; do
  case "$1" in
    --cores) cores=$2; shift 2 ;;
    --envs) envs=$2; shift 2 ;;
    --updates) updates=$2; shift 2 ;;
    --costs-only) costs_only=1; shift ;;
    --out) out=$2; shift 2 ;;
    *) echo "scaling_check.sh: unknown option '$1'" >&2; exit 2 ;;
  esac
done
build=${MASA_BUILD_DIR:-build}
bash "$(dirname "$0")/build_benchmarks.sh" "$build"
mkdir -p "$out"
machine=$(bash experiments/machine.sh 2> /dev/null || hostname)
echo "# $(date -u +%FT%TZ) $(git rev-parse --short HEAD 2> /dev/null || echo '?') on $machine, $cores cores, load $(cut -d' ' -f1-3 /proc/loadavg)" | tee "$out/check.txt"

# 1. Costs, with e2e_ranks.sh's configuration (one actor's environments; per-sample costs barely
#    depend on the batch).
samples=$((envs * 24))
bound=$("$build/bench/bench_efficiency_bound" --set task=a1_beam --set method=masa --set "ppo.num_envs=$envs" \
  --set ppo.horizon=24 --set "ppo.minibatch_size=$((samples / 4))" --rounds 3 --cores "$cores")
echo "$bound" | sed 's/^/# /' | tee -a "$out/check.txt"
ranks=$(OMP_NUM_THREADS=1 tests/mpi/mpirun.sh -np 2 -x OMP_NUM_THREADS "$build/bench/bench_learner_ranks" --recipe a1_beam --updates 2)
echo "$ranks" | sed 's/^/# /' | tee -a "$out/check.txt"
t_env=$(sed -n 's/^t_env *\([0-9.]*\) .*/\1/p' <<< "$bound")
t_learn=$(sed -n 's/^t_learn *\([0-9.]*\) .*/\1/p' <<< "$bound")
wire=$(sed -n 's/^wire \([0-9.]*\) bytes per env step.*/\1/p' <<< "$bound")
params=$(sed -n 's/.*parameters \([0-9]*\) bytes a message/\1/p' <<< "$bound")
allreduce=$(sed -n 's/.*gradient allreduce \([0-9]*\) floats ([0-9]* KB) in \([0-9]*\) us.*/\2/p' <<< "$ranks")
grad_floats=$(sed -n 's/.*gradient allreduce \([0-9]*\) floats.*/\1/p' <<< "$ranks")
cat > "$out/costs.json" << EOF
{"t_env_us": $t_env, "t_learn_us": $t_learn, "thread_speedup": {}, "allreduce_us": {"2": $allreduce},
 "minibatches_x_epochs": 20, "param_bytes": $params, "bytes_per_sample": $wire, "grad_bytes": $((grad_floats * 4)),
 "nic_gbps": 10, "nic_latency_us": 30}
EOF
(( costs_only )) && { echo "scaling_check.sh: $out/costs.json (--costs-only: no points)" >&2; exit 0; }

# 2. Measured points: "fps MEASURED A E H L T CORES LAG" (scaling_model.py check's lines).
: > "$out/points.txt"
point() {  # point ACTORS RANKS LAG
  local a=$1 l=$2 lag=$3 line fps
  line=$(bench/e2e_ranks.sh a1_beam --ranks "$l" --actors "$a" --envs "$envs" --updates "$updates" --warmup "$warmup" \
    --lag "$lag" --out "$out/e2e_a${a}_l${l}_lag${lag}") || { echo "# $line" | tee -a "$out/check.txt"; return 0; }
  echo "# $line" | tee -a "$out/check.txt"
  fps=$(sed -n 's/.*: fps \([0-9.]*\) (wall clock.*/\1/p' <<< "$line")
  echo "fps $fps $a $envs 24 $l 1 $cores $lag" >> "$out/points.txt"
}
for l in 1 2; do  # cores of their own
  a=$((cores - l))
  (( a >= 1 && a % l == 0 )) || continue
  point "$a" "$l" 0
  point "$a" "$l" 1
done
for l in 1 2; do  # C actors, sharing the cores with the ranks
  (( cores % l == 0 )) && point "$cores" "$l" 0
done

# 3. The model beside every point.
python3 bench/scaling_model.py "$out/costs.json" check "$out/points.txt" | tee -a "$out/check.txt"
echo "scaling_check.sh: $out/check.txt" >&2
