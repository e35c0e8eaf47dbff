#!/usr/bin/env bash
# Message authentication over real multicast (udpm, ttl=0), separate processes: a learner and
# actor 0 share the run key; actor 1 has another key and actor 2 none (--no-auth). Actors 1 and 2
# start with their own parameters (--start-without-learner), so that they do publish rollouts.
#  - training goes on with actor 0 (updates come, "actor 0 joined");
#  - no chunk of actor 1 or 2 is ever accepted ("actor 1 joined" never appears): the learner drops
#    them as unauthenticated and counts them;
#  - actor 1 never acts with the learner's parameters: it rejects them as unauthenticated.
#   MASA_BUILD_DIR=build bash tests/integration/wrong_key_actor.sh [PORT]
# Prints PASS and exits 0, or FAIL with the logs' tails and exits 1. About 20-40 s.
set -euo pipefail
cd "$(dirname "$0")/../.."
source tests/integration/lib.sh

port=${1:-7676}
begin_local_run wrong_key "$port"

bash deploy/run_key.sh "$work/other.key"
log "learner and actor 0 with the run key, actor 1 with another key, actor 2 with none, on $url (work dir $work)"
start_learner "$run" "$url" "$run_id"
start_actor 0 "$url" "$run_id"
a0=$actor_pid
start_actor 1 "$url" "$run_id" --key-file "$work/other.key" --start-without-learner
a1=$actor_pid
start_actor 2 "$url" "$run_id" --no-auth --start-without-learner
a2=$actor_pid
wait_until 60 "4 updates with actor 0" at_least_updates "$run" 4
# Actors 1 and 2 publish from their start; let each finish a few rollouts.
sleep 2

kill -TERM "$a0" "$a1" "$a2"
wait "$a0" "$a1" "$a2" || fail "an actor did not stop cleanly on SIGTERM"
kill -INT "$learner_pid"
wait "$learner_pid" || fail "the learner did not exit cleanly on SIGINT"

grep -q "actor 0 joined" "$work/learner.log" || fail "no chunk of actor 0 (the run's key) was accepted"
for a in 1 2; do
  ! grep -q "actor $a joined" "$work/learner.log" || fail "a chunk of actor $a (not the run's key) was accepted"
done
sent=0
for a in 1 2; do
  n=$(sed -n 's/.*rollouts (incarnation [0-9]*), \([0-9][0-9]*\) chunks sent.*/\1/p' "$work/actor$a.log" | tail -1)
  [ -n "$n" ] && [ "$n" -gt 0 ] || fail "actor $a sent no chunk: nothing was tried"
  sent=$((sent + n))
done
unauth=$(sed -n 's/^masa_learner: rollout chunks accepted.*, unauthenticated \([0-9][0-9]*\).*/\1/p' "$work/learner.log" | tail -1)
[ -n "$unauth" ] && [ "$unauth" -gt 0 ] || fail "the learner counted no unauthenticated chunk; actors 1 and 2 sent $sent"
[ "$unauth" -le "$sent" ] || fail "the learner counted $unauth unauthenticated chunks, more than the $sent that actors 1 and 2 sent"
grep -q "MASA_POLICY (latest: unauthenticated)" "$work/actor1.log" ||
  fail "actor 1 (another key) did not report the learner's parameters as unauthenticated"
echo "PASS: $(updates_in "$run") updates from actor 0; actors 1 (another key) and 2 (no key) sent $sent chunks, the learner dropped $unauth as unauthenticated and accepted none"
rm -rf "$work"
