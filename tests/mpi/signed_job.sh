#!/usr/bin/env bash
# A signed MPI job (issue #33, item 2): 2 learner ranks, 2 actors and a compromised actor
# (tests/mpi/forging_actor.cpp) started by mpirun as one job, over real LCM on loopback multicast.
# Every process signs with its own key, made in memory; the public keys are gathered over MPI.
#  1. The job trains to --max-updates and every process exits 0; rank 0 and both actors say they
#     sign with a key made in memory; the run directory has no key file (no run.key, no keys/) and
#     its job_roster lists learner 0 and the 3 actors, each with another key, and no learner rank 1;
#     masa_lcm_probe --roster job_roster verifies the broadcasts and refuses the forged ones.
#  2. The forging actor re-signs the learner's parameters with its actor key (version + 1000,
#     parameters zeroed): both actors refuse every one (MASA_POLICY: not_permitted), and its unsigned
#     copies (unauthenticated); no actor acted with a forged version (the learner dropped no chunk as
#     future_version). Its heartbeats in actor 0's name are refused by rank 0 (claims_another_sender),
#     and actor 1's chunks it copies from rank 1's rollout URL to rank 0's (another_ranks_actor).
#  3. No process of the job has a key on its command line (ps, during the job).
#  4. deploy/train.sh --ranks 2 signs by default (mpirun_train.sh --auth signed); --auth hmac gives
#     the job the run key RUN_DIR/run.key.
# Exit 77 (skipped) with the reason when mpirun is missing.
#   tests/mpi/signed_job.sh BUILD_DIR
set -euo pipefail
source "$(dirname "$0")/../integration/lib.sh"
[ $# -ge 1 ] && { build=$1; learner_bin="$build/learner/masa_learner"; actor_bin="$build/actors/masa_actor"; }
command -v mpirun > /dev/null || { echo "SKIP: no mpirun (bash scripts/install_deps.sh installs Open MPI)"; exit 77; }
require_binaries
forger_bin="$build/tests/masa_test_forging_actor"
[ -x "$forger_bin" ] || fail "$forger_bin is missing: build first"
mpirun_sh="$masa_repo/tests/mpi/mpirun.sh"
work=$(mktemp -d "${TMPDIR:-/tmp}/masa_mpi_signed.XXXXXX")
trap 'rm -rf "$work"' EXIT
port=$(( 7800 + RANDOM % 100 * 4 ))
url="udpm://239.255.76.67:$port?ttl=0&recv_buf_size=8388608"
marker=$((100000 + RANDOM * 7 % 800000))  # the seed marks this test's processes (ps)
sets=("${test_sets[@]}" --set ppo.horizon=16 --set ppo.minibatch_size=128 --set seed=$marker)
run="$work/run"

log "1. 2 learner ranks, 2 actors and a forging actor, signed, 8 updates"
timeout 180 "$mpirun_sh" -np 2 "$learner_bin" "${sets[@]}" --url "$url" --max-updates 8 --run-dir "$run" \
  : -np 2 "$actor_bin" "${sets[@]}" --num-envs 8 --await-params-s 5 \
  : -np 1 "$forger_bin" > "$work/job.log" 2>&1 &
launcher=$!
# A watcher with the job's roster (public keys only) verifies its broadcasts as an actor does.
for _ in $(seq 1 200); do [ -f "$run/job_roster" ] && break; sleep 0.05; done
"$build/tools/masa_lcm_probe" --url "$url" --channel MASA_POLICY --roster "$run/job_roster" --duration 2 --quiet \
  > "$work/probe.log" 2>&1 &
probe=$!
# 3. Every command line of the job while it runs: paths and settings, never a key.
for _ in $(seq 1 100); do
  [ -f "$run/metrics.csv" ] && break
  sleep 0.2
done
ps -eo args | grep -E "seed=$marker|masa_test_forging_actor" | grep -v grep > "$work/ps.txt" || true
wait "$launcher" || fail "the signed job failed or hung (exit $?)"
[ "$(($(wc -l < "$run/metrics.csv") - 1))" -eq 8 ] || fail "metrics.csv has not 8 updates"
grep -q "masa_learner: messages signed with a key made in memory (ed25519:" "$work/job.log" ||
  fail "rank 0 does not say it signs with a key made in memory"
[ "$(grep -c 'masa_actor [01]: actor [01] of 3 in an MPI job.*messages signed with a key made in memory, ed25519:' "$work/job.log")" -eq 2 ] ||
  fail "the 2 actors do not both say they sign with a key made in memory"
[ ! -e "$run/run.key" ] && [ ! -e "$run/keys" ] || fail "a signed job left a key file in its run directory"
[ -f "$run/job_roster" ] || fail "no job_roster in the run directory"
[ "$(grep -c '^learner 0 [0-9a-f]\{64\} MASA_POLICY,MASA_LEARNER_STATS$' "$run/job_roster")" -eq 1 ] ||
  fail "job_roster: not one learner 0 on its channels"
[ "$(grep -c '^actor [012] [0-9a-f]\{64\} MASA_ROLLOUT,MASA_ACTOR_HEARTBEAT$' "$run/job_roster")" -eq 3 ] ||
  fail "job_roster: not 3 actors on their channels"
grep -q '^learner 1 ' "$run/job_roster" && fail "job_roster lists learner rank 1, which publishes nothing"
[ "$(awk '!/^#/ {print $3}' "$run/job_roster" | sort -u | wc -l)" -eq 4 ] || fail "job_roster: keys are not all different"
wait "$probe" || fail "masa_lcm_probe --roster job_roster failed: $(tail -n 3 "$work/probe.log")"
awk '$1 == "MASA_POLICY" && $2 > 0 { found = 1 } END { exit !found }' "$work/probe.log" ||
  fail "the watcher verified no parameter broadcast with job_roster: $(cat "$work/probe.log")"
grep -q "rejected .* on MASA_POLICY" "$work/probe.log" || fail "the watcher refused no forged broadcast: $(cat "$work/probe.log")"
log "   8 updates; signed with keys made in memory; job_roster: learner 0 and 3 actors; a watcher verifies with it"

log "2. the forging actor's parameters and heartbeats are refused"
grep -E "forging actor 2: heard [1-9][0-9]* parameter messages; sent [1-9][0-9]* re-signed" "$work/job.log" ||
  fail "the forging actor heard no parameters or sent no forgery"
for a in 0 1; do
  line=$(grep "masa_actor $a: parameter messages refused after decoding" "$work/job.log") || fail "actor $a said nothing at its stop"
  echo "   $line"
  [[ $line =~ MASA_POLICY:\ [^\;]*not_permitted\ [1-9] ]] || fail "actor $a did not refuse the actor-signed parameters as not_permitted"
  [[ $line =~ MASA_POLICY:\ [^\;]*unauthenticated\ [1-9] ]] || fail "actor $a did not refuse the unsigned parameters"
done
grep "rank 0 of 2: rollout chunks accepted" "$work/job.log" | grep -q future_version &&
  fail "an actor acted with forged parameters (the learner dropped chunks of a future version)"
grep -E "rank 0 of 2: other messages rejected before decoding: .*on the parameters. URL .*MASA_ACTOR_HEARTBEAT: [^;]*claims_another_sender [1-9]" "$work/job.log" ||
  fail "rank 0 did not refuse the heartbeats in actor 0's name"
grep -E "forging actor 2: .*, [1-9][0-9]* of actor 1's chunks copied to rank 0" "$work/job.log" ||
  fail "the forging actor copied none of actor 1's chunks to rank 0"
grep -E "rank 0 of 2: rollout chunks accepted .*another_ranks_actor [1-9]" "$work/job.log" ||
  fail "rank 0 did not refuse actor 1's chunks copied to its rollout URL: $(grep 'rank 0 of 2: rollout chunks accepted' "$work/job.log")"

log "3. no key on a command line"
[ "$(wc -l < "$work/ps.txt")" -ge 4 ] || fail "ps saw $(wc -l < "$work/ps.txt") processes of the job"
grep -qE "[0-9a-fA-F]{64}|BEGIN|key-file|signing-key" "$work/ps.txt" && fail "a key or key file on a command line: $(cat "$work/ps.txt")"
log "   $(wc -l < "$work/ps.txt") command lines, none with a key"

log "4. deploy/train.sh --ranks 2: signed by default, --auth hmac with the run key"
train_sh() { MASA_BUILD_DIR=$build MASA_LCM_URL=$url timeout 150 bash "$masa_repo/deploy/train.sh" "$@"; }
small=(--set ppo.horizon=16 --set ppo.minibatch_size=128 --set seed=$marker --set "model.policy_hidden=[16]"
       --set "model.critic_hidden=[16]")
train_sh a1_beam masa --ranks 2 --actors 2 --envs 8 --updates 2 --run-dir "$work/run_sh" "${small[@]}" \
  > "$work/sh.log" 2>&1 || fail "train.sh --ranks 2 failed (exit $?)"
grep -q "masa_learner: messages signed with a key made in memory" "$work/sh.log" || fail "train.sh --ranks 2 did not sign"
[ ! -e "$work/run_sh/run.key" ] || fail "train.sh --ranks 2 made a run key for a signed job"
train_sh a1_beam masa --ranks 2 --actors 2 --envs 8 --updates 2 --run-dir "$work/run_hmac" --auth hmac "${small[@]}" \
  > "$work/hmac.log" 2>&1 || fail "train.sh --ranks 2 --auth hmac failed (exit $?)"
grep -q "masa_learner: messages authenticated with the run key $work/run_hmac/run.key" "$work/hmac.log" ||
  fail "train.sh --ranks 2 --auth hmac did not use RUN_DIR/run.key"
[ "$(grep -c "messages authenticated with the job's run key" "$work/hmac.log")" -eq 2 ] || fail "the hmac job's actors did not take the run key"
log "   signed by default; --auth hmac uses RUN_DIR/run.key"
echo "PASS"
