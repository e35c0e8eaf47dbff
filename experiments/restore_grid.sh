#!/usr/bin/env bash
# Brings a grid kept under experiments/results/ (record_grid.sh) back into a run directory, so that
# it goes on on this machine: run directories are not in git and do not outlive the machine, the
# record is. Finished runs stay finished; a run whose checkpoint is in the record (record_grid.sh
# --checkpoints) goes on from it; the rest start afresh, their partial metrics and logs dropped.
# grid.txt says what was restored from where, and RECORD.txt of the next record lists it.
#
#   experiments/restore_grid.sh --from experiments/results/a1_beam_grid_recipe_in_progress --out runs/grid_a1_recipe
#   experiments/grid.sh --out runs/grid_a1_recipe                      (then go on)
#
# Refused when --out exists (a grid there has newer metrics than any record).
set -euo pipefail

usage() { sed -n '2,11p' "$0" | sed 's/^# \{0,1\}//'; exit 0; }
from="" out=""
while [ $# -gt 0 ]; do
  case "$1" in
    --from) from=${2:?--from needs a directory}; shift 2 ;;
    --out) out=${2:?--out needs a directory}; shift 2 ;;
    -h|--help) usage ;;
    *) echo "restore_grid.sh: unknown option '$1' (see --help)" >&2; exit 2 ;;
  esac
done
[ -n "$from" ] && [ -n "$out" ] || { echo "restore_grid.sh: give --from RECORD_DIR and --out GRID_DIR" >&2; exit 2; }
[ -f "$from/grid.txt" ] || { echo "restore_grid.sh: $from is not a recorded grid (no grid.txt)" >&2; exit 2; }
[ -e "$out" ] && { echo "restore_grid.sh: $out exists; restore into a new directory (or remove it first)" >&2; exit 2; }

field() { sed -n "s/^$1=//p" "$from/grid.txt"; }
tasks=$(field tasks) methods=$(field methods) seeds=$(field seeds)
[ -n "$tasks" ] && [ -n "$methods" ] && [ -n "$seeds" ] || { echo "restore_grid.sh: $from/grid.txt names no tasks, methods or seeds" >&2; exit 2; }

mkdir -p "$out"
# What describes the record, not the grid, stays behind.
tar -C "$from" --exclude=./RECORD.txt --exclude=./README.md --exclude=./status.txt -cf - . | tar -C "$out" -xf -
# record_grid.sh keeps the environments compressed; xz checks its own integrity while unpacking.
# (-exec +: find fails when xz does; the half-made grid goes, $out did not exist before)
find "$out" -mindepth 3 -maxdepth 3 -name actor_state.bin.xz -exec xz -d {} + || {
  rm -rf "$out"
  echo "restore_grid.sh: unpacking a run's environments (actor_state.bin.xz) failed; nothing restored" >&2; exit 1
}
# Records keep their per-update CSVs compressed (experiments/README.md, "The tree's budget"): the
# runs get them back as the learner wrote them, and their curve scripts read them so again.
find "$out" -name '*.csv.xz' -exec xz -d {} + || {
  rm -rf "$out"
  echo "restore_grid.sh: unpacking a run's metrics (*.csv.xz) failed; nothing restored" >&2; exit 1
}
find "$out" -name '*.gp' -exec sed -i 's/"< xz -dc \([^"]*\.csv\)\.xz"/"\1"/g' {} +

finished=0 going_on=0 afresh=0
for t in $tasks; do for m in $methods; do for s in $seeds; do
  dir="$out/$t/${m}_s$s"
  if [ -f "$dir/done" ]; then finished=$((finished + 1))
  elif [ -f "$dir/checkpoint.bin" ] && [ -f "$dir/config.yaml" ]; then going_on=$((going_on + 1))
  else
    [ -e "$dir" ] || [ -e "$dir.log" ] || continue
    rm -rf "$dir" "$dir.log"; afresh=$((afresh + 1))
  fi
done; done; done

commit=$(git -C "$(dirname "$0")" rev-parse --short HEAD 2> /dev/null || echo unknown)
echo "# restored $(date -u +%FT%TZ) from $from at commit $commit on $("$(dirname "$0")/machine.sh"): $finished finished," \
     "$going_on go on from their checkpoints, $afresh begun but without a checkpoint start afresh" >> "$out/grid.txt"
echo "restore_grid.sh: $out: $finished runs finished, $going_on go on from their checkpoints," \
     "$afresh start afresh; go on with: experiments/grid.sh --out $out"
