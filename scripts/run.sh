#!/usr/bin/env bash
# The README's run command: set up, build, prove the task's symmetry spec against the physics
# (masa_verify), train the task with its recipe (configs/recipes/<task>.yaml: one learner and
# 2 actors over loopback LCM, sized for 2 cores), then evaluate the trained policy mean over 20
# episodes and draw an image strip of one episode.
#   scripts/run.sh [task] [method] [--actors K] [--updates N] [--set key=value ...]
# Ctrl-C stops training and leaves a resumable run (deploy/train.sh --resume DIR); the evaluation
# and the strip then show the policy as far as it got. With MASA_BUILD_DIR set, that build is used
# as it is (nothing is installed or built); MASA_RUNS_DIR (default runs) holds the run.
set -euo pipefail
cd "$(dirname "$0")/.."
task=a1_beam method=""
[ $# -gt 0 ] && [[ $1 != --* ]] && { task=$1; shift; }
[ $# -gt 0 ] && [[ $1 != --* ]] && { method=$1; shift; }
[ -n "${MASA_BUILD_DIR:-}" ] || bash scripts/build.sh
build=${MASA_BUILD_DIR:-build}
"$build/tools/masa_verify" --task "$task" --top 3

run_dir="${MASA_RUNS_DIR:-runs}/${task}_${method:-recipe}_$(date +%Y%m%d_%H%M%S)"
train=(bash deploy/train.sh --run-dir "$run_dir")
if [ -f "configs/recipes/$task.yaml" ]; then
  train+=(--recipe "$task")
  [ -z "$method" ] || train+=(--set "method=$method")
else
  train+=("$task" "${method:-masa}")
fi
# Training's own Ctrl-C ends train.sh; the evaluation below still runs on what was learned.
set +e
"${train[@]}" "$@"
set -e
[ -f "$run_dir/policy.bin" ] || { echo "run.sh: no policy in $run_dir (training stopped before its first checkpoint)" >&2; exit 1; }

echo "run.sh: evaluating the policy mean of $run_dir over 20 episodes"
"$build/tools/masa_eval" "$run_dir" --episodes 20 --threads 2 --csv "$run_dir/eval.csv" | tee "$run_dir/eval.txt"
if command -v xvfb-run > /dev/null; then
  xvfb-run -a "$build/tools/masa_eval" "$run_dir" --episodes 1 --video "$run_dir/strip.png" --width 400 --height 300 \
    > /dev/null && echo "run.sh: strip of one episode: $run_dir/strip.png"
fi
echo "run.sh: curves $run_dir/learning_curve.png; watch it: xvfb-run -a build/tools/masa_eval $run_dir --video a.mp4"
