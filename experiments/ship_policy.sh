#!/usr/bin/env bash
# Ships a trained run as a task's policy: tasks/<task>/policy/ gets policy.bin (from the run's
# policy.bin, or its checkpoint), config.yaml, metrics.csv, learning_curve.png, a 20-episode
# evaluation of the policy mean (eval.txt, eval.csv) and a strip of episode 0 (strip.png).
#   experiments/ship_policy.sh RUN_DIR [--episodes N]
set -euo pipefail
cd "$(dirname "$0")/.."
run=${1:?usage: ship_policy.sh RUN_DIR [--episodes N]}
episodes=20
[ "${2:-}" = --episodes ] && episodes=$3
build=${MASA_BUILD_DIR:-build}
task=$(sed -n 's/^task: //p' "$run/config.yaml")
out=tasks/$task/policy
mkdir -p "$out"
src=$run/policy.bin
[ -f "$src" ] || src=$run/checkpoint.bin
"$build/tools/masa_eval" "$src" --episodes 1 --save-policy "$out/policy.bin" > /dev/null
cp "$run/config.yaml" "$run/metrics.csv" "$out/"
[ -f "$run/learning_curve.png" ] && cp "$run/learning_curve.png" "$out/"
"$build/tools/masa_eval" "$out/policy.bin" --episodes "$episodes" --threads "$(nproc)" --csv "$out/eval.csv" \
  | grep -v '^wrote' > "$out/eval.txt"
xvfb-run -a "$build/tools/masa_eval" "$out/policy.bin" --episodes 1 --video "$out/strip.png" --width 400 --height 300 > /dev/null
updates=$(tail -n 1 "$run/metrics.csv" | cut -d, -f1) steps=$(tail -n 1 "$run/metrics.csv" | cut -d, -f3)
wall=$(tail -n 1 "$run/metrics.csv" | cut -d, -f4)
# policy/README.md: what was shipped, how it was made, and how it does.
{
  echo "# $task: shipped policy"
  echo
  echo "Trained $(date +%Y-%m-%d) from commit $(git rev-parse --short HEAD) on $(nproc) cores ($(grep -m1 'model name' /proc/cpuinfo | cut -d: -f2 | sed 's/^ //')):"
  echo "$((updates + 1)) updates, $steps env steps, $(printf %.0f "$wall") s of training wall time. Run configuration: \`config.yaml\`."
  echo
  echo '```bash'
  echo "build/tools/masa_eval tasks/$task/policy/policy.bin --episodes $episodes      # the table below"
  echo "xvfb-run -a build/tools/masa_eval tasks/$task/policy/policy.bin --video $task.mp4"
  echo '```'
  echo
  grep '^|' "$out/eval.txt"
  echo
  grep -v '^|' "$out/eval.txt" | grep -v '^equivariance\|^'"$task"' /' || true
  echo
  echo '![strip of evaluation episode 0](strip.png)'
  echo
  echo '![learning curve](learning_curve.png)'
} > "$out/README.md"
echo "shipped $run as $out: $((updates + 1)) updates, $steps env steps, $(du -h "$out/policy.bin" | cut -f1) policy"
cat "$out/eval.txt"
