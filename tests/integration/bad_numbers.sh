#!/usr/bin/env bash
# Numeric command-line values out of their range are refused by name before anything runs
# (docs/inputs.md gaps 5 and 13: `masa_verify --states 0` printed PASS having checked nothing;
# the others ran with a negative count, a zero-sized video, a negative duration).
#   tests/integration/bad_numbers.sh [BUILD_DIR]
set -uo pipefail
source "$(dirname "$0")/lib.sh"
[ $# -ge 1 ] && build=$1
policy="$masa_repo/tasks/a1_beam/policy/policy.bin"
failures=0
work=$(mktemp -d "${TMPDIR:-/tmp}/masa_bad_numbers.XXXXXX")
trap 'rm -rf "$work"' EXIT
refuse() {  # refuse OPTION PROGRAM ARGS...: the program must exit non-zero and name OPTION
  local option=$1 out status
  shift
  out=$(timeout 30 "$@" 2>&1)
  status=$?
  if [ "$status" -eq 0 ] || ! grep -q -- "$option" <<< "$out"; then
    echo "NOT REFUSED (exit $status): $*"
    echo "$out" | tail -n 3
    failures=$((failures + 1))
  else
    echo "refused: $* -> $(grep -m1 -- "$option" <<< "$out")"
  fi
}
refuse --states "$build/tools/masa_verify" --task a1_beam --states 0
refuse --steps "$build/tools/masa_verify" --task a1_beam --steps -3
refuse --episodes "$build/tools/masa_rollout" --task a1_beam --episodes -1
refuse --width "$build/tools/masa_eval" "$policy" --width 0
refuse --fps "$build/tools/masa_eval" "$policy" --fps -5
refuse --duration "$build/deploy/masa_deploy" "$policy" --duration -1
refuse --duration "$build/deploy/masa_sim_robot" "$policy" --duration 0
refuse --duration "$build/tools/masa_lcm_probe" --duration -2
refuse --count "$build/tools/masa_lcm_probe" --count -1
refuse --max-updates "$build/learner/masa_learner" --max-updates -5 --run-dir "$work/run" --url memq://
for bad in "--actors 0" "--envs -1" "--updates x" "--ranks 0"; do
  # shellcheck disable=SC2086
  MASA_BUILD_DIR=$build refuse "${bad%% *}" bash "$masa_repo/deploy/train.sh" a1_beam masa $bad --run-dir "$work/sh"
done
# A hosts file's host names reach ssh (docs/inputs.md gap 7): one that would be read as an ssh option
# or carries shell syntax is refused by its line before anything starts; so are bad counts.
hosts_case() {  # hosts_case WHAT LINE: train.sh --hosts with a file of LINE must exit 2 naming the line
  printf 'localhost 1 8\n%s\n' "$2" > "$work/hosts"
  MASA_BUILD_DIR=$build refuse "hosts:2" bash "$masa_repo/deploy/train.sh" a1_beam masa --hosts "$work/hosts" \
    --run-dir "$work/hosts_run"
  [ ! -e "$work/hosts_run" ] || { echo "STARTED: $1 made the run dir"; failures=$((failures + 1)); rm -rf "$work/hosts_run"; }
}
hosts_case "an ssh option" "-oProxyCommand=touch\$IFS$work/pwned 1 8"
hosts_case "shell syntax" 'host$(touch) 1 8'
hosts_case "a quote" "it's 1 8"
hosts_case "zero actors" "node1 0 8"
hosts_case "an extra field" "node1 1 8 9"
[ ! -e "$work/pwned" ] || { echo "a host name ran a command"; failures=$((failures + 1)); }
[ "$failures" -eq 0 ] || { echo "FAIL: $failures value(s) not refused"; exit 1; }
echo "PASS"
