#!/usr/bin/env bash
# experiments/paper_figure.sh: a panel per task from a grid's curves, a task without a grid drawn
# as an empty panel that says so, a malformed panel argument or a folder without curves refused
# before anything is drawn.
# usage: paper_figure_check.sh WORK_DIR
set -euo pipefail
repo=$(cd "$(dirname "$0")/../.." && pwd)
work=$1
rm -rf "$work" && mkdir -p "$work/curves"
for m in masa sa sasa ma; do  # masa_compare's curve form: env_steps wall_s median q25 q75 n
  printf '# synthetic\n1000 1 %s 1 3 5\n2000 2 %s 2 4 5\n' "$((RANDOM % 5))" "$((RANDOM % 5 + 5))" > "$work/curves/return_$m.dat"
done
if bash "$repo/experiments/paper_figure.sh" --out "$work/bad.png" "no title separator" 2> "$work/bad.err"; then
  echo "FAIL: a panel without TITLE=DIR was accepted"; exit 1
fi
grep -q "a panel is TITLE=CURVES_DIR" "$work/bad.err" || { echo "FAIL: no reason given: $(cat "$work/bad.err")"; exit 1; }
[ ! -e "$work/bad.png" ] || { echo "FAIL: drew a figure for a refused command"; exit 1; }
if bash "$repo/experiments/paper_figure.sh" --out "$work/typo.png" "Task=$work/curvs" 2> "$work/typo.err"; then
  echo "FAIL: a directory without curves was drawn as a task not measured"; exit 1
fi
grep -q "has no return_masa.dat" "$work/typo.err" || { echo "FAIL: no reason given: $(cat "$work/typo.err")"; exit 1; }
bash "$repo/experiments/paper_figure.sh" --out "$work/fig.png" "Task one=$work/curves" "Task two=-" > /dev/null
[ -s "$work/fig.png" ] || { echo "FAIL: no image"; exit 1; }
[ "$(head -c 4 "$work/fig.png" | tail -c 3)" = PNG ] || { echo "FAIL: not a PNG"; exit 1; }
for m in masa sa sasa ma; do grep -q "$work/curves/return_$m.dat" "$work/fig.gp" || { echo "FAIL: $m not plotted"; exit 1; }; done
grep -q "set title 'Task two'" "$work/fig.gp" && grep -q "not measured yet" "$work/fig.gp" ||
  { echo "FAIL: the task without a grid has no panel saying so"; exit 1; }
echo "OK: two panels, four methods, the missing task said"
