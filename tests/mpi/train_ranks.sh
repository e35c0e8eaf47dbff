#!/usr/bin/env bash
# Training as one MPI job (issue #30): 2 learner ranks and 2 actors started by mpirun (MPMD), over
# real LCM on loopback multicast, each actor feeding its own rank's URL.
#  0. One learner rank and one actor train (the actor sent to the job's URL while a lone learner
#     rank listened on its rank port: it hung before the fix).
#  1. The job trains to --max-updates and every process exits 0: the actors stop when the learner
#     ranks end training. metrics.csv has one row per update and counts the env steps of both
#     ranks; the ranks checked their parameter hashes (every 2 updates) without a mismatch; rank 0
#     heard both actors acknowledge parameters (it heard only its own before).
#  2. Resumed as a new job from rank 0's checkpoint, it goes on to the new total.
#  3. A learner rank killed with SIGKILL ends the whole job within seconds (no hang).
#  4. Ctrl-C of mpirun (SIGINT) stops every process within seconds, the learners after a checkpoint.
#  5. An actor frozen (SIGSTOP: dead to its rank, alive to mpirun): its rank hears nothing for
#     runner.rank_silence_stop_s and stops every rank with the reason, after a checkpoint, exit 3;
#     the job ends (it waited for ever before).
#  6. deploy/train.sh --ranks 2, the one-machine entry, runs the same job (2 ranks, 2 actors) to its
#     end; --ranks that do not divide the actors are refused before anything starts.
#   tests/mpi/train_ranks.sh [BUILD_DIR]
set -euo pipefail
source "$(dirname "$0")/../integration/lib.sh"
[ $# -ge 1 ] && { build=$1; learner_bin="$build/learner/masa_learner"; actor_bin="$build/actors/masa_actor"; }
require_binaries
mpirun_sh="$masa_repo/tests/mpi/mpirun.sh"
work=$(mktemp -d "${TMPDIR:-/tmp}/masa_mpi_ranks.XXXXXX")
trap 'rm -rf "$work"' EXIT
port=$(( 7800 + RANDOM % 100 * 4 ))
url="udpm://239.255.76.67:$port?ttl=0&recv_buf_size=8388608"
# 16 envs x 16 steps, 8 a rank; the seed marks this test's processes (pgrep)
marker=$((100000 + RANDOM * 7 % 800000))
sets=("${test_sets[@]}" --set ppo.horizon=16 --set ppo.minibatch_size=128 --set seed=$marker)
job_processes() { pgrep -fc "^($learner_bin|$actor_bin) .*seed=$marker" || true; }

job() {  # job UPDATES [extra learner args]: 2 learner ranks, 2 actors of 8 environments
  local updates=$1; shift
  timeout 120 "$mpirun_sh" -np 2 "$learner_bin" "${sets[@]}" --url "$url" --max-updates "$updates" --rank-check-every 2 "$@" \
    : -np 2 "$actor_bin" "${sets[@]}" --num-envs 8 --await-params-s 5
}

log "0. one learner rank and one actor under mpirun, 3 updates"
timeout 60 "$mpirun_sh" -np 1 "$learner_bin" "${sets[@]}" --url "$url" --max-updates 3 --run-dir "$work/run1" \
  : -np 1 "$actor_bin" "${sets[@]}" --num-envs 16 > "$work/job0.log" 2>&1 || fail "one rank: the job failed or hung"
[ "$(($(wc -l < "$work/run1/metrics.csv") - 1))" -eq 3 ] || fail "one rank: not 3 updates"
log "   3 updates (the actor sends where the one learner listens)"

log "1. 2 learner ranks + 2 actors, 6 updates"
job 6 --run-dir "$work/run" > "$work/job1.log" 2>&1 || fail "the job failed or hung (exit $?)"
rows=$(($(wc -l < "$work/run/metrics.csv") - 1))
[ "$rows" -eq 6 ] || fail "metrics.csv has $rows rows, expected 6"
steps=$(tail -n 1 "$work/run/metrics.csv" | cut -d, -f2)
[ "$steps" -eq $((6 * 16 * 16)) ] || fail "env steps $steps, expected $((6 * 16 * 16)) (both ranks' batches)"
grep -q "rank 1 of 2: run id" "$work/job1.log" || fail "no rank 1"
[ "$(grep -c 'rollouts to learner rank' "$work/job1.log")" -eq 2 ] || fail "the actors did not report their ranks"
grep -q "differ between learner ranks" "$work/job1.log" && fail "the ranks disagreed"
grep -q "stopped after" "$work/job1.log" || fail "no clean stop"
# Rank 0 broadcasts the parameters and hears every actor's acknowledgement, not only its own actor's.
grep -q "actors that acknowledged parameters 2" "$work/job1.log" || fail "rank 0 did not hear both actors acknowledge"
[ -f "$work/run/checkpoint.bin" ] && [ -f "$work/run/policy.bin" ] || fail "rank 0 wrote no checkpoint or policy"
log "   6 updates, $steps env steps, every process exited 0"

log "2. resumed as a new job to 9 updates"
job 9 --resume "$work/run" > "$work/job2.log" 2>&1 || fail "the resumed job failed or hung (exit $?)"
rows=$(($(wc -l < "$work/run/metrics.csv") - 1))
[ "$rows" -eq 9 ] || fail "after resuming metrics.csv has $rows rows, expected 9"
log "   resumed from 6 to 9"

# start_long_job NAME: a job of 1000 updates in the background (launcher=its pid), returning once
# it has made 2 updates. stop_and_check WHAT: after the fault, the job must be gone within 15 s.
start_long_job() {
  job 1000 --run-dir "$work/$1" > "$work/$1.log" 2>&1 &
  launcher=$!
  for _ in $(seq 1 300); do
    [ -f "$work/$1/metrics.csv" ] && [ "$(wc -l < "$work/$1/metrics.csv")" -ge 3 ] && break
    sleep 0.1
  done
  t0=$(date +%s)
}
stop_and_check() {
  for _ in $(seq 1 150); do kill -0 "$launcher" 2> /dev/null || break; sleep 0.1; done
  kill -0 "$launcher" 2> /dev/null && { pkill -KILL -f "seed=$marker" || true; fail "the job still runs 15 s after $1"; }
  sleep 0.5
  [ "$(job_processes)" -eq 0 ] || fail "$(job_processes) processes of the job are left after $1"
  log "   every process gone $(( $(date +%s) - t0 )) s after $1"
}

log "3. a learner rank killed with SIGKILL ends the job"
start_long_job run_kill
victim=$(pgrep -f "^$learner_bin .*run_kill" | tail -n 1) || fail "no learner rank to kill"
kill -KILL "$victim"
stop_and_check "a rank was killed"

log "4. Ctrl-C of mpirun"
start_long_job run_int
mpirun_pid=$(pgrep -f "^mpirun .*run_int" | head -n 1) || fail "no mpirun"
kill -INT "$mpirun_pid"
stop_and_check "Ctrl-C"
[ -f "$work/run_int/checkpoint.bin" ] || fail "no checkpoint after Ctrl-C"

log "5. one actor frozen: its rank stops the job after runner.rank_silence_stop_s (4 s)"
sets+=(--set runner.rank_silence_stop_s=4)
start_long_job run_silent
frozen=$(pgrep -f "^$actor_bin .*seed=$marker" | head -n 1) || fail "no actor to freeze"
kill -STOP "$frozen"
stop_and_check "an actor froze"
kill -CONT "$frozen" 2> /dev/null || true
grep -q "no rollout data for .* stopping every rank" "$work/run_silent.log" || fail "the silent rank said nothing"
grep -q "the learner ranks stop at update .*: 1 of 2 heard no rollout data" "$work/run_silent.log" ||
  fail "rank 0 did not say why the ranks stopped"
wait "$launcher" && fail "the job ended with status 0 although it stopped short"
[ -f "$work/run_silent/checkpoint.bin" ] || fail "no checkpoint after the silent stop"

log "6. deploy/train.sh --ranks 2: the same job from the one-machine entry"
train_sh() { MASA_BUILD_DIR=$build MASA_LCM_URL=$url timeout 120 bash "$masa_repo/deploy/train.sh" "$@"; }
train_sh a1_beam masa --ranks 3 --actors 2 --envs 8 --updates 3 > "$work/sh_bad.log" 2>&1 && fail "3 ranks for 2 actors accepted"
grep -q "2 actors do not divide among 3 learner ranks" "$work/sh_bad.log" || fail "no reason for refusing 3 ranks"
train_sh a1_beam masa --ranks 2 --actors 2 --envs 8 --updates 4 --run-dir "$work/run_sh" \
  --set ppo.horizon=16 --set ppo.minibatch_size=128 --set seed=$marker --set "model.policy_hidden=[16]" \
  --set "model.critic_hidden=[16]" > "$work/sh.log" 2>&1 || fail "train.sh --ranks 2 failed (exit $?)"
[ "$(($(wc -l < "$work/run_sh/metrics.csv") - 1))" -eq 4 ] || fail "train.sh --ranks 2: not 4 updates"
grep -q "rank 1 of 2: run id" "$work/sh.log" || fail "train.sh --ranks 2 ran no rank 1"
[ "$(grep -c 'rollouts to learner rank' "$work/sh.log")" -eq 2 ] || fail "train.sh --ranks 2: the actors did not take their ranks from the job"
log "   4 updates with 2 ranks; 3 ranks for 2 actors refused"
echo "PASS"
