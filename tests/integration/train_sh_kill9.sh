#!/usr/bin/env bash
# A local run of deploy/train.sh (learner + 2 actors on this machine) whose launcher is killed with
# SIGKILL leaves nothing running: the learner and the actors are tethered to the launcher's
# keep-alive pipe, see its end and stop (before the fix they trained on for good).
#   MASA_BUILD_DIR=build bash tests/integration/train_sh_kill9.sh [PORT]
set -euo pipefail
cd "$(dirname "$0")/../.."
source tests/integration/lib.sh
port=${1:-7675}
work=$(mktemp -d "${TMPDIR:-/tmp}/masa_kill9.XXXXXX")
run="$work/run"
# Under set -e a failing command in the trap ends the script with its status: pkill finds nothing
# once the run has stopped (exit 1), which made the test exit 1 after its PASS line.
trap 'kill_started; if [ -n "${run_id:-}" ]; then pkill -KILL -f -- "--run-id $run_id( |$)" 2>/dev/null || true; fi' EXIT
require_binaries

MASA_BUILD_DIR=$build MASA_LCM_URL="udpm://239.255.76.67:$port?ttl=0" \
  bash deploy/train.sh a1_beam masa --actors 2 --envs 8 --updates 100000 --run-dir "$run" \
  --set model.policy_hidden=[16] --set model.critic_hidden=[16] --set ppo.minibatch_size=256 > "$work/train.log" 2>&1 &
launcher=$!
started_pids+=("$launcher")
wait_until 60 "2 updates of the local run" at_least_updates "$run" 2
run_id=$(cat "$run/run_id")
n=$(pgrep -c -f -- "--run-id $run_id( |$)" || true)
[ "$n" -ge 3 ] || fail "expected the learner and 2 actors with run id $run_id, found $n processes"
kill -KILL "$launcher"
log "killed train.sh (SIGKILL) at update $(updates_in "$run"); $n processes of run $run_id running"
gone() { ! pgrep -f -- "--run-id $run_id( |$)" > /dev/null; }
wait_until 30 "the learner and actors to stop after their launcher was killed" gone
grep -q "checkpoint written" "$run/../train.log" "$run"/*.log 2>/dev/null || log "(no checkpoint line seen; the learner was told to stop)"
echo "PASS: train.sh killed with SIGKILL; its learner and 2 actors stopped"
rm -rf "$work"
