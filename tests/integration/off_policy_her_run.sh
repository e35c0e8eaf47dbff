#!/usr/bin/env bash
# Hindsight relabeling in the distributed off-policy learner over LCM (issue #50, item 1), started as
# a user starts it: deploy/train.sh trifinger_lift with `--set learner=off_policy --set
# sac.her_share=0.8`, a learner and 2 actor processes over real multicast (udpm, ttl=0). The actors
# stream TriFinger's rollouts (the cube's pose and the goal are in the observations), the learner
# keeps each actor environment's stretches as one episode and relabels its batches. Passes when
#  - every round took the gradient steps its data owed and relabeled about 80% of its samples
#    (relabeled_share in off_policy.csv, within the binomial spread of 0.8);
#  - the run's policy.bin is read by masa_eval, which prints TriFinger's success.
#   MASA_BUILD_DIR=build bash tests/integration/off_policy_her_run.sh [PORT]
set -euo pipefail
cd "$(dirname "$0")/../.."
source tests/integration/lib.sh

port=${1:-7741}
begin_local_run off_policy_her "$port"
rounds=12 envs=8 horizon=32 starts=512 ups=0.25
log "deploy/train.sh trifinger_lift masa, off_policy with hindsight, 2 actors x $envs envs, $rounds rounds, on $url"
OMP_NUM_THREADS=1 MASA_BUILD_DIR=$build MASA_LCM_URL=$url bash deploy/train.sh trifinger_lift masa --actors 2 --envs $envs \
  --updates $rounds --run-dir "$run" --set learner=off_policy --set sac.horizon=$horizon --set sac.her_share=0.8 \
  --set sac.learning_starts=$starts --set sac.updates_per_step=$ups --set sac.batch_size=64 \
  --set "sac.policy_hidden=[32]" --set "sac.q_hidden=[32]" --set runner.eval_every=0 --set runner.plot_every=0 \
  > "$work/train.log" 2>&1 &
train_pid=$!
started_pids+=("$train_pid")
wait "$train_pid" || fail "train.sh did not finish cleanly: $(tail -n 5 "$work/train.log")"
[ "$(updates_in "$run")" -eq "$rounds" ] || fail "$(updates_in "$run") rounds in metrics.csv, not $rounds"
awk -F, -v starts=$starts -v ups=$ups '
  NR == 1 { for (c = 1; c <= NF; c++) col[$c] = c; next }
  { n = NR - 1; got = $col["env_steps"]; owed = got >= starts ? int(ups * (got - starts + 1) + 1e-9) : 0
    if ($col["gradient_steps"] != owed - before) { printf "FAIL: round %d took %s gradient steps, owed %d\n", n, $col["gradient_steps"], owed - before; exit }
    before = owed
    if ($col["gradient_steps"] > 0) { share = $col["relabeled_share"]; samples = $col["gradient_steps"] * 64
      if (share < 0.8 - 5 * sqrt(0.16 / samples) || share > 0.8 + 5 * sqrt(0.16 / samples)) { printf "FAIL: round %d relabeled %s of its samples\n", n, share; exit }
      checked++ } }
  END { if (checked == 0) print "FAIL: no round took gradient steps"; else printf "relabeled: %d rounds at about 0.8\n", checked }' \
  "$run/off_policy.csv" > "$work/verdict.txt"
grep -q FAIL "$work/verdict.txt" && fail "$(cat "$work/verdict.txt")"
"$build/tools/masa_eval" "$run" --episodes 1 --max-steps 50 > "$work/eval.log" 2>&1 || fail "masa_eval refused the run's policy.bin: $(tail -n 3 "$work/eval.log")"
grep -q "success" "$work/eval.log" || fail "masa_eval printed no success rate: $(tail -n 5 "$work/eval.log")"
echo "PASS: a TriFinger off-policy run of 2 actors over LCM relabeled its batches ($(cat "$work/verdict.txt")); masa_eval read its policy"
