#!/usr/bin/env bash
# learner: off_policy resumed from its checkpoint (masa_train, stopped at --updates) goes on as the
# run never stopped: metrics.csv and off_policy.csv, round by round, are the uninterrupted run's
# (clocks aside). The replay buffer, the networks, their optimizers, the fitted normalizer and the
# generator all travel in off_policy_state.bin; the stop falls after the warm-up, so all of them matter.
# With `her` as the third argument the run is TriFinger's with hindsight relabeling: the streams'
# episodes travel in the state too, and every round relabels its share of the samples.
#   tests/integration/off_policy_resume_exact.sh BUILD_DIR WORK_DIR [her]
source "$(dirname "$0")/masa_train_case.sh"
task=(--set task=a1_beam)
[ "${3:-}" = her ] && task=(--set task=trifinger_lift --set sac.her_share=0.8)
tiny=("${task[@]}" --set learner=off_policy --set sac.num_envs=8 --set sac.horizon=16 --set env.max_episode_steps=40
      --set sac.learning_starts=200 --set sac.updates_per_step=0.25 --set sac.batch_size=16 --set "sac.policy_hidden=[16]"
      --set "sac.q_hidden=[16]" --set sac.n_step=2 --set runner.checkpoint_every=3 --set runner.eval_every=4
      --set runner.eval_episodes=1 --set runner.plot_every=0)
"${train[@]}" --updates 12 --run-dir whole "${tiny[@]}" > whole.log 2>&1 || fail "the whole run failed"
"${train[@]}" --updates 5 --run-dir parts "${tiny[@]}" > parts1.log 2>&1 || fail "the first part failed"
[ -s parts/off_policy_state.bin ] || fail "no off_policy_state.bin beside the checkpoint"
cp -r parts at5
"${train[@]}" --updates 12 --resume parts > parts2.log 2>&1 || fail "the resume failed: $(tail -n 2 parts2.log)"
cmp -s <(strip whole/metrics.csv) <(strip parts/metrics.csv) || fail "metrics.csv differs: $(diff <(strip whole/metrics.csv) <(strip parts/metrics.csv) | head -4)"
cmp -s whole/off_policy.csv parts/off_policy.csv || fail "off_policy.csv differs: $(diff whole/off_policy.csv parts/off_policy.csv | head -4)"
steps=$(tail -n 1 whole/off_policy.csv | cut -d, -f6)
[ "$steps" -gt 0 ] || fail "no gradient steps were taken ($steps)"
if [ "${3:-}" = her ]; then
  share=$(awk -F, 'NR == 1 { for (c = 1; c <= NF; c++) if ($c == "relabeled_share") col = c; next } END { print $col }' whole/off_policy.csv)
  awk -v s="$share" 'BEGIN { exit !(s >= 0.5 && s <= 1.0) }' || fail "the last round relabeled a share of $share, not about 0.8"
fi
# A stop inside the checkpoint's writing: the off-policy state goes to off_policy_state.next.bin,
# then checkpoint.bin, then the next state takes the old one's name. Either stop point goes on as
# the run never stopped (before, a stop between the two files left a pair no resume accepted).
cp -r at5 ahead && "${train[@]}" --updates 6 --resume ahead > ahead.log 2>&1 || fail "the run to 6 failed"
cp -r at5 stop_before && cp ahead/off_policy_state.bin stop_before/off_policy_state.next.bin
cp -r ahead stop_after && cp ahead/off_policy_state.bin stop_after/off_policy_state.next.bin && cp at5/off_policy_state.bin stop_after/
for stop in stop_before stop_after; do
  "${train[@]}" --updates 12 --resume $stop > $stop.log 2>&1 || fail "$stop: the resume failed: $(tail -n 2 $stop.log)"
  cmp -s whole/off_policy.csv $stop/off_policy.csv || fail "$stop: off_policy.csv differs: $(diff whole/off_policy.csv $stop/off_policy.csv | head -4)"
  [ ! -e $stop/off_policy_state.next.bin ] || fail "$stop: the next state is still there"
done
grep -q "a stop fell before the checkpoint" stop_before.log || fail "the stale next state went unreported: $(tail -n 2 stop_before.log)"
# The checkpoint says whose it is: another algorithm does not resume it, and masa_eval does not
# evaluate it (it holds no policy: before, it held PPO's untrained networks, which masa_eval ran).
if "${train[@]}" --updates 14 --resume at5 --set learner=ppo --set ppo.minibatch_size=32 > other_algorithm.log 2>&1; then fail "a PPO learner resumed an off-policy checkpoint"; fi
grep -q "is of a run with learner: off_policy; this run's learner is ppo" other_algorithm.log || fail "the refusal does not say why: $(tail -n 2 other_algorithm.log)"
if "$build/tools/masa_eval" at5/checkpoint.bin --episodes 1 > eval_checkpoint.log 2>&1; then fail "masa_eval evaluated an off-policy checkpoint"; fi
grep -q "evaluate the policy.bin beside it" eval_checkpoint.log || fail "masa_eval's refusal does not say what to do: $(tail -n 2 eval_checkpoint.log)"
"$build/tools/masa_eval" at5/policy.bin --episodes 1 > eval_policy.log 2>&1 || fail "masa_eval refused the run's policy.bin"
# The state is sealed: a flipped byte is refused by name, nothing is resumed from it.
cp -r parts damaged && printf '\xff' | dd of=damaged/off_policy_state.bin bs=1 seek=200 conv=notrunc status=none
if "${train[@]}" --updates 14 --resume damaged > damaged.log 2>&1; then fail "a damaged off_policy_state.bin was resumed"; fi
grep -q "off_policy_state.bin" damaged.log || fail "the refusal does not name the file: $(tail -n 2 damaged.log)"
echo "PASS: resumed at 5, bit for bit the run never stopped to 12 ($steps gradient steps); a stop between its two files at either point goes on the same; another algorithm and masa_eval refuse its checkpoint; a damaged state refused by name"
