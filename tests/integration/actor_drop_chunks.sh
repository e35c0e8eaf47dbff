#!/usr/bin/env bash
# Fault test over real multicast (udpm, ttl=0): both actors throw away a share of their rollout
# chunks (masa_actor's test-only fault injection, --drop-chunks-percent, seeded), as a lossy network
# would. Training must not stall (updates keep coming: nothing waits for a missing chunk) and the
# learner must count what never arrived ("lost", from the gaps in each actor's rollout numbering).
#   MASA_BUILD_DIR=build bash tests/integration/actor_drop_chunks.sh [PORT] [PERCENT]
# Prints PASS and exits 0, or FAIL with the logs' tails and exits 1. About 20-40 s.
set -euo pipefail
cd "$(dirname "$0")/../.."
source tests/integration/lib.sh

port=${1:-7672}
percent=${2:-30}
begin_local_run drop_chunks "$port"

log "learner and 2 actors throwing away $percent% of their chunks, on $url (work dir $work)"
start_learner "$run" "$url" "$run_id"
start_actor 0 "$url" "$run_id" --drop-chunks-percent "$percent" --drop-seed 11
a0=$actor_pid
start_actor 1 "$url" "$run_id" --drop-chunks-percent "$percent" --drop-seed 12
a1=$actor_pid
wait_until 60 "8 updates despite the dropped chunks (the learner stalled?)" at_least_updates "$run" 8

kill -TERM "$a0" "$a1"
wait "$a0" "$a1" || fail "an actor did not stop cleanly on SIGTERM"
kill -INT "$learner_pid"
wait "$learner_pid" || fail "the learner did not exit cleanly on SIGINT"

thrown=0
for a in 0 1; do
  n=$(sed -n 's/.*, \([0-9][0-9]*\) thrown away by fault injection.*/\1/p' "$work/actor$a.log" | tail -1)
  [ -n "$n" ] || fail "actor $a did not report its fault-injection count"
  thrown=$((thrown + n))
done
[ "$thrown" -gt 0 ] || fail "the actors threw away no chunk: the fault injection did nothing"
# The learner's summary at exit counts every chunk that never arrived (the last two rollouts of each
# actor excepted: their gaps are counted once the actor is two rollouts past them).
lost=$(sed -n 's/^masa_learner: rollout chunks accepted.*, lost \([0-9][0-9]*\).*/\1/p' "$work/learner.log" | tail -1)
[ -n "$lost" ] && [ "$lost" -gt 0 ] || fail "the learner counted no lost chunk although the actors threw away $thrown"
# Exact for rollouts partly received, estimated (the actor's chunks per rollout) for wholly lost ones.
[ "$lost" -ge $((thrown / 2)) ] && [ "$lost" -le $((thrown + 8)) ] ||
  fail "the learner counted $lost lost chunks, the actors threw away $thrown"
echo "PASS: $(updates_in "$run") updates with $percent% of chunks thrown away; actors threw away $thrown, the learner counted $lost lost"
rm -rf "$work"
