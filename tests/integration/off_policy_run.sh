#!/usr/bin/env bash
# Off-policy learning over LCM (issue #34, item 2), started as a user starts it: deploy/train.sh with
# `--set learner=off_policy`, a signed run (its default), a learner and 2 actor processes over real
# multicast (udpm, ttl=0). The actors stream their rollouts, the learner keeps them in its replay
# buffer and takes SAC's gradient steps. Passes when
#  - both actors' data reached the learner and every round's gradient steps are the ones owed
#    (floor(updates_per_step x transitions past learning_starts), minus the steps of the rounds before;
#    a round short of a lost chunk's environments brings fewer transitions and is owed fewer);
#  - it learned: the mean training return of the last 8 rounds is at least twice that of rounds 5-12
#    (the first rounds of the policy, after the uniform warm-up) and above 20 (uniformly random
#    actions earn 6-13 here);
#  - the run's policy.bin is read by masa_eval as an ordinary policy file.
#   MASA_BUILD_DIR=build bash tests/integration/off_policy_run.sh [PORT]
# Prints PASS and exits 0, or FAIL with the logs' tails and exits 1. About 60-120 s.
set -euo pipefail
cd "$(dirname "$0")/../.."
source tests/integration/lib.sh

port=${1:-7731}
begin_local_run off_policy "$port"
rounds=40 envs=8 horizon=32 starts=1024 ups=0.5
log "deploy/train.sh a1_beam masa, learner off_policy, 2 actors x $envs envs, $rounds rounds, on $url (work dir $work)"
OMP_NUM_THREADS=1 MASA_BUILD_DIR=$build MASA_LCM_URL=$url bash deploy/train.sh a1_beam masa --actors 2 --envs $envs \
  --updates $rounds --run-dir "$run" --set learner=off_policy --set sac.horizon=$horizon \
  --set sac.learning_starts=$starts --set sac.updates_per_step=$ups --set sac.batch_size=128 \
  --set "sac.policy_hidden=[64,64]" --set "sac.q_hidden=[64,64]" --set runner.eval_every=0 --set runner.plot_every=0 \
  > "$work/train.log" 2>&1 &
train_pid=$!
started_pids+=("$train_pid")
wait "$train_pid" || fail "train.sh did not finish cleanly"
[ "$(updates_in "$run")" -eq "$rounds" ] || fail "$(updates_in "$run") rounds in metrics.csv, not $rounds"
for a in 0 1; do grep -q "actor $a joined" "$work/train.log" "$run"/*.log 2> /dev/null || fail "actor $a never joined"; done

# Each round's gradient steps (off_policy.csv) are the ones its data owed, and the policy lag stays
# within sac.max_policy_lag (0, the default: every round's data acted with the newest parameters).
awk -F, -v starts=$starts -v ups=$ups '
  NR == 1 { for (c = 1; c <= NF; c++) col[$c] = c; next }
  { n = NR - 1; got = $col["env_steps"]; owed = got >= starts ? int(ups * (got - starts + 1) + 1e-9) : 0
    if ($col["gradient_steps"] != owed - before) { printf "FAIL: round %d took %s gradient steps, owed %d\n", n, $col["gradient_steps"], owed - before; exit }
    if ($col["policy_lag_max"] != 0) { printf "FAIL: round %d has policy lag %s\n", n, $col["policy_lag_max"]; exit }
    before = owed }' "$run/off_policy.csv" > "$work/verdict.txt"
[ "$(wc -l < "$run/off_policy.csv")" -eq $((rounds + 1)) ] || fail "off_policy.csv has $(wc -l < "$run/off_policy.csv") lines"
awk -F, 'NR == 1 { for (c = 1; c <= NF; c++) col[$c] = c; next }
  # A round in which no episode ended has return nan: the last 8 rounds that have one (a policy
  # that stands to the time limit ends none for many rounds; the average was nan and failed).
  $col["return"] != "nan" { r[++k] = $col["return"]; at[k] = NR - 1 }
  END { for (i = 1; i <= k; i++) if (at[i] >= 5 && at[i] <= 12) { early += r[i]; ne++ }
        early /= ne; for (i = k - 7; i <= k; i++) late += r[i] / 8
        printf "training return: rounds 5-12 %.1f, last 8 %.1f\n", early, late
        if (!(late >= 2 * early && late > 20)) print "FAIL: it did not learn" }' "$run/metrics.csv" | tee -a "$work/verdict.txt"
grep -q FAIL "$work/verdict.txt" && fail "$(cat "$work/verdict.txt")"
# The learning curve is drawn (its panels are the off-policy ones: gnuplot stopped on PPO's KL panel).
if command -v gnuplot > /dev/null; then
  [ -s "$run/learning_curve.png" ] || fail "no learning_curve.png: $(cat "$run/learning_curve.log" 2> /dev/null | head -5)"
  ! grep -q "undefined" "$run/learning_curve.log" 2> /dev/null || fail "gnuplot: $(head -5 "$run/learning_curve.log")"
fi
"$build/tools/masa_eval" "$run" --episodes 2 > "$work/eval.log" 2>&1 || fail "masa_eval refused the run's policy.bin: $(tail -n 3 "$work/eval.log")"
echo "PASS: an off-policy run of 2 actors over LCM took every owed gradient step and learned ($(grep "^training return" "$work/verdict.txt" | sed 's/training return: //')); masa_eval read its policy"
