#!/usr/bin/env bash
# A signed run (issue #33, item 2) over real multicast (udpm, ttl=0), separate processes, started by
# deploy/train.sh as a user starts one: a key per process and the roster made before anything
# starts, only file paths on the command lines. While it trains, two intruders publish rollouts:
#  - "actor 2", with a key of its own and a roster that lists it (made by another masa_roster): the
#    run's roster does not list actor 2, so the learner refuses its chunks as unknown_sender;
#  - an actor with a run key (HMAC, the old mode): its chunks carry no SIG1 trailer, unauthenticated.
# Passes when the run makes its updates from its own actors 0 and 1, no private key or key material
# is on any process's command line, the private keys are mode 0600, and the learner counted both
# intruders' chunks by reason and accepted none ("actor 2 joined" never appears).
#   MASA_BUILD_DIR=build bash tests/integration/signed_run.sh [PORT]
# Prints PASS and exits 0, or FAIL with the logs' tails and exits 1. About 30-60 s.
set -euo pipefail
cd "$(dirname "$0")/../.."
source tests/integration/lib.sh

port=${1:-7717}
begin_local_run signed "$port"
url="udpm://239.255.77.177:$port?ttl=0"
roster_bin="$build/tools/masa_roster"
[ -x "$roster_bin" ] || fail "$roster_bin is missing: build masa_roster"

log "deploy/train.sh, signed (its default), on $url (work dir $work)"
MASA_BUILD_DIR=$build MASA_LCM_URL=$url bash deploy/train.sh a1_beam masa --actors 2 --envs 8 --updates 16 \
  --run-dir "$run" --set model.policy_hidden=[16] --set model.critic_hidden=[16] --set ppo.minibatch_size=256 \
  --set runner.eval_every=0 > "$work/train.log" 2>&1 &
train_pid=$!
started_pids+=("$train_pid")
# The intruders start as soon as the run has an id, so that they publish while it trains.
wait_until 60 "the run's id" test -s "$run/run_id"
run_id=$(cat "$run/run_id")
"$roster_bin" make "$work/other" --actors 3 > /dev/null
start_actor 2 "$url" "$run_id" --roster "$work/other/roster" --signing-key "$work/other/keys/actor2.key" --start-without-learner
intruder=$actor_pid
bash deploy/run_key.sh "$work/other.key"
start_actor 3 "$url" "$run_id" --key-file "$work/other.key" --start-without-learner
hmac=$actor_pid
wait_until 90 "the learner's first update" at_least_updates "$run" 1
# A watcher with the roster and no key (masa_lcm_probe --roster) counts the run's own chunks and
# refuses the intruders' by reason.
"$build/tools/masa_lcm_probe" --url "$url" --channel MASA_ROLLOUT --roster "$run/roster" --duration 3 --quiet \
  > "$work/probe.log" 2>&1 &
probe=$!

# What is on the command lines of the run's processes: paths, never a key.
args=$(ps -eo args | grep -E "masa_(learner|actor)" | grep -F "$run" | grep -v grep || true)
[ -n "$args" ] || fail "no masa_learner or masa_actor of the run in ps"
grep -q -- "--signing-key $run/keys/learner0.key" <<< "$args" || fail "the learner was not given its key file: $args"
grep -q -- "--signing-key $run/keys/actor1.key" <<< "$args" || fail "actor 1 was not given its key file: $args"
! grep -q "PRIVATE KEY\|--key-file" <<< "$args" || fail "key material or a run key on a command line: $args"
for k in learner0 actor0 actor1; do
  [ "$(stat -c %a "$run/keys/$k.key")" = 600 ] || fail "$run/keys/$k.key is not mode 0600"
done
[ "$(grep -c '^actor ' "$run/roster")" = 2 ] && [ "$(grep -c '^learner 0 ' "$run/roster")" = 1 ] ||
  fail "the roster does not list the learner and actors 0 and 1: $(cat "$run/roster")"

wait "$train_pid" || fail "train.sh did not finish cleanly"
wait "$probe" || fail "masa_lcm_probe --roster failed: $(tail -n 3 "$work/probe.log")"
awk '$1 == "MASA_ROLLOUT" && $2 > 0 { found = 1 } END { exit !found }' "$work/probe.log" ||
  fail "the watcher verified no chunk of the run: $(cat "$work/probe.log")"
grep -q "rejected .* on MASA_ROLLOUT" "$work/probe.log" || fail "the watcher refused no intruder's chunk: $(cat "$work/probe.log")"
kill -TERM "$intruder" "$hmac"
wait "$intruder" "$hmac" || fail "an intruding actor did not stop cleanly on SIGTERM"

learner_log="$run/learner.log"
[ -f "$learner_log" ] || learner_log="$work/train.log"
grep -q "messages signed with $run/keys/learner0.key" "$work/train.log" || fail "the learner did not sign with its own key"
grep -q "messages signed with $run/keys/actor0.key" "$run/actor0.log" || fail "actor 0 did not sign with its own key"
[ "$(updates_in "$run")" -ge 16 ] || fail "only $(updates_in "$run") updates"
! grep -q "actor 2 joined\|actor 3 joined" "$work/train.log" || fail "an intruder's chunk was accepted"
sent=$(sed -n 's/.*rollouts (incarnation [0-9]*), \([0-9][0-9]*\) chunks sent.*/\1/p' "$work/actor2.log" | tail -1)
[ -n "$sent" ] && [ "$sent" -gt 0 ] || fail "the intruder with its own key sent no chunk: nothing was tried"
line=$(grep "rollout chunks accepted" "$work/train.log" | tail -1)
unknown=$(sed -n 's/.*unknown_sender \([0-9][0-9]*\).*/\1/p' <<< "$line")
unauth=$(sed -n 's/.*unauthenticated \([0-9][0-9]*\).*/\1/p' <<< "$line")
[ -n "$unknown" ] && [ "$unknown" -gt 0 ] || fail "no chunk counted unknown_sender: $line"
[ "$unknown" -le "$sent" ] || fail "$unknown chunks counted unknown_sender, more than the $sent actor 2 sent"
[ -n "$unauth" ] && [ "$unauth" -gt 0 ] || fail "no chunk of the run-key actor counted unauthenticated: $line"
echo "PASS: $(updates_in "$run") signed updates from actors 0 and 1 (a watcher with the roster verified them too); the learner refused $unknown chunks of an unlisted actor 2 (unknown_sender) and $unauth of a run-key actor (unauthenticated); keys mode 0600, only paths on command lines"
rm -rf "$work"
