#!/usr/bin/env bash
# Ships a trained run as a task's policy: tasks/<task>/policy/ gets policy.bin (from the run's
# policy.bin, or its checkpoint), config.yaml, metrics.csv, learning_curve.png, a 20-episode
# evaluation of the policy mean (eval.txt, eval.csv) and a strip of episode 0 (strip.png).
#   experiments/ship_policy.sh RUN_DIR [--episodes N] [--commit C] [--to DIR]
# --to DIR writes there instead of tasks/<task>/policy/ (to look before replacing a shipped one).
# The README names the commit that trained the run: the one its config.yaml names ("# Written by
# masa C"), else --commit C (a run of older binaries), else this checkout's HEAD; and the run's
# log, when there is one beside the run directory (a grid's), for the exact command.
set -euo pipefail
caller=$(pwd)
cd "$(dirname "$0")/.."
abs() { case "$1" in /*) echo "$1" ;; *) echo "$caller/$1" ;; esac; }
usage="usage: ship_policy.sh RUN_DIR [--episodes N] [--commit C] [--to DIR]"
run=$(abs "${1:?$usage}")
shift
episodes=20 commit="" out=""
while [ $# -gt 0 ]; do
  case "$1" in
    --episodes) episodes=${2:?$usage}; shift 2 ;;
    --commit) commit=${2:?$usage}; shift 2 ;;
    --to) out=$(abs "${2:?$usage}"); shift 2 ;;
    *) echo "ship_policy.sh: unknown option '$1' ($usage)" >&2; exit 2 ;;
  esac
done
[ -f "$run/config.yaml" ] || { echo "ship_policy.sh: $run is not a run directory (no config.yaml)" >&2; exit 2; }
written_by=$(sed -n 's/^# Written by masa \([0-9a-f]*\).*/\1/p' "$run/config.yaml" | head -1)
commit=${written_by:-${commit:-$(git rev-parse --short HEAD)}}
build=${MASA_BUILD_DIR:-build}
task=$(sed -n 's/^task: //p' "$run/config.yaml")
[ -n "$out" ] || out=tasks/$task/policy
mkdir -p "$out"
src=$run/policy.bin
[ -f "$src" ] || src=$run/checkpoint.bin
"$build/tools/masa_eval" "$src" --episodes 1 --save-policy "$out/policy.bin" > /dev/null
cp "$run/config.yaml" "$run/metrics.csv" "$out/"
[ -f "$run/learning_curve.png" ] && cp "$run/learning_curve.png" "$out/"
"$build/tools/masa_eval" "$out/policy.bin" --episodes "$episodes" --threads "$(nproc)" --csv "$out/eval.csv" \
  | grep -v '^wrote' > "$out/eval.txt"
xvfb-run -a "$build/tools/masa_eval" "$out/policy.bin" --episodes 1 --video "$out/strip.png" --width 400 --height 300 > /dev/null
# By column name: a run of older binaries has `epoch,version,...` where today's has `update,...`
# (its version is the update count).
column() {
  awk -F, -v want="$1" -v alt="${2:-}" 'NR == 1 { for (i = 1; i <= NF; i++) if ($i == want || $i == alt) c = i; next }
    { v = $c } END { print v }' "$run/metrics.csv"
}
updates=$(column update version) steps=$(column env_steps) wall=$(column wall_time_s)
# policy/README.md: what was shipped, how it was made, and how it does.
{
  echo "# $task: shipped policy"
  echo
  echo "Trained $(date -r "$run/metrics.csv" +%Y-%m-%d) by commit ${commit:0:7} on $(nproc --all) cores ($(grep -m1 'model name' /proc/cpuinfo | cut -d: -f2 | sed 's/^ //')):"
  echo "$updates updates, $steps env steps, $(printf %.0f "$wall") s of training wall time. Run configuration: \`config.yaml\`."
  if [ -f "$run.log" ]; then
    echo "The command (from the run's log): \`$(grep -m1 -o 'masa_train .*' "$run.log" | sed 's/ --run-dir [^ ]*//; s/ *$//')\`."
  fi
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
