#!/usr/bin/env bash
# Trains with one learner on this machine and K actor processes, either on this machine over
# loopback LCM (udpm, ttl=0), or, with --hosts FILE, on the hosts FILE lists, started there over ssh
# and talking over LAN multicast (udpm, ttl=1). Ctrl-C stops everything cleanly, remote actors
# included; the learner checkpoints, so the run directory is resumable.
#   deploy/train.sh [task] [method] [--actors K] [--envs E] [--updates N] [--set key=value ...]
#   deploy/train.sh --recipe NAME [--actors K] [--run-dir DIR] ...   (configs/recipes/NAME.yaml: its task,
#                   method, batch and ppo.max_updates updates; its environments split over the actors)
#   deploy/train.sh [task] [method] --hosts FILE [--envs E] [--updates N] [--set key=value ...]
#   deploy/train.sh --resume RUN_DIR [--actors K] [--envs E] [--updates N]   (N counts all updates)
#   deploy/train.sh ... --ranks L   (L data-parallel learner ranks on this machine: the same MPI job as
#                   on a cluster, started by deploy/cluster/mpirun_train.sh; L must divide K and E*K)
# FILE has one host per line, "host [actors] [envs]" (default 1 actor of E environments), '#'
# comments; "localhost" runs its actors here without ssh. See deploy/hosts.example.
# Every message is signed (--auth signed, the default): each process has its own Ed25519 key,
# RUN_DIR/keys/<role><index>.key (mode 0600; MASA_KEYS_DIR puts them elsewhere, on this host's own
# disk when RUN_DIR is on a file system other hosts mount), and RUN_DIR/roster says whose key may publish on which
# channel (the learner's alone on MASA_POLICY, each actor's on its own rollouts and heartbeats), so a
# stolen actor key can neither forge parameters nor another actor's rollouts; both are made here by
# masa_roster before anything starts, kept on --resume (where the actors beyond --actors K leave the
# roster: a run no longer believes actors it does not run), and with --hosts each host gets the roster
# and only its own actors' keys, over the remote shell's stdin. With --ranks the MPI job's processes
# make their keys in memory and gather the public keys over MPI (no key file). --auth hmac authenticates with one
# run key, RUN_DIR/run.key, shared by all (any holder can forge anything; no replay protection);
# --no-auth (--auth none) runs without (docs/reliability.md, "Message authentication").
# MASA_BUILD_DIR (default build) and MASA_RUNS_DIR (default runs) choose the folders, MASA_LCM_URL
# the LCM URL (default: multicast with the largest receive buffer the kernel allows). With --hosts:
#   MASA_REMOTE_SHELL      how to run a command on a host (default "ssh -o BatchMode=yes"); it is
#                          called as `$MASA_REMOTE_SHELL HOST 'shell command'`, with the launcher's
#                          keep-alive pipe on stdin (see deploy/tethered.sh)
#   MASA_REMOTE_DIR        this repository's path on the hosts (default: the same as here)
#   MASA_REMOTE_BUILD_DIR  the build folder there, relative to MASA_REMOTE_DIR (default MASA_BUILD_DIR)
# Defaults are sized for a 2-core machine (the paper's 4096 x 32 batches are GPU-scale):
# 2 actors x 32 environments, horizon 32, minibatch 1024. Override anything with --set. The config's
# horizon is kept and its minibatch sized for the environments asked for (deploy/batch_size.sh,
# said at the start); a ppo.minibatch_size that cannot divide the batch is refused before anything starts.
set -euo pipefail
cd "$(dirname "$0")/.."

task=a1_beam method=masa task_given=0 method_given=0
[ $# -gt 0 ] && [[ $1 != --* ]] && { task=$1; task_given=1; shift; }
[ $# -gt 0 ] && [[ $1 != --* ]] && { method=$1; method_given=1; shift; }
actors=2 envs=32 envs_given=0 updates="" hosts_file="" actors_given=0 resume="" recipe="" run_dir_given="" auth_mode=signed ranks=1
sets=() user_sets=()
while [ $# -gt 0 ]; do
  case "$1" in
    --resume) resume=$2; shift 2 ;;
    --actors) actors=$2; actors_given=1; shift 2 ;;
    --envs) envs=$2; envs_given=1; shift 2 ;;
    --recipe) recipe=$2; shift 2 ;;
    --run-dir) run_dir_given=$2; shift 2 ;;
    --updates) updates=$2; shift 2 ;;
    --hosts) hosts_file=$2; shift 2 ;;
    --set) sets+=(--set "$2"); user_sets+=("$2"); shift 2 ;;
    --no-auth) auth_mode=none; shift ;;
    --auth) auth_mode=$2; shift 2 ;;
    --ranks) ranks=$2; shift 2 ;;
    *) echo "train.sh: unknown option '$1'" >&2; exit 2 ;;
  esac
done

case "$auth_mode" in
  signed | hmac | none) ;;
  *) echo "train.sh: --auth '$auth_mode': expected signed, hmac or none" >&2; exit 2 ;;
esac
no_auth=0
[ "$auth_mode" = none ] && no_auth=1

for pair in "--actors:$actors" "--envs:$envs" ${updates:+"--updates:$updates"} "--ranks:$ranks"; do
  [[ ${pair#*:} =~ ^[1-9][0-9]*$ ]] || { echo "train.sh: ${pair%%:*} '${pair#*:}' is not a positive count" >&2; exit 2; }
done

build=${MASA_BUILD_DIR:-build}
for bin in "$build/learner/masa_learner" "$build/actors/masa_actor" "$build/tools/masa_config" \
           $([ "$auth_mode" = signed ] && [ "$ranks" = 1 ] && echo "$build/tools/masa_roster"); do
  [ -x "$bin" ] || { echo "train.sh: $bin is missing: run scripts/build.sh first" >&2; exit 2; }
done

# A recipe names the task, the method, the batch and the run's length; what the command line
# gives (task, method, --envs, --updates, --set) still wins.
if [ -n "$recipe" ]; then
  [ -z "$resume" ] || { echo "train.sh: --recipe starts a run; --resume goes on with the run's own config" >&2; exit 2; }
  resolved=$("$build/tools/masa_config" --set "@$recipe" "${sets[@]+"${sets[@]}"}") || exit 2
  [ "$task_given" = 1 ] || task=$(sed -n 's/^task: //p' <<< "$resolved")
  [ "$method_given" = 1 ] || method=$(sed -n 's/^method: //p' <<< "$resolved")
  shape=$("$build/tools/masa_config" --rollout --set "@$recipe" "${sets[@]+"${sets[@]}"}") || exit 2
  recipe_envs=$(sed -n 's/^num_envs: //p' <<< "$shape")
  [ -n "$updates" ] || updates=$(sed -n 's/^max_updates: //p' <<< "$shape")
  if [ "$envs_given" = 0 ] && [ -z "$hosts_file" ]; then
    if (( recipe_envs % actors != 0 )); then
      echo "train.sh: recipe $recipe has $recipe_envs environments, not divisible over $actors actors (give --envs)" >&2
      exit 2
    fi
    envs=$((recipe_envs / actors))
  fi
fi
updates=${updates:-200}
source deploy/batch_size.sh
# The run's config before its environments (deploy/batch_size.sh sizes the minibatch from it). Without a
# recipe: sized for a 2-core machine, 2 actors x 32 environments x horizon 32 in minibatches of 1024
# (the paper's batches, 4096 envs x 32 steps, minibatch 32768, are GPU-scale).
if [ -n "$recipe" ]; then
  run_config=(--set "@$recipe" --set task="$task" --set method="$method" "${sets[@]+"${sets[@]}"}")
else
  run_config=(--set task="$task" --set method="$method")
  shape=$("$build/tools/masa_config" --rollout "${run_config[@]}" "${sets[@]+"${sets[@]}"}") || exit 2
  # PPO's minibatches as for 64 environments (the off-policy learner has its own small default).
  if grep -qx 'section: ppo' <<< "$shape"; then
    run_config+=(--set ppo.num_envs=64 --set ppo.horizon=32 --set ppo.minibatch_size=1024)
  fi
  run_config+=("${sets[@]+"${sets[@]}"}")
fi
# A resumed run's environments: its config's, over the actors, unless --envs says otherwise.
if [ -n "$resume" ] && [ "$envs_given" = 0 ] && [ -z "$hosts_file" ] && [ -r "$resume/config.yaml" ]; then
  run_envs=$("$build/tools/masa_config" --run-config "$resume/config.yaml" --rollout | sed -n 's/^num_envs: //p')
  if [[ $run_envs =~ ^[0-9]+$ ]] && (( run_envs % actors == 0 )); then envs=$((run_envs / actors)); fi
fi

# Data-parallel learner ranks: the job a cluster runs (every process takes its role, actor id, URL
# and the run key from the MPI job, docs/scaling.md), here on this machine, so one machine and many
# share one role logic. One rank (the default) is the plain learner below and needs no MPI.
if [ "$ranks" -gt 1 ]; then
  [ -z "$hosts_file" ] || { echo "train.sh: --ranks with --hosts: on several machines use deploy/cluster/mpirun_train.sh --hostfile or deploy/cluster/slurm_train.sbatch" >&2; exit 2; }
  command -v "${MASA_MPIRUN:-mpirun}" > /dev/null ||
    { echo "train.sh: --ranks needs Open MPI's mpirun (bash scripts/install_deps.sh installs it, then build again)" >&2; exit 2; }
  (( actors % ranks == 0 )) || { echo "train.sh: $actors actors do not divide among $ranks learner ranks (each rank takes its share)" >&2; exit 2; }
  job=("$task" "$method" --ranks "$ranks" --actors "$actors" --envs "$envs" --updates "$updates")
  # Signed: every process of the job makes its own key in memory and the public keys are gathered
  # over MPI (no roster file, no key file); hmac: learner rank 0 hands RUN_DIR/run.key over MPI.
  job+=(--auth "$auth_mode")
  if [ -n "$resume" ]; then
    for f in checkpoint.bin config.yaml; do
      [ -r "$resume/$f" ] || { echo "train.sh: $resume/$f is missing: not a run directory" >&2; exit 2; }
    done
    job+=(--resume "$resume" "${sets[@]+"${sets[@]}"}")
  else
    run_dir=${run_dir_given:-"${MASA_RUNS_DIR:-runs}/${task}_${method}_$(date +%Y%m%d_%H%M%S)"}
    job+=(--run-dir "$run_dir")
    size_batch train.sh $((actors * envs)) "${run_config[@]}" || exit 2
    # The sized minibatch goes as a setting of the job's (mpirun_train.sh checks that it divides).
    [ -n "$recipe" ] && job+=(--set "@$recipe") || job+=(--set ppo.horizon=32)
    job+=("${sets[@]+"${sets[@]}"}" "${batch_sets[@]+"${batch_sets[@]}"}")
    echo "train.sh: $batch_summary"
  fi
  echo "train.sh: $task / $method, $ranks learner ranks, $actors actors x $envs envs, $updates updates, one MPI job"
  exec bash deploy/cluster/mpirun_train.sh "${job[@]}"
fi

# Actor placement: host, actor count and environments per actor, one entry per hosts-file line.
hosts=() host_actors=() host_envs=()
if [ -n "$hosts_file" ]; then
  [ "$actors_given" = 0 ] || { echo "train.sh: --actors and --hosts exclude each other (the hosts file gives the actors)" >&2; exit 2; }
  [ -r "$hosts_file" ] || { echo "train.sh: cannot read hosts file '$hosts_file'" >&2; exit 2; }
  host_name_pattern='^[][A-Za-z0-9_.@:%][][A-Za-z0-9_.@:%-]*$'
  line_no=0
  while IFS= read -r line || [ -n "$line" ]; do
    line_no=$((line_no + 1))
    line=${line%%#*}
    read -r h n e extra <<< "$line" || true
    [ -n "${h:-}" ] || continue
    n=${n:-1} e=${e:-$envs}
    if [ -n "${extra:-}" ] || ! [[ "$n" =~ ^[1-9][0-9]*$ && "$e" =~ ^[1-9][0-9]*$ ]]; then
      echo "train.sh: $hosts_file:$line_no: expected 'host [actors] [envs]' with positive counts, got '$line'" >&2
      exit 2
    fi
    # The name goes to ssh and rsync as an argument: one starting with "-" would be an option
    # (-oProxyCommand=... runs a command), and quotes or shell syntax have no place in a host name.
    if ! [[ "$h" =~ $host_name_pattern ]]; then
      echo "train.sh: $hosts_file:$line_no: '$h' is not a host name ([user@]host of letters, digits and _ . : % [ ] -, not starting with -)" >&2
      exit 2
    fi
    hosts+=("$h") host_actors+=("$n") host_envs+=("$e")
  done < "$hosts_file"
  [ ${#hosts[@]} -gt 0 ] || { echo "train.sh: $hosts_file lists no host" >&2; exit 2; }
else
  hosts=(localhost) host_actors=("$actors") host_envs=("$envs")
fi
actors=0 total_envs=0
for i in "${!hosts[@]}"; do
  actors=$((actors + host_actors[i]))
  total_envs=$((total_envs + host_actors[i] * host_envs[i]))
done

# Ask for the receive buffer the kernel allows (LCM drops large messages with a small one).
# ttl=0 keeps the traffic on this machine; ttl=1 lets it cross one LAN segment to the hosts.
rmem=$(cat /proc/sys/net/core/rmem_max 2>/dev/null || echo 2097152)
buf=$(( rmem < 8388608 ? rmem : 8388608 ))
ttl=$([ -n "$hosts_file" ] && echo 1 || echo 0)
url=${MASA_LCM_URL:-"udpm://239.255.76.67:7667?ttl=$ttl&recv_buf_size=$buf"}
if [ -n "$resume" ]; then
  # The run goes on with its own config.yaml and run id; --set still overrides (e.g. a longer run).
  [ -z "$hosts_file" ] || { echo "train.sh: --resume is for runs on this machine (start masa_learner --resume by hand with --hosts)" >&2; exit 2; }
  for f in checkpoint.bin config.yaml run_id; do
    [ -r "$resume/$f" ] || { echo "train.sh: $resume/$f is missing: not a run directory of train.sh" >&2; exit 2; }
  done
  run_dir=$resume run_id=$(cat "$resume/run_id")
  learner_run=(--resume "$run_dir")
  actor_config=(--run-config "$run_dir/config.yaml")
  common=("${sets[@]+"${sets[@]}"}")
  task=$(sed -n 's/^task: //p' "$run_dir/config.yaml") method=$(sed -n 's/^method: //p' "$run_dir/config.yaml")
else
  # Sized before anything is made: a refused request leaves nothing behind.
  size_batch train.sh "$total_envs" "${run_config[@]}" || exit 2
  echo "train.sh: $batch_summary"
  run_id=$(( ($(date +%s%N) / 1000) % 2000000000 + 1 ))
  run_dir=${run_dir_given:-"${MASA_RUNS_DIR:-runs}/${task}_${method}_$(date +%Y%m%d_%H%M%S)"}
  mkdir -p "$run_dir"
  echo "$run_id" > "$run_dir/run_id"
  learner_run=(--run-dir "$run_dir")
  actor_config=()
  common=("${run_config[@]}" "${batch_sets[@]+"${batch_sets[@]}"}")
fi

# The keys, before anything starts: the learner and every actor read theirs at start-up. Only
# file paths go on command lines, never a key.
if [ "$auth_mode" = none ]; then
  auth=(--no-auth)
  echo "train.sh: WARNING: --no-auth: messages are not authenticated; anyone on the network can feed this run" >&2
elif [ "$auth_mode" = hmac ]; then
  bash deploy/run_key.sh "$run_dir/run.key"
  auth=(--key-file "$run_dir/run.key")
else
  # MASA_KEYS_DIR: the private keys on this host's own disk, when the run directory is on a file
  # system other hosts mount (else every host could read the learner's key there).
  keys_dir=${MASA_KEYS_DIR:-$run_dir/keys}
  "$build/tools/masa_roster" make "$run_dir" --keys "$keys_dir" --actors "$actors" > /dev/null ||
    { echo "train.sh: cannot make the keys and roster in $run_dir (keys in $keys_dir)" >&2; exit 2; }
  auth=(--roster "$run_dir/roster" --signing-key "$keys_dir/learner0.key")
fi
# The options that give actor $1 on host $2 (default here) its key: here, in the keys directory;
# another host, the copy carried to its run directory (below).
actor_auth() {
  if [ "$auth_mode" = signed ]; then
    local key="$run_dir/keys/actor$1.key"
    [ "${2:-localhost}" = localhost ] && key="$keys_dir/actor$1.key"
    actor_auth_args=(--roster "$run_dir/roster" --signing-key "$key")
  else
    actor_auth_args=("${auth[@]}")
  fi
}

# Keep-alive pipe: every actor's and the learner's tethered.sh reads it on stdin, and only this
# script holds its write end (children close it), so when this script ends in any way, even by
# SIGKILL, each of them sees end of file and stops its program: nothing is left running, here or
# on the hosts. Local runs and multi-host runs alike. The fifo's name is removed at once; the open ends remain.
fifo_dir=$(mktemp -d)
mkfifo "$fifo_dir/keepalive"
exec {keep}<>"$fifo_dir/keepalive"
exec {alive_in}<"$fifo_dir/keepalive"
rm -rf "$fifo_dir"

if [ -z "$hosts_file" ]; then
  echo "train.sh: $task / $method, $actors actors x $envs envs, $updates updates, run dir $run_dir"
  # The learner may be in an update when told to stop: give it time to finish and checkpoint.
  MASA_TETHER_GRACE_S=300 bash deploy/tethered.sh "$build/learner/masa_learner" "${common[@]+"${common[@]}"}" \
    --url "$url" --run-id "$run_id" "${learner_run[@]}" "${auth[@]}" --max-updates "$updates" \
    <&"$alive_in" {keep}>&- {alive_in}<&- &
  learner=$!
  pids=()
  for ((a = 0; a < actors; ++a)); do
    actor_auth "$a"
    OMP_NUM_THREADS=1 bash deploy/tethered.sh "$build/actors/masa_actor" "${actor_config[@]+"${actor_config[@]}"}" \
      "${common[@]+"${common[@]}"}" --url "$url" --run-id "$run_id" "${actor_auth_args[@]}" --actor-id "$a" --num-envs "$envs" \
      <&"$alive_in" >> "$run_dir/actor$a.log" 2>&1 {keep}>&- {alive_in}<&- &
    pids+=($!)
  done
  exec {alive_in}<&-

  stop() {
    # SIGTERM: the tethered learner's wrapper, started in the background, cannot trap SIGINT.
    kill -TERM "$learner" 2>/dev/null || true
    wait "$learner" 2>/dev/null || true
    kill -TERM "${pids[@]}" 2>/dev/null || true
    wait "${pids[@]}" 2>/dev/null || true
  }
  trap 'echo "train.sh: stopping"; stop; exit 130' INT TERM
  wait "$learner" || true
  kill -TERM "${pids[@]}" 2>/dev/null || true
  wait "${pids[@]}" 2>/dev/null || true
  echo "train.sh: done. Curves: $run_dir/learning_curve.png, metrics: $run_dir/metrics.csv."
  echo "train.sh: to go on to N updates in total: deploy/train.sh --resume $run_dir --actors $actors --envs $envs --updates N"
  exit 0
fi

# --- Multi-host form ---
read -r -a remote_shell <<< "${MASA_REMOTE_SHELL:-ssh -o BatchMode=yes}"
remote_dir=${MASA_REMOTE_DIR:-$PWD}
remote_build=${MASA_REMOTE_BUILD_DIR:-$build}

echo "train.sh: $task / $method over $url, $actors actors on ${#hosts[@]} hosts ($total_envs envs), $updates updates, run dir $run_dir"

# The run key goes to each actor host before anything starts, on the remote shell's stdin (never on
# a command line: `ps` shows those), to the same path under MASA_REMOTE_DIR, mode 0600. Written
# under a temporary name and renamed: a host that shares this file system keeps the one key.
# Signed: each host gets the roster (public) and the keys of its own actors only, the same way.
remote_path() {  # a path under the run dir as the host sees it (relative: under MASA_REMOTE_DIR)
  [[ $1 = /* ]] && echo "$1" || echo "$remote_dir/$1"
}
if [ "$auth_mode" = signed ]; then
  carry_file() {  # host, file here, its path under run_dir there, umask
    local q
    q=$(printf %q "$run_dir/$3")
    "${remote_shell[@]}" "$1" "cd $(printf %q "$remote_dir") && umask $4 && mkdir -p $(printf %q "$run_dir/keys") && cat > $q.tmp.\$\$ && mv -f $q.tmp.\$\$ $q" \
      < "$2" || { echo "train.sh: cannot carry $3 to $1 (to $(remote_path "$run_dir/$3") there)" >&2; exit 2; }
  }
  a=0
  for i in "${!hosts[@]}"; do
    h=${hosts[i]}
    if [ "$h" != localhost ]; then
      carry_file "$h" "$run_dir/roster" roster 077
      for ((k = 0; k < host_actors[i]; ++k)); do carry_file "$h" "$keys_dir/actor$((a + k)).key" "keys/actor$((a + k)).key" 077; done
    fi
    a=$((a + host_actors[i]))
  done
fi
if [ "$auth_mode" = hmac ]; then
  for h in $(printf '%s\n' "${hosts[@]}" | sort -u); do
    [ "$h" = localhost ] && continue
    key_q=$(printf %q "$run_dir/run.key")
    carry="cd $(printf %q "$remote_dir") && mkdir -p $(printf %q "$run_dir") && umask 077 && cat > $key_q.tmp.\$\$ && mv -f $key_q.tmp.\$\$ $key_q"
    "${remote_shell[@]}" "$h" "$carry" < "$run_dir/run.key" ||
      { echo "train.sh: cannot carry the run key to $h (to $(remote_path "$run_dir/run.key") there)" >&2; exit 2; }
  done
fi

# The learner may be in an update when told to stop: give it time to finish and checkpoint.
MASA_TETHER_GRACE_S=300 bash deploy/tethered.sh "$build/learner/masa_learner" "${common[@]}" --url "$url" \
  --run-id "$run_id" --run-dir "$run_dir" "${auth[@]}" --max-updates "$updates" <&"$alive_in" {keep}>&- {alive_in}<&- &
learner=$!
pids=() pid_actor=()
a=0
for i in "${!hosts[@]}"; do
  h=${hosts[i]}
  for ((k = 0; k < host_actors[i]; ++k)); do
    # localhost: this repository and build; another host: MASA_REMOTE_DIR and MASA_REMOTE_BUILD_DIR there.
    dir=$remote_dir bin_dir=$remote_build
    [ "$h" = localhost ] && dir=$PWD bin_dir=$build
    actor_auth "$a" "$h"
    actor_cmd=("$bin_dir/actors/masa_actor" "${common[@]}" --url "$url" --run-id "$run_id" "${actor_auth_args[@]}" --actor-id "$a"
               --num-envs "${host_envs[i]}")
    cmd="cd $(printf %q "$dir") && exec env OMP_NUM_THREADS=1 bash deploy/tethered.sh $(printf '%q ' "${actor_cmd[@]}")"
    log="$run_dir/actor$a.log"
    echo "# actor $a on $h, ${host_envs[i]} envs" > "$log"
    echo "train.sh: actor $a on $h (${host_envs[i]} envs), log $log"
    if [ "$h" = localhost ]; then
      bash -c "$cmd" <&"$alive_in" >> "$log" 2>&1 {keep}>&- {alive_in}<&- &
    else
      "${remote_shell[@]}" "$h" "$cmd" <&"$alive_in" >> "$log" 2>&1 {keep}>&- {alive_in}<&- &
    fi
    pids+=($!) pid_actor+=("$a")
    a=$((a + 1))
  done
done
exec {alive_in}<&-

# Closes the keep-alive pipe and gives the remote actors time to stop, then ends their shells.
stop_actors() {
  exec {keep}>&- 2>/dev/null || true
  local t
  for ((t = 0; t < 150; ++t)); do
    local alive=0 p
    for p in "${pids[@]}"; do kill -0 "$p" 2>/dev/null && alive=1; done
    [ "$alive" = 0 ] && break
    sleep 0.1
  done
  kill -TERM "${pids[@]}" 2>/dev/null || true
  wait "${pids[@]}" 2>/dev/null || true
}
stop() {
  # SIGTERM: the tethered learner's wrapper, started in the background, cannot trap SIGINT.
  kill -TERM "$learner" 2>/dev/null || true
  wait "$learner" 2>/dev/null || true
  stop_actors
}
trap 'echo "train.sh: stopping"; stop; exit 130' INT TERM

# Training goes on when an actor dies (the learner takes whoever is alive); say so, and where its log is.
running=("${pids[@]}")
while kill -0 "$learner" 2>/dev/null; do
  ended=""
  set +e
  wait -n -p ended "$learner" "${running[@]}"
  status=$?
  set -e
  [ -z "$ended" ] || [ "$ended" = "$learner" ] && break
  still=()
  for j in "${!pids[@]}"; do
    if [ "${pids[j]}" = "$ended" ]; then
      echo "train.sh: actor ${pid_actor[j]} ended (status $status) while training; see $run_dir/actor${pid_actor[j]}.log" >&2
    fi
  done
  for p in "${running[@]}"; do [ "$p" = "$ended" ] || still+=("$p"); done
  running=("${still[@]}")
done
wait "$learner" 2>/dev/null || true
stop_actors
echo "train.sh: done. Metrics: $run_dir/metrics.csv. Resume: $build/learner/masa_learner --resume $run_dir (with the same --set options)"
