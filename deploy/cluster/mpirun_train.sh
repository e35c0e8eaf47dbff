#!/usr/bin/env bash
# Trains as one MPI job: L data-parallel learner ranks and A actor processes, started, placed and
# stopped by mpirun (Open MPI), on this machine or on the hosts of an Open MPI hostfile. Every
# process learns its role and place from the job (docs/scaling.md): actor i sends its rollouts to
# learner rank i mod L on that rank's own multicast port; learner rank 0 broadcasts the parameters
# and writes the run directory. --auth signed (the default): every process signs with its own key,
# made in memory, and the public keys are gathered over MPI (RUN_DIR/job_roster is their list, for
# a watcher); --auth hmac: learner rank 0 hands the run key RUN_DIR/run.key to every process over
# MPI; --auth none (or --no-auth): nothing. No key is ever on a command line. Ctrl-C stops the job;
# its checkpoint is resumable with --resume.
#   deploy/cluster/mpirun_train.sh [task] [method] [--recipe NAME] [--ranks L] [--actors A] [--envs E]
#       [--threads T] [--hostfile FILE] [--updates N] [--run-dir DIR | --resume DIR]
#       [--auth signed|hmac|none] [--no-auth] [--set key=value ...]
#       [-- extra mpirun options]
# Defaults: 2 ranks, 2 actors of 32 environments, 1 thread each; the learner's num_envs = A x E, which the
# ranks share equally. --recipe NAME (configs/recipes/NAME.yaml) gives the task, method, updates
# and environments (split over the actors unless --envs is given). The config's horizon is kept and
# its minibatch sized for A x E environments (deploy/batch_size.sh; said before the job starts); a
# request that cannot be met is refused before anything starts. The run directory is
# ${MASA_RUNS_DIR:-runs}/<task>_<method>_<time> unless --run-dir. With --hostfile the URL is LAN multicast (ttl=1); see
# deploy/cluster/hostfile.example. MASA_BUILD_DIR (default build) is the build on every host (the
# same path everywhere); MASA_LCM_URL overrides the URL; MASA_MPIRUN the mpirun to use.
set -euo pipefail
# Paths the user gave are relative to where the command was typed; the script runs in the repository.
absolute() { [[ $1 = /* ]] && echo "$1" || echo "$PWD/$1"; }

task=a1_beam method=masa task_given=0 method_given=0
[ $# -gt 0 ] && [[ $1 != --* ]] && { task=$1; task_given=1; shift; }
[ $# -gt 0 ] && [[ $1 != --* ]] && { method=$1; method_given=1; shift; }
ranks=2 actors=2 envs=32 envs_given=0 threads=1 hostfile="" updates="" run_dir="" resume="" auth=signed recipe=""
sets=() user_sets=() recipe_sets=() mpi_extra=()
while [ $# -gt 0 ]; do
  case "$1" in
    --recipe) recipe=$2; shift 2 ;;
    --ranks) ranks=$2; shift 2 ;;
    --actors) actors=$2; shift 2 ;;
    --envs) envs=$2; envs_given=1; shift 2 ;;
    --threads) threads=$2; shift 2 ;;
    --hostfile) hostfile=$(absolute "$2"); shift 2 ;;
    --updates) updates=$2; shift 2 ;;
    --run-dir) run_dir=$(absolute "$2"); shift 2 ;;
    --resume) resume=$(absolute "$2"); shift 2 ;;
    --set) sets+=(--set "$2"); user_sets+=("$2"); shift 2 ;;
    --auth) auth=$2; shift 2 ;;
    --no-auth) auth=none; shift ;;
    --) shift; mpi_extra=("$@"); break ;;
    *) echo "mpirun_train.sh: unknown option '$1'" >&2; exit 2 ;;
  esac
done
for pair in "--ranks:$ranks" "--actors:$actors" "--envs:$envs" "--threads:$threads" ${updates:+"--updates:$updates"}; do
  [[ ${pair#*:} =~ ^[1-9][0-9]*$ ]] || { echo "mpirun_train.sh: ${pair%%:*} '${pair#*:}' is not a positive count" >&2; exit 2; }
done
cd "$(dirname "$0")/../.."
case "$auth" in
  signed | hmac | none) ;;
  *) echo "mpirun_train.sh: --auth '$auth': expected signed, hmac or none" >&2; exit 2 ;;
esac
[ "$auth" != hmac ] || [ -n "$run_dir$resume" ] ||
  { echo "mpirun_train.sh: --auth hmac needs --run-dir or --resume (the run key is RUN_DIR/run.key)" >&2; exit 2; }
(( actors % ranks == 0 )) ||
  { echo "mpirun_train.sh: $actors actors do not divide among $ranks learner ranks: give --actors a multiple of --ranks" >&2; exit 2; }
[ -z "$recipe" ] || [ -z "$resume" ] ||
  { echo "mpirun_train.sh: --recipe starts a run; --resume goes on with the run's own config" >&2; exit 2; }
build=${MASA_BUILD_DIR:-build}
for bin in "$build/learner/masa_learner" "$build/actors/masa_actor" "$build/tools/masa_config"; do
  [ -x "$bin" ] || { echo "mpirun_train.sh: $bin is missing: build first (scripts/build.sh)" >&2; exit 2; }
done
source deploy/batch_size.sh
if [ -n "$recipe" ]; then
  # The recipe names the task, the method, the environments and the run's length; what the command
  # line gives still wins.
  resolved=$("$build/tools/masa_config" --set "@$recipe" "${sets[@]+"${sets[@]}"}") || exit 2
  [ "$task_given" = 1 ] || task=$(sed -n 's/^task: //p' <<< "$resolved")
  [ "$method_given" = 1 ] || method=$(sed -n 's/^method: //p' <<< "$resolved")
  shape=$("$build/tools/masa_config" --rollout --set "@$recipe" "${sets[@]+"${sets[@]}"}") || exit 2
  [ -n "$updates" ] || updates=$(shape_key max_updates <<< "$shape")
  if [ "$envs_given" = 0 ]; then
    recipe_envs=$(shape_key num_envs <<< "$shape")
    (( recipe_envs % actors == 0 )) ||
      { echo "mpirun_train.sh: recipe $recipe has $recipe_envs environments, not divisible over $actors actors: give --envs (per actor) or another --actors" >&2; exit 2; }
    envs=$((recipe_envs / actors))
  fi
  recipe_sets=(--set "@$recipe")
fi
if [ -n "$hostfile" ]; then
  [ -f "$hostfile" ] || { echo "mpirun_train.sh: no hostfile '$hostfile'" >&2; exit 2; }
  url=${MASA_LCM_URL:-"udpm://239.255.76.67:7667?ttl=1&recv_buf_size=8388608"}
  mpi_extra=(--hostfile "$hostfile" "${mpi_extra[@]}")
else
  url=${MASA_LCM_URL:-"udpm://239.255.76.67:7667?ttl=0&recv_buf_size=8388608"}
fi

config=("${recipe_sets[@]+"${recipe_sets[@]}"}" --set "task=$task" --set "method=$method" "${sets[@]+"${sets[@]}"}")
if [ -z "$resume" ]; then
  size_batch mpirun_train.sh $((actors * envs)) "${config[@]}" || exit 2
  config+=("${batch_sets[@]+"${batch_sets[@]}"}")
  run_dir=${run_dir:-$(absolute "${MASA_RUNS_DIR:-runs}/${task}_${method}_$(date +%Y%m%d_%H%M%S)")}
  echo "mpirun_train.sh: $task / $method, $ranks learner ranks, $actors actors x $envs envs: $batch_summary${updates:+, $updates updates}, run dir $run_dir"
else
  echo "mpirun_train.sh: resuming $resume with its own config, $ranks learner ranks, $actors actors x $envs envs${updates:+, to $updates updates}"
fi
learner_args=(--url "$url")
[ -n "$updates" ] && learner_args+=(--max-updates "$updates")
# The learner ranks sign by default in a job; the actors learn the mode from the job's plan.
[ "$auth" != none ] || learner_args+=(--no-auth)
[ "$auth" != hmac ] || learner_args+=(--key-file "${resume:-$run_dir}/run.key")
if [ -n "$resume" ]; then
  learner_args+=(--resume "$resume")
  config=("${sets[@]+"${sets[@]}"}")
  actor_config=(--run-config "$resume/config.yaml" "${sets[@]+"${sets[@]}"}")
else
  learner_args+=(--run-dir "$run_dir")
  actor_config=("${config[@]}")
fi
# Open MPI refuses root unless told (containers and CI run as root); nobody else needs the override.
# A 2-core workstation runs more processes than cores (--oversubscribe).
[ "$(id -u)" -ne 0 ] || export OMPI_ALLOW_RUN_AS_ROOT=1 OMPI_ALLOW_RUN_AS_ROOT_CONFIRM=1
set -x
exec "${MASA_MPIRUN:-mpirun}" --oversubscribe --bind-to none -x OMP_NUM_THREADS="$threads" "${mpi_extra[@]}" \
  -np "$ranks" "$build/learner/masa_learner" "${config[@]}" "${learner_args[@]}" \
  : -np "$actors" "$build/actors/masa_actor" "${actor_config[@]}" --num-envs "$envs" --threads "$threads"
