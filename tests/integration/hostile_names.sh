#!/usr/bin/env bash
# Names a user (or a copied grid) chose reach ffmpeg and gnuplot as data, never as commands
# (docs/inputs.md gap 6): a method or task directory named to break out of gnuplot's quotes is
# skipped by masa_compare with the reason, and an --video path with a quote is one file for ffmpeg.
# And what masa_compare reads from a run is a number or refused (gap 12).
#   tests/integration/hostile_names.sh [BUILD_DIR]
set -uo pipefail
source "$(dirname "$0")/lib.sh"
[ $# -ge 1 ] && build=$(cd "$1" && pwd)
work=$(mktemp -d "${TMPDIR:-/tmp}/masa_hostile_names.XXXXXX")
trap 'rm -rf "$work"' EXIT
cd "$work" || exit 1
failures=0
fail() { echo "FAIL: $*"; failures=$((failures + 1)); }

# A grid with two honest methods and one (and one task) whose name would close gnuplot's quote
# and call system().
curve() {  # curve DIR RETURN0: a three-row metrics.csv
  mkdir -p "$1"
  printf 'update,env_steps,wall_time_s,return\n1,1000,1,%s\n2,2000,2,%s\n3,3000,3,%s\n' "$2" "$(($2 + 5))" "$(($2 + 9))" > "$1/metrics.csv"
  touch "$1/done"
}
evil="x'.system('touch PWNED_METHOD').'"
curve grid/a1_beam/masa_s0 10
curve grid/a1_beam/sa_s0 5
curve "grid/a1_beam/${evil}_s0" 7
curve "grid/t'.system('touch PWNED_TASK').'/masa_s0" 3
"$build/tools/masa_compare" grid > compare.out 2>&1 || fail "masa_compare failed: $(tail -n 5 compare.out)"
for f in PWNED_METHOD PWNED_TASK; do
  found=$(find "$work" -name "$f" | head -n 1)
  [ -z "$found" ] || fail "a directory's name ran a command: $found"
done
grep -q "skipped .*_s0: task and method names are letters" compare.out || fail "the method's skip not said: $(tail -n 5 compare.out)"
grep -q "skipped .*PWNED_TASK.*: task and method names" compare.out || fail "the task's skip not said: $(tail -n 5 compare.out)"
[ -s grid/a1_beam/compare.png ] || fail "the honest methods' figure was not drawn: $(tail -n 5 compare.out)"

# A damaged metrics.csv (docs/inputs.md gap 12): a cell that is not a number mid-file is refused by
# file, line and column (it read as 0); a last row torn by a crash still ends the record quietly.
curve damaged/a1_beam/masa_s0 10
curve damaged/a1_beam/sa_s0 5
sed -i '3s/,15$/,1x5/' damaged/a1_beam/masa_s0/metrics.csv
if "$build/tools/masa_compare" damaged > damaged.out 2>&1; then
  fail "a damaged cell was read: $(grep '| masa |' damaged.out | head -n 2)"
fi
grep -q "masa_s0/metrics.csv:3: column 'return' holds '1x5', not a number" damaged.out ||
  fail "the damaged cell not named: $(tail -n 3 damaged.out)"
sed -i '3s/,1x5$/,15/' damaged/a1_beam/masa_s0/metrics.csv
printf '4,4000,4,2' >> damaged/a1_beam/masa_s0/metrics.csv; printf '4,4000,4,1e' >> damaged/a1_beam/sa_s0/metrics.csv
"$build/tools/masa_compare" damaged > torn.out 2>&1 || fail "a torn last row was refused: $(tail -n 3 torn.out)"

# --video with a quote and shell syntax in its name: ffmpeg writes exactly that file.
video="film's \$(touch PWNED_VIDEO).gif"
if command -v xvfb-run > /dev/null && command -v ffmpeg > /dev/null; then
  xvfb-run -a "$build/tools/masa_eval" "$masa_repo/tasks/a1_beam/policy/policy.bin" --episodes 1 --max-steps 10 \
    --video "$video" --width 64 --height 48 > eval.out 2>&1 || fail "masa_eval --video failed: $(tail -n 5 eval.out)"
  [ -s "$video" ] || fail "no film at the quoted path: $(ls; tail -n 5 eval.out)"
  [ ! -e PWNED_VIDEO ] || fail "the --video path ran a command"
else
  echo "note: no xvfb-run or ffmpeg: the --video case is not run"
fi

[ "$failures" -eq 0 ] && echo "PASS: hostile names stayed names" || exit 1
