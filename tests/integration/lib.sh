# Helpers for the process tests in tests/integration (sourced, not run).
# They start masa_learner and masa_actor as separate processes talking over real LCM (udpm) and
# judge progress from the learner's metrics.csv (one row per update) and its log.

build=${MASA_BUILD_DIR:-build}
[[ "$build" = /* ]] || build="$PWD/$build"
learner_bin="$build/learner/masa_learner"
actor_bin="$build/actors/masa_actor"
masa_repo=$(cd "$(dirname "${BASH_SOURCE[0]}")/../.." && pwd)

# Small networks and batches: these tests are about the system, not learning. 2 actors x 8 envs.
# The learning curve is drawn on exit only (a gnuplot render every 10 updates cost the suite seconds).
test_sets=(--set task=a1_beam --set method=masa --set ppo.num_envs=16 --set ppo.horizon=32
           --set ppo.minibatch_size=256 --set model.policy_hidden=[16] --set model.critic_hidden=[16]
           --set runner.plot_every=0)

started_pids=()

log() { echo "[$(date +%H:%M:%S)] $*"; }

fail() {
  echo "FAIL: $*"
  [ -n "${work:-}" ] && [ -d "$work" ] && for f in "$work"/*.log "$work"/run/*.log; do
    [ -f "$f" ] && { echo "--- tail of $f"; tail -n 25 "$f"; }
  done
  exit 1
}

require_binaries() {
  local b
  for b in "$learner_bin" "$actor_bin"; do
    [ -x "$b" ] || { echo "FAIL: $b is missing: build first (MASA_BUILD_DIR=$build)"; exit 1; }
  done
}

# begin_local_run NAME PORT: a test's processes on this machine's loopback multicast: sets url
# (ttl=0, on PORT), a fresh run_id, work (a new folder) and run ($work/run); what the test starts
# is killed when it exits.
begin_local_run() {
  url="udpm://239.255.76.67:$2?ttl=0"
  run_id=$(( ($(date +%s%N) / 1000) % 2000000000 + 1 ))
  work=$(mktemp -d "${TMPDIR:-/tmp}/masa_$1.XXXXXX")
  run="$work/run"
  trap 'kill_started' EXIT
  require_binaries
}

# Stops every process this test started, by pid.
kill_started() {
  local p
  for p in "${started_pids[@]}"; do kill -KILL "$p" 2>/dev/null || true; done
  for p in "${started_pids[@]}"; do wait "$p" 2>/dev/null || true; done
}

# Updates the learner has made: data rows of metrics.csv.
updates_in() {
  local csv="$1/metrics.csv"
  [ -f "$csv" ] || { echo 0; return; }
  local n
  n=$(wc -l < "$csv")
  echo $(( n > 0 ? n - 1 : 0 ))
}

# wait_until SECONDS DESCRIPTION COMMAND...: polls COMMAND every 0.2 s; fails the test on timeout.
wait_until() {
  local limit=$1 what=$2
  shift 2
  local deadline=$(( $(date +%s%N) + limit * 1000000000 ))
  until "$@"; do
    [ "$(date +%s%N)" -lt "$deadline" ] || fail "$what: not within ${limit} s"
    sleep 0.2
  done
}

at_least_updates() { [ "$(updates_in "$1")" -ge "$2" ]; }

# Sets auth=(--key-file $work/run.key), the run key every process of a test shares (made on first
# use), or auth=() when the arguments given already choose (--key-file or --no-auth).
set_auth() {
  local a
  for a in "$@"; do
    [[ "$a" == --key-file || "$a" == --no-auth || "$a" == --roster ]] && { auth=(); return 0; }
  done
  bash "$masa_repo/deploy/run_key.sh" "$work/run.key"
  auth=(--key-file "$work/run.key")
}

# start_learner RUN_DIR URL RUN_ID [extra args...]: a learner in the background, log in
# $learner_log_file (default $work/learner.log; a test that runs several learners names each one's
# here, since moving the file after the start raced with the learner's shell opening it).
start_learner() {
  local dir=$1 url=$2 rid=$3
  shift 3
  set_auth "$@"
  "$learner_bin" "${test_sets[@]}" --url "$url" --run-id "$rid" --run-dir "$dir" --max-updates 100000 "${auth[@]+"${auth[@]}"}" "$@" \
    > "${learner_log_file:-$work/learner.log}" 2>&1 &
  learner_pid=$!
  started_pids+=("$learner_pid")
}

# start_actor ID URL RUN_ID [extra args...]: sets actor_pid; log appended to $work/actorID.log.
start_actor() {
  local id=$1 url=$2 rid=$3
  shift 3
  set_auth "$@"
  OMP_NUM_THREADS=1 "$actor_bin" "${test_sets[@]}" --url "$url" --run-id "$rid" --actor-id "$id" --num-envs 8 "${auth[@]+"${auth[@]}"}" "$@" \
    >> "$work/actor$id.log" 2>&1 &
  actor_pid=$!
  started_pids+=("$actor_pid")
}
