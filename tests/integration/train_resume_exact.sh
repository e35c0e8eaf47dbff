#!/usr/bin/env bash
# masa_train resumed from its checkpoint is the run left alone: its metrics, update by update, are
# bit for bit those of the same run never stopped (clocks aside), whether it stopped at its --updates
# or was killed (SIGTERM) in the middle of a rollout; the environments go on from actor_state.bin.
# Without that file the environments restart from a reset and the log says why.
#   tests/integration/train_resume_exact.sh BUILD_DIR WORK_DIR
source "$(dirname "$0")/masa_train_case.sh"
tiny=(--set task=a1_beam --set model.policy_hidden=[16] --set model.critic_hidden=[16] --set ppo.num_envs=8
      --set ppo.horizon=8 --set ppo.minibatch_size=64 --set env.max_episode_steps=40 --set runner.checkpoint_every=4
      --set runner.eval_every=5 --set runner.eval_episodes=1 --set runner.plot_every=0)

"${train[@]}" --updates 40 --run-dir whole "${tiny[@]}" > whole.log 2>&1 || fail "the whole run failed"

# 1. Stopped at its --updates (a boundary), resumed to 40.
"${train[@]}" --updates 13 --run-dir parts "${tiny[@]}" > parts1.log 2>&1 || fail "the first part failed"
[ -s parts/actor_state.bin ] || fail "no actor_state.bin beside the checkpoint"
"${train[@]}" --updates 40 --resume parts > parts2.log 2>&1 || fail "the resume failed"
grep -q "^masa_train: resumed at update 13 (.*); the environments go on as they were (actor_state.bin)" parts2.log || \
  fail "the resume did not say it went on exactly: $(grep resumed parts2.log)"
cmp -s <(strip whole/metrics.csv) <(strip parts/metrics.csv) || fail "the resumed run's metrics differ from the whole run's"

# 2. Killed in the middle of a rollout (SIGTERM): the checkpoint pairs with the last boundary.
"${train[@]}" --updates 40 --run-dir killed "${tiny[@]}" --set ppo.num_envs=64 > killed1.log 2>&1 &
pid=$!
for _ in $(seq 600); do [ -f killed/metrics.csv ] && [ "$(wc -l < killed/metrics.csv)" -ge 8 ] && break; sleep 0.05; done
kill -TERM "$pid"; wait "$pid" || fail "the killed run exited non-zero"
"${train[@]}" --updates 40 --run-dir whole64 "${tiny[@]}" --set ppo.num_envs=64 > whole64.log 2>&1 || fail "the whole 64-env run failed"
stopped=$(sed -n 's/^masa_train: \([0-9]*\) updates, .*/\1/p' killed1.log | tail -1)
[ -n "$stopped" ] && [ "$stopped" -lt 40 ] || fail "the run was not stopped early (at ${stopped:-?})"
"${train[@]}" --updates 40 --resume killed > killed2.log 2>&1 || fail "the resume after the kill failed"
grep -q "^masa_train: resumed at update $stopped (.*); the environments go on as they were" killed2.log || \
  fail "the resume after the kill: $(grep resumed killed2.log)"
cmp -s <(strip whole64/metrics.csv) <(strip killed/metrics.csv) || fail "the killed and resumed run's metrics differ from the whole run's"

# 3. Without actor_state.bin: a reset, and the log says why.
rm parts/actor_state.bin
"${train[@]}" --updates 44 --resume parts > parts3.log 2>&1 || fail "the resume without actor_state.bin failed"
grep -q "^masa_train: resumed at update 40 (.*); the environments start from a reset here (no actor_state.bin)" parts3.log || \
  fail "no reason given: $(grep resumed parts3.log)"
echo "PASS: resumed at 13 and after a kill at $stopped, both bit for bit the runs never stopped; without actor_state.bin a reset, said"
