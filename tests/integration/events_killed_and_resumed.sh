#!/usr/bin/env bash
# TensorBoard events of a run killed and resumed (issue #51, item 2): masa_train is killed (SIGKILL)
# past its last checkpoint, resumed to the end; the event file, read by an independent decoder
# (tests/tools/read_tfevents.py: Python's protobuf, CRCs checked), holds every update's scalars
# once, in step order, equal to metrics.csv's, and the config as text. The same for an off-policy run
# (off_policy.csv's rows too).
#   tests/integration/events_killed_and_resumed.sh BUILD_DIR WORK_DIR SOURCE_DIR
source "$(dirname "$0")/masa_train_case.sh"
reader="$3/tests/tools/read_tfevents.py"
check() {  # run dir, updates: every update once, in order, returns as metrics.csv has them
  /usr/bin/python3 "$reader" "$1/events.out.tfevents.masa" > "$1/events.txt" || fail "$1: the event file does not read: $(tail -n 2 "$1/events.txt")"
  grep -q "^0 text config " "$1/events.txt" || fail "$1: no config text"
  /usr/bin/python3 - "$1" "$2" << 'PY' || fail "$1: events and metrics.csv disagree"
import csv, sys
run, updates = sys.argv[1], int(sys.argv[2])
rows = list(csv.DictReader(open(run + "/metrics.csv")))
assert len(rows) == updates, f"{len(rows)} rows"
seen = {}
last_step = -1
for line in open(run + "/events.txt"):
    step, kind, rest = line.split(" ", 2)
    if kind != "scalar":
        continue
    tag, value = rest.rsplit(" ", 1)
    assert int(step) >= last_step, f"step {step} after {last_step}"
    last_step = int(step)
    assert (tag, step) not in seen, f"{tag} at {step} twice"
    seen[(tag, step)] = float(value)
for r in rows:
    assert seen[("progress/update", r["env_steps"])] == float(r["update"]), r["update"]
    if r["return"] != "nan":
        assert abs(seen[("train/return", r["env_steps"])] - float(r["return"])) <= 1e-4 * (1 + abs(float(r["return"]))), r["update"]
print(f"{run}: {len(seen)} scalars, each once, {updates} updates")
PY
}
tiny=(--set task=a1_beam --set "model.policy_hidden=[16]" --set "model.critic_hidden=[16]" --set env.max_episode_steps=20
      --set runner.checkpoint_every=4 --set runner.eval_every=3 --set runner.eval_episodes=1 --set runner.plot_every=0)
ppo=(--set ppo.num_envs=8 --set ppo.horizon=8 --set ppo.minibatch_size=64)
off=(--set learner=off_policy --set sac.num_envs=8 --set sac.horizon=8 --set sac.learning_starts=64 --set sac.batch_size=16 --set "sac.policy_hidden=[16]" --set "sac.q_hidden=[16]")
for case in ppo off_policy; do
  extra=("${ppo[@]}")
  [ $case = off_policy ] && extra=("${off[@]}")
  "${train[@]}" --updates 400 --run-dir $case "${tiny[@]}" "${extra[@]}" > $case.log 2>&1 &
  pid=$!
  for _ in $(seq 1 600); do [ "$(wc -l < $case/metrics.csv 2> /dev/null || echo 0)" -ge 11 ] && break; sleep 0.05; done
  kill -9 $pid 2> /dev/null || fail "$case: the run ended before it could be killed"
  wait $pid 2> /dev/null || true
  rows=$(($(wc -l < $case/metrics.csv) - 1))
  [ "$rows" -ge 10 ] || fail "$case: killed at $rows updates"
  "${train[@]}" --resume $case --updates 16 > $case.resumed.log 2>&1 || fail "$case: the resume failed"
  check $case 16
  if [ $case = off_policy ]; then
    grep -q " scalar off_policy/q_loss " $case/events.txt || fail "off_policy.csv's rows are not in the events"
  fi
  echo "$case: killed after update $rows, resumed from its checkpoint to 16"
done
echo "PASS: killed and resumed runs' events hold every update's scalars once, in order, as metrics.csv has them"
