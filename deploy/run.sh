#!/usr/bin/env bash
# The README's run command: set up, build, and train a task with a method on this machine (one
# learner and K actors over loopback LCM; see deploy/train.sh for the options and defaults).
#   deploy/run.sh [task] [method] [--actors K] [--envs E] [--updates N] [--set key=value ...]
# Before training it proves the task's symmetry spec against the physics (masa_verify).
set -euo pipefail
cd "$(dirname "$0")/.."
task=a1_beam method=masa
[ $# -gt 0 ] && [[ $1 != --* ]] && { task=$1; shift; }
[ $# -gt 0 ] && [[ $1 != --* ]] && { method=$1; shift; }
bash deploy/build.sh
./build/tools/masa_verify --task "$task" --top 3
exec bash deploy/train.sh "$task" "$method" "$@"
