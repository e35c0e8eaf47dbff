#!/usr/bin/env bash
# Builds masa_train, masa_compare and masa_eval of one commit into a directory of their own: the
# frozen binaries a grid keeps using while the checkout moves on (MASA_BUILD_DIR=BUILD_DIR
# experiments/grid.sh ...; film_grid.sh and ship_policy.sh evaluate with its masa_eval), and the way
# to get them back on a new machine for a grid restored from its record.
#
#   experiments/build_at.sh COMMIT BUILD_DIR
#
# The sources are a git worktree of this checkout at COMMIT, in BUILD_DIR.src. Release, for this
# machine's CPU (-march=native), no tests or benchmarks. Run again, it only rebuilds what changed.
set -euo pipefail

[ $# -eq 2 ] || { sed -n '2,10p' "$0" | sed 's/^# \{0,1\}//'; exit 2; }
commit=$1 dir=$2
repo=$(cd "$(dirname "$0")/.." && pwd)
full=$(git -C "$repo" rev-parse --verify --quiet "$commit^{commit}") || {
  echo "build_at.sh: '$commit' is no commit of $repo" >&2; exit 2; }
mkdir -p "$dir"
dir=$(cd "$dir" && pwd)
src="$dir.src"

if [ -d "$src" ]; then
  have=$(git -C "$src" rev-parse HEAD 2> /dev/null || echo none)
  [ "$have" = "$full" ] || { echo "build_at.sh: $src holds $have, not $full (remove both $src and $dir)" >&2; exit 2; }
else
  git -C "$repo" worktree add --detach --force "$src" "$full" > /dev/null
fi
cmake -S "$src" -B "$dir" -DCMAKE_BUILD_TYPE=Release -DMASA_BUILD_TESTS=OFF -DMASA_BUILD_BENCHMARKS=OFF > "$dir.cmake.log" ||
  { tail -n 20 "$dir.cmake.log" >&2; exit 1; }
targets="masa_train masa_compare"
# masa_eval where the commit has it (a commit older than the tool builds without it).
# (The list is read whole first: grep -q leaving early would fail the pipe under pipefail.)
known=$(cmake --build "$dir" --target help 2> /dev/null || true)
grep -qw masa_eval <<< "$known" && targets="$targets masa_eval"
cmake --build "$dir" -j"$(nproc)" --target $targets > "$dir.build.log" 2>&1 ||
  { tail -n 20 "$dir.build.log" >&2; exit 1; }
echo "build_at.sh: ${targets// /, } of ${full:0:12} in $dir (use MASA_BUILD_DIR=$dir)"
