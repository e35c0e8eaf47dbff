#!/usr/bin/env bash
# The learner's own evaluation does not make the actors' rollouts too old (issue #53, item 2).
# deploy/train.sh trains trifinger_lift (episodes of a fixed 750 steps, so each evaluation of 8
# episodes outlasts an update many times) with 2 actors x 16 environments, evaluating every 5 updates,
# for 21 updates. Before the fix the learner evaluated before it published the parameters, the
# actors' wait for them ran out, and every evaluation cost about 20 rollout chunks dropped as
# too_old (207 in 41 updates, 8 evaluations). Now: none, but for a few a loaded machine or a lost
# chunk may cost any run; more than 20 from update 3 to 21 fails.
#   tests/integration/eval_keeps_rollouts.sh BUILD_DIR
set -uo pipefail
repo=$(cd "$(dirname "$0")/../.." && pwd)
build=$(cd "${1:?usage: eval_keeps_rollouts.sh BUILD_DIR}" && pwd)
work=$(mktemp -d "${TMPDIR:-/tmp}/masa_eval_keeps.XXXXXX")
trap 'rm -rf "$work"' EXIT
cd "$repo"
MASA_BUILD_DIR=$build MASA_LCM_URL="udpm://239.255.76.67:$((7000 + RANDOM % 150 * 4))?ttl=0" timeout 300 \
  deploy/train.sh trifinger_lift masa --actors 2 --envs 16 --updates 21 --run-dir "$work/run" \
  --set runner.eval_every=5 --set model.policy_hidden=[64] --set model.critic_hidden=[64] --set runner.plot_every=0 \
  > "$work/train.log" 2>&1
evaluations=$(grep -c "eval (policy mean" "$work/train.log")
summary=$(grep "rollout chunks accepted" "$work/train.log")
echo "$evaluations evaluations; $summary"
# Chunks dropped (any reason: metrics.csv's running count) from update 3 on: the first updates'
# drops belong to the start (the actors' wait is not yet fitted to the learner's answers).
csv="$work/run/metrics.csv"
column=$(head -n 1 "$csv" 2> /dev/null | tr ',' '\n' | grep -nx dropped_chunks | cut -d: -f1)
at3=$(awk -F, -v c="${column:-0}" '$1 == 3 { print $c }' "$csv" 2> /dev/null)
last=$(awk -F, -v c="${column:-0}" '$1 == 21 { print $c }' "$csv" 2> /dev/null)
if [ "$evaluations" -lt 4 ] || [ -z "$summary" ] || [ -z "$at3" ] || [ -z "$last" ]; then
  echo "FAIL: the run did not train 21 updates with 4 evaluations"
  tail -n 20 "$work/train.log"
elif [ $((last - at3)) -gt 20 ]; then
  echo "FAIL: $((last - at3)) rollout chunks dropped from update 3 to 21, around $evaluations evaluations (expected at most a few)"
  grep -E "too_old|eval \(policy|^update" "$work/train.log" | cut -c1-170
else
  echo "PASS: $((last - at3)) chunks dropped from update 3 to 21, around $evaluations evaluations"
fi
