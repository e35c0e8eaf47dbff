#!/usr/bin/env bash
# A hostile publisher on a live run (issue #9): a learner and two actors train over real multicast
# (udpm, ttl=0) while masa_lcm_fuzz republishes mutated copies of their live messages on every
# channel at 200 per second for 5 s.
#  1. Without authentication (--no-auth) the copies reach the wire guards and the validators: the
#     run still makes its updates, no process dies, every process exits cleanly, the learner's
#     parameters stay finite (its policy file loads, its MASA equivariance is checked on load, and
#     an episode with it is finite), and the copies are counted (malformed chunks at the learner,
#     rejected parameter messages at the actors; the learner reads heartbeats as acknowledgements of
#     its parameters, through the same guard; stats have no subscriber here).
#     masa_lcm_probe watches all four channels meanwhile and exits cleanly.
#  2. With the run key, every copy fails its tag: the learner accepts no chunk the actors did not
#     send, and counts the fuzzed chunks as unauthenticated.
#   MASA_BUILD_DIR=build bash tests/integration/live_fuzz.sh [PORT]
# Prints PASS and exits 0, or FAIL with the logs' tails and exits 1. About 40-80 s.
set -euo pipefail
cd "$(dirname "$0")/../.."
source tests/integration/lib.sh

port=${1:-7697}
fuzz_bin="$build/tools/masa_lcm_fuzz"
eval_bin="$build/tools/masa_eval"
probe_bin="$build/tools/masa_lcm_probe"
for b in "$fuzz_bin" "$eval_bin" "$probe_bin"; do [ -x "$b" ] || { echo "FAIL: $b is missing: build first"; exit 1; }; done

# fuzzed_run NAME [auth args...]: learner + 2 actors, the fuzzer for 5 s from the first update.
fuzzed_run() {
  local name=$1
  shift
  run="$work/$name"
  learner_log="$work/$name.learner.log"
  learner_log_file=$learner_log start_learner "$run" "$url" "$run_id" "$@"
  start_actor 0 "$url" "$run_id" "$@"
  a0=$actor_pid
  start_actor 1 "$url" "$run_id" "$@"
  a1=$actor_pid
  wait_until 60 "$name: a first update" at_least_updates "$run" 1
  local at_start
  at_start=$(updates_in "$run")
  # 5 s at 200 copies per second, and at least 8 updates made meanwhile.
  # A watcher on the same wire hears every fuzzed copy too (docs/inputs.md gap 16).
  "$probe_bin" --url "$url" --all --duration 7 --quiet > "$work/$name.probe.log" 2>&1 &
  probe_pid=$!
  started_pids+=("$probe_pid")
  "$fuzz_bin" --url "$url" --rate 200 --duration 5 --seed 7 > "$work/$name.fuzz.log" 2>&1 &
  fuzz_pid=$!
  started_pids+=("$fuzz_pid")
  wait_until 120 "$name: 8 updates under fuzzing" at_least_updates "$run" $((at_start + 8))
  wait "$fuzz_pid" || fail "$name: the fuzzer failed"
  wait "$probe_pid" || fail "$name: masa_lcm_probe did not exit cleanly under fuzzing: $(tail -n 3 "$work/$name.probe.log")"
  awk '$1 == "MASA_ROLLOUT" && $2 > 0 { found = 1 } END { exit !found }' "$work/$name.probe.log" ||
    fail "$name: masa_lcm_probe counted no rollout traffic: $(cat "$work/$name.probe.log")"
  for p in "$learner_pid" "$a0" "$a1"; do kill -0 "$p" 2> /dev/null || fail "$name: a process died under fuzzing"; done
  kill -TERM "$a0" "$a1"
  wait "$a0" || fail "$name: actor 0 did not exit cleanly"
  wait "$a1" || fail "$name: actor 1 did not exit cleanly"
  kill -INT "$learner_pid"
  wait "$learner_pid" || fail "$name: the learner did not exit cleanly"
  sent=$(sed -n 's/^masa_lcm_fuzz: \([0-9][0-9]*\) mutated copies sent in all$/\1/p' "$work/$name.fuzz.log")
  chunk_copies=$(sed -n 's/^masa_lcm_fuzz: MASA_ROLLOUT: .*, \([0-9][0-9]*\) mutated copies sent$/\1/p' "$work/$name.fuzz.log")
  [ -n "$sent" ] && [ "$sent" -ge 500 ] || fail "$name: the fuzzer sent only ${sent:-no} copies"
  [ -n "$chunk_copies" ] && [ "$chunk_copies" -gt 0 ] || fail "$name: no fuzzed rollout chunk"
  accepted=$(sed -n 's/^masa_learner: rollout chunks accepted \([0-9][0-9]*\).*/\1/p' "$learner_log")
  actor_chunks=0
  for a in 0 1; do
    n=$(sed -n 's/.*rollouts (incarnation [0-9]*), \([0-9][0-9]*\) chunks sent.*/\1/p' "$work/actor$a.log" | tail -1)
    actor_chunks=$((actor_chunks + ${n:-0}))
  done
  # The actors' logs are appended across both runs: keep each run's.
  for a in 0 1; do mv "$work/actor$a.log" "$work/$name.actor$a.log"; done
}

# The learner's parameters: the policy file loads (MASA equivariance checked) and acts finitely.
check_parameters() {
  "$eval_bin" "$run/policy.bin" --episodes 1 > "$work/$1.eval.log" 2>&1 || fail "$1: the policy file does not load or run"
  grep -qiE "nan|inf" "$work/$1.eval.log" && fail "$1: the evaluation shows non-finite numbers"
  true
}

begin_local_run live_fuzz "$port"
log "1. no authentication: fuzzed copies reach the guards and validators ($url, work dir $work)"
fuzzed_run open --no-auth
check_parameters open
malformed=$(sed -n 's/^masa_learner: rollout chunks accepted.*, malformed \([0-9][0-9]*\).*/\1/p' "$learner_log")
[ -n "$malformed" ] && [ "$malformed" -gt 0 ] || fail "open: the learner counted no malformed chunk ($chunk_copies fuzzed)"
[ "$accepted" -le $((actor_chunks + chunk_copies)) ] || fail "open: more chunks accepted than were sent"
grep -q "masa_learner: other messages rejected before decoding: " "$learner_log" ||
  fail "open: the learner did not say what else it rejected"
grep -q "rejected before decoding: .*MASA_POLICY" "$work/open.actor0.log" || fail "open: actor 0 counted no rejected parameter message"
open_summary="$sent copies ($chunk_copies chunks): learner accepted $accepted chunks of the actors' $actor_chunks, malformed $malformed"

log "2. with the run key: every fuzzed copy fails its tag"
run_id=$((run_id + 1))
fuzzed_run signed
check_parameters signed
unauth=$(sed -n 's/^masa_learner: rollout chunks accepted.*, unauthenticated \([0-9][0-9]*\).*/\1/p' "$learner_log")
[ -n "$unauth" ] && [ "$unauth" -gt 0 ] || fail "signed: no fuzzed chunk counted as unauthenticated"
[ "$unauth" -le "$chunk_copies" ] || fail "signed: $unauth unauthenticated chunks, more than the $chunk_copies fuzzed"
[ "$accepted" -le "$actor_chunks" ] || fail "signed: $accepted chunks accepted, more than the actors' $actor_chunks"
if grep -q "malformed" <(grep "^masa_learner: rollout chunks accepted" "$learner_log"); then
  fail "signed: a fuzzed chunk got past the tag check to the wire guard"
fi
echo "PASS: open: $open_summary; signed: $sent copies ($chunk_copies chunks), $unauth chunks unauthenticated, $accepted of the actors' $actor_chunks accepted; every process exited cleanly, parameters finite"
rm -rf "$work"
