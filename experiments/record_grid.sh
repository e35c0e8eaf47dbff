#!/usr/bin/env bash
# Copies a grid (experiments/grid.sh) into a results folder for the record, the way every folder
# under experiments/results/ is kept: the figures and the verdict redrawn from the metrics being
# recorded, every run's config.yaml, metrics.csv and log, the grid's definition and status, and
# RECORD.txt (when, from which commit, on what machine, where each run was resumed); no
# checkpoints, policies or per-run PNGs, which the repository does not need (--policies keeps them).
# --checkpoints keeps the checkpoints of the runs not yet finished (with their environments,
# actor_state.bin, kept xz-compressed as actor_state.bin.xz: 4.2 MB -> 1.9 MB for the Ant recipe),
# so that restore_grid.sh can bring the grid back on another machine (or in a later session, whose
# machine is new) and go on. --all-checkpoints keeps the finished runs' too, for a grid to be
# extended (grid.sh --extend) elsewhere: 3.3 MB a run for the Ant recipe.
#
#   experiments/record_grid.sh --out runs/grid_ant --to experiments/results/ant_acrobatic_grid_2026-12-05
#
# --force replaces an existing --to folder, but for its README.md (what a person wrote about the
# record is kept; the rest is the grid's, redrawn). Refused while a grid runs in --out (its
# metrics would move under the copy). MASA_BUILD_DIR chooses the build whose masa_compare redraws (default build).
set -euo pipefail

usage() { sed -n '2,17p' "$0" | sed 's/^# \{0,1\}//'; exit 0; }
out="" to="" force=0 policies=0 checkpoints=0
while [ $# -gt 0 ]; do
  case "$1" in
    --out) out=${2:?--out needs a directory}; shift 2 ;;
    --to) to=${2:?--to needs a directory}; shift 2 ;;
    --force) force=1; shift ;;
    --policies) policies=1; shift ;;
    --checkpoints) checkpoints=1; shift ;;
    --all-checkpoints) checkpoints=2; shift ;;
    -h|--help) usage ;;
    *) echo "record_grid.sh: unknown option '$1' (see --help)" >&2; exit 2 ;;
  esac
done
[ -n "$out" ] && [ -n "$to" ] || { echo "record_grid.sh: give --out GRID_DIR and --to RESULTS_DIR" >&2; exit 2; }
[ -f "$out/grid.txt" ] || { echo "record_grid.sh: $out is not a grid (no grid.txt)" >&2; exit 2; }
here=$(cd "$(dirname "$0")" && pwd)
out=$(cd "$out" && pwd)
case "$out/" in "$(realpath -m "$to")"/*) echo "record_grid.sh: --to $to would hold or replace the grid itself" >&2; exit 2 ;; esac

# Not while a grid runs there: its metrics would move under the copy. grid.sh --replot takes the
# same lock, so a grid started after this check makes the redraw fail rather than the copy mix.
( flock -n 9 ) 9> "$out/.grid.lock" || { echo "record_grid.sh: a grid is running in $out; record it once it has stopped" >&2; exit 3; }
[ ! -e "$to" ] || [ "$force" = 1 ] || { echo "record_grid.sh: $to exists (--force replaces it)" >&2; exit 2; }
# The figures and the verdict of exactly these metrics.
"$here/grid.sh" --replot --out "$out" > /dev/null || { echo "record_grid.sh: redrawing the comparison failed" >&2; exit 1; }
kept_readme=""
if [ -e "$to" ]; then
  if [ -f "$to/README.md" ]; then
    kept_readme=$(mktemp)
    cp "$to/README.md" "$kept_readme"
  fi
  rm -rf "$to"
fi

mkdir -p "$to"
if [ -n "$kept_readme" ]; then
  cp "$kept_readme" "$to/README.md"
  rm -f "$kept_readme"
  echo "record_grid.sh: kept $to/README.md (written by hand: bring its figures up to date)"
fi
excludes=(--exclude=learning_curve.png --exclude=learning_curve.log
          --exclude=.grid.lock --exclude=.queue --exclude=.queue.lock --exclude=.slots)
[ "$policies" = 1 ] || excludes+=(--exclude=policy.bin)
# off_policy_state.bin: an off-policy run's trainer and replay (about 110 MB for the A1 recipe), a
# checkpoint like the others.
[ "$checkpoints" -ge 1 ] || excludes+=(--exclude=checkpoint.bin --exclude=actor_state.bin --exclude=off_policy_state.bin)
excludes+=(--exclude=actor_state.bin.tmp)
[ -z "$kept_readme" ] || excludes+=(--exclude=./README.md)
"$here/grid.sh" --status --out "$out" > "$to/status.txt"
tar -C "$out" "${excludes[@]}" -cf - . | tar -C "$to" -xf -
# A finished run's checkpoint only serves grid.sh --extend: kept when asked (--all-checkpoints).
[ "$checkpoints" = 2 ] || find "$to" -mindepth 3 -maxdepth 3 -name done -execdir rm -f checkpoint.bin actor_state.bin off_policy_state.bin \;
# The environments (simulator states, doubles) halve under xz; restore_grid.sh unpacks them.
if [ "$checkpoints" -ge 1 ]; then
  find "$to" -mindepth 3 -maxdepth 3 -name actor_state.bin -exec xz -6 -T1 {} + || \
    { echo "record_grid.sh: compressing the environments (xz) failed" >&2; exit 1; }
fi

repo=$(cd "$here/.." && pwd)
commit=$(git -C "$repo" rev-parse HEAD 2> /dev/null || echo unknown)
# (the folder being written does not count: replacing a record is not a change of the code)
to_abs=$(realpath -m "$to") exclude=()
case "$to_abs/" in "$repo"/*) exclude=(":(exclude)$to_abs") ;; esac
dirty=$(git -C "$repo" status --porcelain --untracked-files=no -- . "${exclude[@]}" 2> /dev/null | head -1 || true)
{
  echo "recorded: $(date -u +%Y-%m-%dT%H:%M:%SZ) from $out"
  echo "checkout: $commit${dirty:+ (with uncommitted changes)}"
  echo "machine: $("$here/machine.sh")"
  echo "build: ${MASA_BUILD_DIR:-build} (each run's log starts with the exact command it ran)"
  echo "grid: $(grep -v '^#' "$out/grid.txt" | tr '\n' ' ')"
  grep '^#' "$out/grid.txt" || true
  echo "status: $(tail -n 1 "$to/status.txt")"
  if [ "$checkpoints" -ge 1 ]; then
    echo "checkpoints: $(find "$to" -name checkpoint.bin | wc -l) $([ "$checkpoints" = 2 ] || echo "unfinished ")runs keep theirs" \
         "(experiments/restore_grid.sh --from $to --out DIR brings the grid back to go on)"
  fi
  # Where each run went on, from its log. masa_train says it ("resumed at update K"), and whether
  # its environments went on as they were (actor_state.bin: "exact") or from a reset, which shows
  # in the curves; before it said so, the update where the previous process stopped stands in ("?"
  # after a hard stop, which left no such line).
  echo "resumes (update at which a run went on from its checkpoint; environments reset there unless marked exact):"
  for log in "$out"/*/*_s*.log; do
    [ -f "$log" ] || continue
    points=$(awk 'function flush() { if (pending) printf "%s ", guess == "" ? "?" : guess; pending = 0 }
                  /^# .* on .*: / { flush() }
                  /^# .* --resume / { pending = 1; guess = last; last = "" }
                  /^masa_train: resumed at update [0-9]+/ { if (pending) printf "%s%s ", $5, (/go on as they were/ ? "(exact)" : ""); pending = 0 }
                  /^masa_train: [0-9]+ updates,/ { last = $2 }
                  END { flush() }' "$log")
    run=${log#"$out"/}
    [ -z "$points" ] || echo "  ${run%.log}: $points"
  done
} > "$to/RECORD.txt"
echo "record_grid.sh: $out recorded in $to ($(du -sh "$to" | cut -f1)); see $to/RECORD.txt"
