#!/usr/bin/env bash
# The launchers size the PPO batch for the actors x environments asked for, say what they chose, and
# refuse a request they cannot size before anything starts, naming the option to change (issue #53).
# Nothing trains here: mpirun and srun are stand-ins that record their command line, and
# slurm_train.sbatch runs as Slurm would start it (SLURM_NTASKS set).
#  1. The README's cluster request, 14 actors x 32 humanoid_tightrope environments (the task file's
#     minibatch, 32768, is for 4096): mpirun_train.sh and slurm_train.sbatch start the job with 4
#     minibatches of 3584 and say so; --recipe gives the recipe's task, method and batch.
#  2. Refused, with nothing started and no run directory made: a minibatch the user set that does
#     not divide the batch (names ppo.minibatch_size), actors that do not divide among the ranks
#     (--actors), Slurm tasks that do not (--ntasks), a recipe's environments that do not divide
#     over the actors (--envs); the same from train.sh.
#  3. masa_learner given such a config says which key, as a config error, not an internal check.
#   tests/integration/launch_sizing.sh BUILD_DIR
set -uo pipefail
repo=$(cd "$(dirname "$0")/../.." && pwd)
build=$(cd "${1:?usage: launch_sizing.sh BUILD_DIR}" && pwd)
work=$(mktemp -d "${TMPDIR:-/tmp}/masa_launch_sizing.XXXXXX")
trap 'rm -rf "$work"' EXIT
failures=0
fail() {
  echo "FAIL: $*"
  failures=$((failures + 1))
}
cd "$repo"

# Stand-ins for mpirun and srun: they write their arguments (srun: its --multi-prog file) and end.
mkdir -p "$work/bin"
printf '#!/bin/sh\necho "$@" > "%s/started"\n' "$work" > "$work/bin/mpirun"
printf '#!/bin/sh\nfor a; do f=$a; done\ncat "$f" > "%s/started"\n' "$work" > "$work/bin/srun"
chmod +x "$work/bin/mpirun" "$work/bin/srun"
# A port of its own: a launcher that wrongly starts must not reach a run on the default one.
export MASA_BUILD_DIR=$build MASA_RUNS_DIR=$work/runs MASA_MPIRUN=$work/bin/mpirun PATH="$work/bin:$PATH" \
       MASA_LCM_URL="udpm://239.255.76.67:$((7000 + RANDOM % 150 * 4))?ttl=0"

# launch NAME COMMAND...: runs a launcher, its output in $work/NAME.out; sets status and started.
launch() {
  local name=$1
  shift
  rm -f "$work/started"
  status=0
  "$@" > "$work/$name.out" 2>&1 < /dev/null || status=$?
  started=$([ -f "$work/started" ] && cat "$work/started" || true)
}
slurm_job() {  # slurm_job NAME NTASKS ARGS...: slurm_train.sbatch as the job's batch script
  local name=$1 ntasks=$2
  shift 2
  MASA_REPO=$repo SLURM_NTASKS=$ntasks SLURM_JOB_ID=1 SLURM_SUBMIT_DIR=$work launch "$name" bash deploy/cluster/slurm_train.sbatch "$@"
}
expect_started_with() {  # NAME PATTERN...: the launcher started its job with every PATTERN
  local name=$1 pattern
  shift
  [ "$status" = 0 ] || { fail "$name: status $status: $(tail -n 3 "$work/$name.out")"; return; }
  for pattern in "$@"; do
    grep -q -e "$pattern" <<< "$started" || fail "$name: the job was not started with '$pattern': $started"
  done
}
expect_refused() {  # NAME OPTION: refused with status 2, naming OPTION; nothing started, no run made
  local name=$1 option=$2
  if [ "$status" != 2 ] || ! grep -q -e "$option" "$work/$name.out"; then
    fail "$name: expected a refusal naming $option, got status $status: $(tail -n 3 "$work/$name.out")"
  fi
  [ -z "$started" ] || fail "$name: the job was started although refused"
  [ -z "$(ls -A "$work/runs" 2> /dev/null)" ] || fail "$name: a run directory was made although refused"
  ! grep -q "check failed" "$work/$name.out" || fail "$name: an internal check reached the user"
  rm -rf "$work/runs"
}

echo "1. the README's request, sized"
launch mpirun_readme deploy/cluster/mpirun_train.sh humanoid_tightrope masa --ranks 2 --actors 14 --envs 32
expect_started_with mpirun_readme "ppo.num_envs=448" "ppo.minibatch_size=3584"
grep -q "4 minibatches of 3584" "$work/mpirun_readme.out" || fail "mpirun_train.sh did not say what it chose"
slurm_job slurm_readme 16 humanoid_tightrope masa --ranks 2 --envs 32 --updates 2000
expect_started_with slurm_readme "ppo.num_envs=448" "ppo.minibatch_size=3584" "^2-15 .*masa_actor"
grep -q "4 minibatches of 3584" "$work/slurm_readme.out" || fail "slurm_train.sbatch did not say what it chose"
launch mpirun_recipe deploy/cluster/mpirun_train.sh --recipe humanoid_tightrope --ranks 2 --actors 8
expect_started_with mpirun_recipe "@humanoid_tightrope" "task=humanoid_tightrope" "ppo.num_envs=512" \
  "ppo.minibatch_size=4096" "--max-updates 2000" "--num-envs 64"
slurm_job slurm_recipe 10 --recipe a1_beam
expect_started_with slurm_recipe "@a1_beam" "ppo.num_envs=512" "ppo.minibatch_size=4096" "--num-envs 64"
rm -rf "$work/runs"

echo "2. refused before anything starts, naming what to change"
launch mpirun_minibatch deploy/cluster/mpirun_train.sh a1_beam masa --actors 2 --envs 7 --set ppo.minibatch_size=1000
expect_refused mpirun_minibatch "ppo.minibatch_size"
launch mpirun_actors deploy/cluster/mpirun_train.sh a1_beam masa --ranks 2 --actors 3
expect_refused mpirun_actors "--actors"
launch mpirun_recipe_split deploy/cluster/mpirun_train.sh --recipe a1_beam --ranks 2 --actors 6
expect_refused mpirun_recipe_split "--envs"
slurm_job slurm_tasks 5 a1_beam masa --ranks 2
expect_refused slurm_tasks "--ntasks"
slurm_job slurm_minibatch 4 a1_beam masa --envs 7 --set ppo.minibatch_size=1000
expect_refused slurm_minibatch "ppo.minibatch_size"
launch train_minibatch timeout 60 deploy/train.sh a1_beam masa --envs 5 --updates 1 --set ppo.minibatch_size=100
expect_refused train_minibatch "ppo.minibatch_size"
launch train_ranks_minibatch deploy/train.sh a1_beam masa --ranks 2 --envs 5 --set ppo.minibatch_size=100
expect_refused train_ranks_minibatch "ppo.minibatch_size"
launch train_recipe_split timeout 60 deploy/train.sh --recipe a1_beam --actors 3 --updates 1
expect_refused train_recipe_split "--envs"

echo "3. masa_learner names the key"
launch learner_minibatch "$build/learner/masa_learner" --set task=humanoid_tightrope --set ppo.num_envs=448 \
  --run-dir "$work/runs/learner" --no-auth --url "udpm://239.255.76.67:7399?ttl=0"
expect_refused learner_minibatch "key 'ppo.minibatch_size': 32768 does not divide the batch"

[ "$failures" = 0 ] && echo "PASS: the launchers size the batch and refuse what they cannot, by option" ||
  echo "FAIL: $failures checks"
