#!/usr/bin/env bash
# The repository's budget (issue #54, item 6; experiments/README.md, "The tree's budget"): the files
# git tracks, as a clone checks them out, add up to at most MAX_TOTAL_MB, and none is over
# MAX_FILE_MB unless it is named with --allow. Prints the total, the largest files and each breach.
#   bash tests/tools/check_tree_budget.sh REPO MAX_TOTAL_MB MAX_FILE_MB [--allow PATH]...
# Exit 0 within the budget, 1 over it, 2 on bad arguments, 77 where REPO is no git checkout.
set -uo pipefail
[ $# -ge 3 ] || { echo "usage: check_tree_budget.sh REPO MAX_TOTAL_MB MAX_FILE_MB [--allow PATH]..." >&2; exit 2; }
repo=$1 max_total_mb=$2 max_file_mb=$3
shift 3
allowed=()
while [ $# -gt 0 ]; do
  case "$1" in
    --allow) allowed+=("${2:?--allow needs a path}"); shift 2 ;;
    *) echo "check_tree_budget.sh: unknown argument '$1'" >&2; exit 2 ;;
  esac
done
[[ $max_total_mb =~ ^[0-9]+(\.[0-9]+)?$ && $max_file_mb =~ ^[0-9]+(\.[0-9]+)?$ ]] ||
  { echo "check_tree_budget.sh: the budgets are numbers of MB (10^6 bytes)" >&2; exit 2; }
git -C "$repo" rev-parse --git-dir > /dev/null 2>&1 || { echo "SKIP: $repo is not a git checkout"; exit 77; }
list=$(mktemp)
trap 'rm -f "$list"' EXIT
# Tracked files as they are in the work tree (a file deleted but not yet committed counts as gone).
(cd "$repo" && git ls-files -z | xargs -0 stat -c '%s %n' 2> /dev/null) | sort -rn > "$list"
allow_args=$(printf '%s\n' "${allowed[@]+"${allowed[@]}"}")
awk -v total_mb="$max_total_mb" -v file_mb="$max_file_mb" -v allow="$allow_args" '
  BEGIN { n = split(allow, a, "\n"); for (i = 1; i <= n; i++) if (a[i] != "") ok[a[i]] = 1 }
  { size = $1; name = substr($0, index($0, " ") + 1); total += size; count++
    if (count <= 5) top = top sprintf("  %.2f MB %s\n", size / 1e6, name)
    if (size > file_mb * 1e6 && !(name in ok)) { over = over sprintf("FAIL: %s is %.2f MB, over the %s MB a file may hold (list it with --allow, or keep it out of the tree)\n", name, size / 1e6, file_mb); bad++ } }
  END {
    printf "%d tracked files, %.1f MB (budget %s MB, %s MB a file); the largest:\n%s", count, total / 1e6, total_mb, file_mb, top
    printf "%s", over
    if (total > total_mb * 1e6) { printf "FAIL: the tree is %.1f MB, over its budget of %s MB\n", total / 1e6, total_mb; bad++ }
    if (bad) exit 1
    printf "PASS: within the budget\n" }' "$list"
