#!/usr/bin/env bash
# The grid's methods side by side, as a person would rather look at them: for one task and one
# seed, each method's trained policy (policy.bin of a finished run, else its latest checkpoint)
# filmed in the same evaluation episode, its policy mean, as a strip of frames (masa_eval --video),
# one row per method in the grid's order, each frame captioned with the method, the seed, the time
# and the task's progress figures. A row ends where its episode ends (a fall ends it early).
#
#   experiments/film_grid.sh --out runs/grid_ant_recipe --seed 2
#       [--task T] [--episode-seed K] [--frames N] [--width W] [--height H] [--to FILE.png]
#
# Writes DIR/<task>/film_s<seed>.png (or --to), and prints each method's episode: return, length
# and the task's progress figures. --task defaults to the grid's only task; runs not begun are
# named and left out. Needs xvfb-run (a display) and ffmpeg. MASA_BUILD_DIR chooses the build.
set -euo pipefail
caller=$(pwd)
cd "$(dirname "$0")/.."
abs() { case "$1" in /*) echo "$1" ;; *) echo "$caller/$1" ;; esac; }
usage() { sed -n '2,13p' "$0" | sed 's/^# \{0,1\}//'; exit 0; }
out="" task="" seed="" episode_seed=0 frames=8 width=480 height=300 to=""
while [ $# -gt 0 ]; do
  case "$1" in
    --out) out=$(abs "${2:?--out needs a grid directory}"); shift 2 ;;
    --task) task=${2:?--task needs a task}; shift 2 ;;
    --seed) seed=${2:?--seed needs a seed}; shift 2 ;;
    --episode-seed) episode_seed=${2:?--episode-seed needs a number}; shift 2 ;;
    --frames) frames=${2:?--frames needs a number}; shift 2 ;;
    --width) width=${2:?--width needs pixels}; shift 2 ;;
    --height) height=${2:?--height needs pixels}; shift 2 ;;
    --to) to=$(abs "${2:?--to needs a .png path}"); shift 2 ;;
    -h|--help) usage ;;
    *) echo "film_grid.sh: unknown option '$1' (see --help)" >&2; exit 2 ;;
  esac
done
[ -n "$out" ] && [ -n "$seed" ] || { echo "film_grid.sh: give --out GRID_DIR and --seed S" >&2; exit 2; }
[ -f "$out/grid.txt" ] || { echo "film_grid.sh: $out is not a grid (no grid.txt)" >&2; exit 2; }
for n in "$seed" "$episode_seed" "$frames" "$width" "$height"; do
  [[ "$n" =~ ^[0-9]+$ ]] || { echo "film_grid.sh: '$n' is not a whole number" >&2; exit 2; }
done
build=${MASA_BUILD_DIR:-build}
eval_bin=$build/tools/masa_eval
[ -x "$eval_bin" ] || { echo "film_grid.sh: $eval_bin is missing: run scripts/build.sh first" >&2; exit 2; }
for tool in xvfb-run ffmpeg; do
  command -v "$tool" > /dev/null || { echo "film_grid.sh: $tool is missing (scripts/install_deps.sh installs it)" >&2; exit 2; }
done
tasks=$(sed -n 's/^tasks=//p' "$out/grid.txt") methods=$(sed -n 's/^methods=//p' "$out/grid.txt")
if [ -z "$task" ]; then
  [ "$(wc -w <<< "$tasks")" = 1 ] || { echo "film_grid.sh: the grid has tasks $tasks: choose one with --task" >&2; exit 2; }
  task=$tasks
fi
grep -qw -- "$task" <<< "$tasks" || { echo "film_grid.sh: the grid has no task '$task' (it has: $tasks)" >&2; exit 2; }
[ -n "$to" ] || to=$out/$task/film_s$seed.png

work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
rows=()
for m in $methods; do
  run=$out/$task/${m}_s$seed
  target=$run/policy.bin
  [ -f "$target" ] || target=$run/checkpoint.bin
  if [ ! -f "$target" ]; then
    echo "film_grid.sh: $m seed $seed has no policy or checkpoint yet: left out"
    continue
  fi
  updates=$(tail -n 1 "$run/metrics.csv" 2> /dev/null | cut -d, -f1)
  label="$m seed $seed (${updates:-?} updates)"
  xvfb-run -a "$eval_bin" "$target" --episodes 1 --seed "$episode_seed" --per-episode --video "$work/$m.png" \
    --label "$label" --strip-frames "$frames" --width "$width" --height "$height" > "$work/$m.log" 2>&1 || {
    echo "film_grid.sh: filming $m failed:" >&2
    tail -n 5 "$work/$m.log" >&2
    exit 1
  }
  echo "$label: $(grep -m1 '^episode 0' "$work/$m.log" | sed 's/^episode 0 ([^)]*): //')"
  rows+=("$work/$m.png")
done
[ ${#rows[@]} -gt 0 ] || { echo "film_grid.sh: no method of seed $seed has a policy or checkpoint to film" >&2; exit 1; }
# Every row as wide as a full strip (an episode of fewer steps than frames gives fewer), then stacked.
inputs=() filter="" stack=""
for i in "${!rows[@]}"; do
  inputs+=(-i "${rows[$i]}")
  filter+="[$i:v]pad=$((frames * width)):$height[r$i];"
  stack+="[r$i]"
done
mkdir -p "$(dirname "$to")"
if [ ${#rows[@]} = 1 ]; then
  filter+="[r0]null"
else
  filter+="${stack}vstack=inputs=${#rows[@]}"
fi
ffmpeg -loglevel error -y "${inputs[@]}" -filter_complex "$filter" -frames:v 1 "$to"
echo "film_grid.sh: wrote $to (${#rows[@]} methods, episode seed $episode_seed)"
