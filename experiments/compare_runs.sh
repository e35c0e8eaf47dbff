#!/usr/bin/env bash
# Compares any runs, not only a grid's methods: variants of one method (an ablation, a swept
# weight), runs of several grids, or single runs, each under a label of yours, cut at a common
# budget, through the same figure and verdict as a grid (masa_compare). Runs of one label are its
# seeds; each run's task and seed come from its config.yaml.
#
#   experiments/compare_runs.sh --out runs/sasa_weight --updates 1000 --reference sasa-w0.1 \
#       sa=runs/grid_ant_recipe/ant_acrobatic/sa_s{0,1} sasa-w1=runs/grid_ant_recipe/ant_acrobatic/sasa_s{0,1} \
#       sasa-w0.1=runs/probe_sasa_w0.1/ant_acrobatic/sasa_s{0,1}
#
# Writes DIR/<task>/<label>_s<seed>/ (the run's config.yaml and its first N updates of
# metrics.csv; `done` when it had N), DIR/sources.txt (which run each is), DIR/grid.txt (the
# labels' order), then masa_compare's compare.png, verdict.md and runs.csv. --updates defaults to
# the fewest any run has; a run with fewer than --updates is kept as unfinished and named.
# --reference (default: the first label) is compared against every other label. Labels: letters,
# digits, '.', '-'. --milestone [TASK:]COLUMN=LEVEL (repeatable) adds when each run first reaches
# LEVEL (COLUMN<=LEVEL: first falls to it), as grid.sh's. Refuses an existing DIR (--force replaces
# it). MASA_BUILD_DIR chooses the build.
set -euo pipefail
caller=$(pwd)
cd "$(dirname "$0")/.."
abs() { case "$1" in /*) echo "$1" ;; *) echo "$caller/$1" ;; esac; }
usage() { awk 'NR > 1 && !/^#/ { exit } NR > 1' "$0" | sed 's/^# \{0,1\}//'; exit 0; }  # the header, whole
die() { echo "compare_runs.sh: $*" >&2; exit 2; }
out="" updates="" reference="" force=0 pairs=() milestones=()
while [ $# -gt 0 ]; do
  case "$1" in
    --out) out=$(abs "${2:?--out needs a directory}"); shift 2 ;;
    --updates) updates=${2:?--updates needs a number}; shift 2 ;;
    --reference) reference=${2:?--reference needs a label}; shift 2 ;;
    --force) force=1; shift ;;
    --milestone) milestones+=(--milestone "${2:?--milestone needs [TASK:]COLUMN=LEVEL}"); shift 2 ;;
    -h|--help) usage ;;
    -*) die "unknown option '$1' (see --help)" ;;
    *=*) pairs+=("$1"); shift ;;
    *) die "'$1' is not LABEL=RUN_DIR (see --help)" ;;
  esac
done
[ -n "$out" ] || die "give --out DIR"
[ ${#pairs[@]} -ge 2 ] || die "give at least two LABEL=RUN_DIR (got ${#pairs[@]})"
[ -z "$updates" ] || [[ "$updates" =~ ^[1-9][0-9]*$ ]] || die "--updates '$updates' is not a positive whole number"
[ ! -e "$out" ] || [ "$force" = 1 ] || die "$out exists (--force replaces it)"

# Read and check every run before writing anything.
labels=() runs=() tasks=() seeds=() rows=()
yaml_top() { sed -n "s/^$1: *\"\{0,1\}\([^\"#]*\)\"\{0,1\} *\(#.*\)\{0,1\}$/\1/p" "$2" | head -1 | sed 's/ *$//'; }
for p in "${pairs[@]}"; do
  label=${p%%=*} run=$(abs "${p#*=}")
  [[ "$label" =~ ^[A-Za-z0-9][A-Za-z0-9.-]*$ ]] || die "label '$label' (of $p): use letters, digits, '.', '-'"
  [ -f "$run/metrics.csv" ] && [ -f "$run/config.yaml" ] || die "$run is not a run directory (no metrics.csv and config.yaml)"
  task=$(yaml_top task "$run/config.yaml") seed=$(yaml_top seed "$run/config.yaml")
  [ -n "$task" ] && [[ "$seed" =~ ^[0-9]+$ ]] || die "$run/config.yaml names no task or seed"
  for i in "${!labels[@]}"; do
    [ "${labels[$i]}/${tasks[$i]}/${seeds[$i]}" != "$label/$task/$seed" ] || \
      die "$label has two runs of $task with seed $seed (${runs[$i]} and $run)"
  done
  n=$(( $(wc -l < "$run/metrics.csv") - 1 ))
  [ "$n" -ge 2 ] || die "$run has fewer than 2 updates in its metrics.csv"
  labels+=("$label") runs+=("$run") tasks+=("$task") seeds+=("$seed") rows+=("$n")
done
order=()
for l in "${labels[@]}"; do [[ " ${order[*]} " == *" $l "* ]] || order+=("$l"); done
[ ${#order[@]} -ge 2 ] || die "every run has the label ${order[0]}: give at least two labels"
reference=${reference:-${order[0]}}
[[ " ${order[*]} " == *" $reference "* ]] || die "--reference $reference is none of the labels (${order[*]})"
if [ -z "$updates" ]; then
  updates=${rows[0]}
  for n in "${rows[@]}"; do [ "$n" -ge "$updates" ] || updates=$n; done
fi

rm -rf "$out"
mkdir -p "$out"
{
  echo "# experiments/compare_runs.sh, $(date -u +%FT%TZ): the first $updates updates of each run"
  echo "methods=${order[*]}"
} > "$out/grid.txt"
echo "label seed task updates_used source" > "$out/sources.txt"
short=()
for i in "${!labels[@]}"; do
  dir="$out/${tasks[$i]}/${labels[$i]}_s${seeds[$i]}"
  mkdir -p "$dir"
  cp "${runs[$i]}/config.yaml" "$dir/"
  # metrics.csv: the header and the updates 1..N (column 1 is the update; a resumed run's rows
  # were cut back to its checkpoint, so each update appears once). Runs made before issue #32
  # count epochs from 0 there (epoch,version,...).
  awk -F, -v n="$updates" 'NR == 1 { old = ($1 == "epoch") } NR == 1 || ($1 ~ /^[0-9]+$/ && (old ? $1 < n : $1 <= n))' \
    "${runs[$i]}/metrics.csv" > "$dir/metrics.csv"
  used=$(( $(wc -l < "$dir/metrics.csv") - 1 ))
  if [ "$used" -ge "$updates" ]; then touch "$dir/done"; else short+=("${labels[$i]}_s${seeds[$i]} (${used} updates)"); fi
  echo "${labels[$i]} ${seeds[$i]} ${tasks[$i]} $used ${runs[$i]}" >> "$out/sources.txt"
done
[ ${#short[@]} -eq 0 ] || echo "compare_runs.sh: fewer than $updates updates, kept as unfinished: ${short[*]}" >&2
build=${MASA_BUILD_DIR:-build}
"$build/tools/masa_compare" "$out" --reference "$reference" "${milestones[@]+"${milestones[@]}"}"
echo "compare_runs.sh: ${#labels[@]} runs of ${#order[@]} labels at $updates updates -> $out (verdict.md, <task>/compare.png; sources.txt)"
