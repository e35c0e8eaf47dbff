#!/usr/bin/env bash
# Fault test over real multicast (udpm, ttl=0), with the learner and two actors as separate processes:
#  1. actor 1 is killed (SIGKILL) mid-run: the learner goes on making updates with actor 0 alone;
#  2. actor 1 is started again with the same id: the learner reports it restarted, drops none of
#     its chunks as duplicates, and, once actor 0 is killed too, keeps updating on actor 1's data
#     alone, which shows that the restarted actor's chunks are accepted and trained on;
#  3. actor 1 is killed too: the learner says that no data arrives and names both actors.
#   MASA_BUILD_DIR=build bash tests/integration/actor_kill_restart.sh [PORT]
# Prints PASS and exits 0, or prints FAIL with the logs' tails and exits 1. About 30-60 s.
set -euo pipefail
cd "$(dirname "$0")/../.."
source tests/integration/lib.sh

port=${1:-7671}
begin_local_run kill_restart "$port"

log "learner and actors 0, 1 on $url (work dir $work)"
start_learner "$run" "$url" "$run_id" --set runner.silence_warn_s=6
start_actor 0 "$url" "$run_id"
actor0=$actor_pid
start_actor 1 "$url" "$run_id"
actor1=$actor_pid
wait_until 40 "2 updates with both actors" at_least_updates "$run" 2
grep -q "actor 0 joined" "$work/learner.log" || fail "the learner did not report actor 0 joining"
grep -q "actor 1 joined" "$work/learner.log" || fail "the learner did not report actor 1 joining"

# 1. Kill actor 1 without warning: nothing it would have sent may be waited for.
kill -KILL "$actor1"
wait "$actor1" 2>/dev/null || true
n=$(updates_in "$run")
log "killed actor 1 at update $n"
wait_until 25 "3 more updates after actor 1 was killed (the learner stalled?)" at_least_updates "$run" $((n + 3))
log "PASS part 1: $(( $(updates_in "$run") - n )) updates with actor 1 dead"

# 2. Restart actor 1 with the same id: it must be accepted at once, not taken for a replay.
start_actor 1 "$url" "$run_id"
wait_until 20 "the learner to report actor 1's restart" grep -q "actor 1 restarted" "$work/learner.log"
kill -KILL "$actor0"
wait "$actor0" 2>/dev/null || true
n=$(updates_in "$run")
log "actor 1 restarted and accepted; killed actor 0 at update $n: actor 1 alone feeds the learner now"
wait_until 25 "3 updates from the restarted actor 1 alone (its chunks rejected?)" at_least_updates "$run" $((n + 3))
if grep -q "(duplicate)" "$work/learner.log"; then
  grep "(duplicate)" "$work/learner.log" | head -3
  fail "the learner dropped chunks as duplicates: the restarted actor was taken for a replay"
fi

log "PASS part 2: restarted actor 1 rejoined; $(( $(updates_in "$run") - n )) updates on its data alone"

# 3. Every actor dead: the learner says so, with the actors it last heard from.
actor1=$actor_pid
kill -KILL "$actor1"
wait "$actor1" 2>/dev/null || true
wait_until 20 "the learner to say that no data arrives and name actors 0 and 1" \
  grep -qE "no rollout data for [0-9]+ s \(at update [0-9]+\); last heard from actor 0 [0-9]+ s ago \([0-9]+ chunks\), actor 1" "$work/learner.log"
log "PASS part 3: $(grep -m1 "no rollout data" "$work/learner.log")"

kill -INT "$learner_pid"
wait "$learner_pid" || fail "the learner did not exit cleanly on SIGINT"
grep -q "checkpoint written" "$work/learner.log" || fail "the learner did not checkpoint on SIGINT"
echo "PASS: killed actor tolerated, restarted actor accepted again, silence reported ($(updates_in "$run") updates in all)"
rm -rf "$work"
