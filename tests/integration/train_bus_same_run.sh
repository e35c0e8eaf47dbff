#!/usr/bin/env bash
# masa_train over its in-process bus (LocalBus: chunks, parameters and stats handed over as typed
# messages, never encoded) is the run it made over LCM's memq:// provider (every message encoded,
# guarded, decoded): the same metrics update by update (clocks aside) and the same policy
# parameters, for PPO and for learner: off_policy (issue #32, item 5).
#   tests/integration/train_bus_same_run.sh BUILD_DIR WORK_DIR
source "$(dirname "$0")/masa_train_case.sh"
tiny=(--set task=a1_beam --set model.policy_hidden=[16] --set model.critic_hidden=[16] --set env.max_episode_steps=40
      --set runner.eval_every=3 --set runner.eval_episodes=1 --set runner.plot_every=0)
ppo=(--set ppo.num_envs=8 --set ppo.horizon=8 --set ppo.minibatch_size=64)
off=(--set learner=off_policy --set sac.num_envs=8 --set sac.horizon=8 --set sac.learning_starts=96 --set sac.batch_size=16 --set sac.policy_hidden=[16]
     --set sac.q_hidden=[16] --set sac.updates_per_step=0.5)
# The policy file's parameters: what follows its text header (the seal and the build's name differ).
params() { python3 -c 'import sys; b = open(sys.argv[1], "rb").read(); print(b[b.index(b"# Written by masa"):].split(b"\n", 1)[1].hex())' "$1"; }

for algo in ppo off; do
  extra=("${ppo[@]}"); [ "$algo" = off ] && extra=("${off[@]}")
  for bus in local memq; do
    "${train[@]}" --bus "$bus" --updates 8 --run-dir "${algo}_$bus" "${tiny[@]}" "${extra[@]+"${extra[@]}"}" > "${algo}_$bus.log" 2>&1 ||
      fail "$algo over --bus $bus failed"
  done
  [ "$(wc -l < "${algo}_local/metrics.csv")" -eq 9 ] || fail "$algo: not 8 updates in metrics.csv"
  cmp -s <(strip "${algo}_local/metrics.csv") <(strip "${algo}_memq/metrics.csv") ||
    fail "$algo: the metrics over the local bus differ from those over memq://: $(diff <(strip "${algo}_local/metrics.csv") <(strip "${algo}_memq/metrics.csv") | head -4)"
  [ "$(params "${algo}_local/policy.bin")" = "$(params "${algo}_memq/policy.bin")" ] ||
    fail "$algo: the policy parameters over the local bus differ from those over memq://"
done
cmp -s ppo_local/metrics.csv off_local/metrics.csv && fail "the PPO and off-policy runs made the same metrics: the comparison compares nothing"
echo "PASS: masa_train over the local bus made the runs it made over memq:// (PPO and off-policy: 8 updates' metrics and the policy parameters, the same)"
