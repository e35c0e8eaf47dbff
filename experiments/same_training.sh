#!/usr/bin/env bash
# Do two builds train the same? Runs a short masa_train of each (one thread, the same recipe, seed
# and overrides) and compares their metrics.csv bit for bit, wall-clock columns aside. Before a
# grid that runs over several sessions goes on with other binaries than it started with, this says
# whether its runs can tell the difference; a difference names the first update and column.
#
#   experiments/same_training.sh BUILD_A BUILD_B [--recipe NAME | --no-recipe] [--updates N] [--seed S] [--set key=value ...]
#
# Defaults: the ant_acrobatic recipe, 12 updates, seed 7, evaluations at half-way and at the end
# (they run the policy mean through the task too). Exit 0: the same; 1: they differ; 2: bad use.
set -euo pipefail

usage() { sed -n '2,10p' "$0" | sed 's/^# \{0,1\}//'; exit "${1:-0}"; }
builds=() recipe=ant_acrobatic updates=12 seed=7 sets=()
while [ $# -gt 0 ]; do
  case "$1" in
    --recipe) recipe=${2:?--recipe needs a name}; shift 2 ;;
    --no-recipe) recipe=""; shift ;;
    --updates) updates=${2:?--updates needs a number}; shift 2 ;;
    --seed) seed=${2:?--seed needs a number}; shift 2 ;;
    --set) sets+=(--set "${2:?--set needs key=value}"); shift 2 ;;
    -h|--help) usage ;;
    -*) echo "same_training.sh: unknown option '$1' (see --help)" >&2; exit 2 ;;
    *) builds+=("$1"); shift ;;
  esac
done
[ ${#builds[@]} -eq 2 ] || { echo "same_training.sh: give two build directories (see --help)" >&2; exit 2; }
[[ "$updates" =~ ^[1-9][0-9]*$ ]] || { echo "same_training.sh: --updates takes a positive number, not '$updates'" >&2; exit 2; }
for k in 0 1; do
  [ -x "${builds[$k]}/tools/masa_train" ] || { echo "same_training.sh: ${builds[$k]}/tools/masa_train is missing" >&2; exit 2; }
  builds[$k]=$(cd "${builds[$k]}" && pwd)
done
cd "$(dirname "$0")/.."   # configs/ and the task models are the checkout's

work=$(mktemp -d "${TMPDIR:-/tmp}/same_training.XXXXXX")
trap 'rm -rf "$work"' EXIT
args=(--quiet --threads 1 --updates "$updates" --set seed="$seed" --set runner.plot_every=0
      --set runner.eval_every=$(( updates / 2 > 0 ? updates / 2 : 1 )))
[ -n "$recipe" ] && args=(--recipe "$recipe" "${args[@]}")
args+=("${sets[@]+"${sets[@]}"}")
pids=()
for k in 0 1; do
  OMP_NUM_THREADS=1 "${builds[$k]}/tools/masa_train" "${args[@]}" --run-dir "$work/run$k" > "$work/run$k.log" 2>&1 &
  pids+=($!)
done
for k in 0 1; do
  wait "${pids[$k]}" || { echo "same_training.sh: ${builds[$k]}/tools/masa_train failed:" >&2; tail -n 5 "$work/run$k.log" >&2; exit 2; }
done

version() { "$1/tools/masa_train" --version 2> /dev/null || echo "of unknown commit"; }
# Every column but the clocks, as the header names them.
awk -F, 'FNR == 1 { file++; if (file == 1) { for (c = 1; c <= NF; c++) name[c] = $c; header = $0 }
                    else if ($0 != header) { print "different columns:\n  " header "\n  " $0; bad = 1; exit }
                    next }
         file == 1 { row[FNR] = $0; next }
         { n = split(row[FNR], a, ","); split($0, b, ",")
           for (c = 1; c <= n; c++) {
             if (name[c] == "wall_time_s" || name[c] == "fps") continue
             if (a[c] != b[c]) { printf "first at update %s, column %s: %s against %s\n", b[1], name[c], a[c], b[c]; bad = 1; exit } } }
         END { if (!bad && FNR - 1 != length(row)) { print "different numbers of updates"; bad = 1 } exit bad }' \
  "$work/run0/metrics.csv" "$work/run1/metrics.csv" > "$work/diff.txt" && same=1 || same=0
what="${recipe:-no recipe}, seed $seed, $updates updates, 1 thread"
if [ "$same" = 1 ]; then
  echo "same_training.sh: the same, bit for bit ($what): masa $(version "${builds[0]}") and masa $(version "${builds[1]}")"
else
  echo "same_training.sh: they differ ($what): $(cat "$work/diff.txt")"
  exit 1
fi
