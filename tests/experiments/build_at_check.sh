#!/usr/bin/env bash
# experiments/build_at.sh refuses what it cannot build, with the reason, before building anything:
# a name that is no commit, a missing argument, and sources of another commit already in the
# place of the worktree (it would otherwise build the wrong code under the asked commit's name).
# (The build itself takes minutes; experiments/README.md records one.)
#   tests/experiments/build_at_check.sh WORK_DIR
set -euo pipefail
work=$1
src=$(cd "$(dirname "$0")/../.." && pwd)
rm -rf "$work" && mkdir -p "$work" && cd "$work"
fail() { echo "FAIL: $*"; exit 1; }
git -C "$src" rev-parse --verify --quiet HEAD > /dev/null || { echo "not a git checkout: nothing to test"; exit 77; }

rc=0; "$src/experiments/build_at.sh" no_such_commit_anywhere out > nocommit.out 2>&1 || rc=$?
[ "$rc" = 2 ] && grep -q "'no_such_commit_anywhere' is no commit of" nocommit.out || fail "a wrong commit: exit $rc, $(cat nocommit.out)"
[ ! -e out ] || fail "a wrong commit left a build directory"
rc=0; "$src/experiments/build_at.sh" HEAD > noargs.out 2>&1 || rc=$?
[ "$rc" = 2 ] && grep -q "experiments/build_at.sh COMMIT BUILD_DIR" noargs.out || fail "one argument: exit $rc, $(cat noargs.out)"

mkdir other.src && git -C other.src init -q && \
  git -C other.src -c user.name=t -c user.email=t@t commit -q --allow-empty -m other
rc=0; "$src/experiments/build_at.sh" HEAD other > other.out 2>&1 || rc=$?
[ "$rc" = 2 ] && grep -q "other.src holds [0-9a-f]*, not $(git -C "$src" rev-parse HEAD)" other.out || \
  fail "sources of another commit: exit $rc, $(cat other.out)"
[ ! -e other/CMakeCache.txt ] || fail "sources of another commit were configured"
echo "PASS: a wrong commit, a missing argument and another commit's sources are refused with the reason"
