# masa_offline end to end on a recorded log: BC as SASA-data and IQL as MASA train on a few A1
# episodes, write their run directories, and masa_eval loads the policy files; bad input is
# refused with what is wrong (unknown method, a dataset of another task, a missing log).
#   MASA_BUILD_DIR=build bash tests/integration/offline_tool.sh
set -uo pipefail
source "$(dirname "$0")/lib.sh"
tool="$build/tools/masa_offline"
dataset="$build/tools/masa_dataset"
eval="$build/tools/masa_eval"
[ -x "$tool" ] && [ -x "$dataset" ] && [ -x "$eval" ] || fail "masa_offline, masa_dataset or masa_eval is missing: build first"
work=$(mktemp -d /tmp/masa_offline.XXXXXX)
trap 'rm -rf "$work"' EXIT

"$dataset" record tasks/a1_beam/policy/policy.bin --episodes 3 --max-steps 40 --out "$work/a1.lcmlog" > "$work/record.log" 2>&1 ||
  fail "recording failed: $(cat "$work/record.log")"
tiny=(--dataset "$work/a1.lcmlog" --steps 40 --set model.policy_hidden=[16] --set model.critic_hidden=[16]
      --set offline.q_hidden=[16] --set offline.log_every=10 --set offline.eval_every=20 --set offline.eval_episodes=1
      --set offline.final_eval_episodes=2 --set env.max_episode_steps=40)

for case in "bc sasa-data" "iql masa"; do
  set -- $case
  out="$work/$1_$2"
  "$tool" "${tiny[@]}" --algo "$1" --method "$2" --out "$out" > "$work/$1.log" 2>&1 || fail "$1 $2 failed: $(cat "$work/$1.log")"
  for f in config.yaml metrics.csv policy.bin eval.txt learning_curve.gp learning_curve.png; do
    [ -s "$out/$f" ] || fail "$1 $2: no $f"
  done
  grep -q "ETA" "$work/$1.log" || fail "$1 $2: no progress line: $(cat "$work/$1.log")"
  # 4 rows of losses (10, 20, 30, 40), the evaluation at 20 on its row, the final one last.
  [ "$(wc -l < "$out/metrics.csv")" -eq 6 ] || fail "$1 $2: metrics.csv has $(wc -l < "$out/metrics.csv") lines: $(cat "$out/metrics.csv")"
  evals=$(awk -F, 'NR == 1 { for (i = 1; i <= NF; ++i) if ($i == "eval_return") c = i; next } $c != "nan" { n++ } END { print n }' "$out/metrics.csv")
  [ "$evals" -eq 2 ] || fail "$1 $2: expected 2 evaluations in metrics.csv, got $evals"
  "$eval" "$out" --episodes 2 > "$work/eval_$1.log" 2>&1 || fail "masa_eval cannot evaluate the $1 policy: $(cat "$work/eval_$1.log")"
  grep -q "over 2 episodes" "$work/eval_$1.log" || fail "masa_eval said: $(cat "$work/eval_$1.log")"
done
grep -q "augment: true" "$work/bc_sasa-data/config.yaml" || fail "the SASA-data run's config does not say augment"
grep -q "equivariance checked on load" "$work/eval_iql.log" || fail "masa_eval did not check the MASA IQL policy's symmetry"

# --env-of: the recording policy's env section (the shipped A1 policy's reward weights), --set still on top.
"$tool" "${tiny[@]}" --algo bc --method masa --env-of tasks/a1_beam/policy/policy.bin --set offline.final_eval_episodes=0 \
  --set offline.eval_every=0 \
  --out "$work/env_of" > "$work/env_of.log" 2>&1 || fail "--env-of failed: $(cat "$work/env_of.log")"
# No evaluation at all (as experiments/offline_table.sh trains): the curve is still drawn.
[ -s "$work/env_of/learning_curve.png" ] && ! grep -q "gnuplot failed" "$work/env_of.log" ||
  fail "a run without evaluation has no learning curve: $(grep gnuplot "$work/env_of.log")"
grep -q "action: -0.05" "$work/env_of/config.yaml" && grep -q "max_episode_steps: 40" "$work/env_of/config.yaml" ||
  fail "--env-of did not take the policy's env under --set: $(grep -A3 '^env' "$work/env_of/config.yaml")"

refused() {  # refused <what the error must say> <args...>
  local want=$1; shift
  if "$tool" "$@" > "$work/err.log" 2>&1; then fail "accepted: $*"; fi
  grep -q "$want" "$work/err.log" || fail "the error for '$*' does not say '$want': $(cat "$work/err.log")"
}
refused "unknown method 'ma'" "${tiny[@]}" --method ma
refused "unknown algorithm 'cql'" "${tiny[@]}" --algo cql
refused "recorded in task 'a1_beam'" "${tiny[@]}" --set task=trifinger_lift
refused "no/such.lcmlog" --dataset no/such.lcmlog
echo "PASS: BC (sasa-data) and IQL (masa) trained on a recorded log, masa_eval loads both; --env-of takes the recording env; bad input refused"
