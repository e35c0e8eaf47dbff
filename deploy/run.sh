#!/usr/bin/env bash
# The README's run command: set up, build, and train a task with a method on this machine (one
# learner and K actors over loopback LCM; see deploy/train.sh for the options and defaults).
#   deploy/run.sh [task] [method] [--actors K] [--envs E] [--updates N] [--set key=value ...]
# Before training it proves the task's symmetry spec against the physics (masa_verify).
set -euo pipefail
cd "$(dirname "$0")/.."
task=${1:-humanoid_tightrope}
method=${2:-masa}
shift $(( $# < 2 ? $# : 2 ))
bash deploy/build.sh
./build/tools/masa_verify --task "$task" --top 3
exec bash deploy/train.sh "$task" "$method" "$@"
