#!/usr/bin/env bash
# The README's run command: set up, build, and run masa's main job for a task and method.
#   deploy/run.sh [task] [method] [--set key=value ...]
# Until the distributed learner lands (issue #4) the main job resolves the run configuration,
# checks the task's symmetry spec and the MASA model's equivariance on it, proves the spec against
# the physics, and rolls out a random policy with its rewards term by term.
set -euo pipefail
cd "$(dirname "$0")/.."
task=${1:-humanoid_tightrope}
method=${2:-masa}
shift $(( $# < 2 ? $# : 2 ))
bash deploy/build.sh
./build/tools/masa_config --set task="$task" --set method="$method" "$@"
./build/tools/masa_spec "configs/specs/$task.yaml"
./build/tools/masa_verify --task "$task" "$@"
./build/tools/masa_rollout --task "$task" --episodes 2 "$@"
