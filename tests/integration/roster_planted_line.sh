#!/usr/bin/env bash
# masa_roster make never adopts a roster line it did not write (issue #55, item 4). A run's roster
# is made; then, one at a time, a line is planted in it (the next actor, with a stranger's key), an
# actor's key swapped for a stranger's, and an actor's channels widened to the learner's policy
# channel. Each time `masa_roster make` (as a resumed run calls it, with one more actor) must exit
# with status 2 naming the line and "not one masa_roster wrote", leave the roster as it was (the
# planted line is not rewritten as ours, no key is made for the new actor), and with the roster
# restored, make must work again. Before the fix make loaded whatever lines were there and wrote
# them back with its own. Prints PASS and exits 0, or FAIL and exits 1. Under a second.
#   MASA_BUILD_DIR=build bash tests/integration/roster_planted_line.sh
set -euo pipefail
cd "$(dirname "$0")/../.."
build=${MASA_BUILD_DIR:-build}
roster_tool="$build/tools/masa_roster"
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
fail() { echo "FAIL: $*"; exit 1; }

run="$work/run"
"$roster_tool" make "$run" --actors 2 > /dev/null || fail "make of a fresh run failed"
cp "$run/roster" "$work/roster.ours"
# A stranger's public key, in the roster's hex: the raw 32 bytes end a PEM Ed25519 public key.
"$roster_tool" make "$work/stranger" --actors 0 > /dev/null
stranger=$(awk '$1 == "learner" { print $3 }' "$work/stranger/roster")
[ ${#stranger} -eq 64 ] || fail "no stranger key ($stranger)"
ours0=$(awk '$1 == "actor" && $2 == 0 { print $3 }' "$run/roster")

check_refused() {  # $1: what was planted; the roster as planted is in $run/roster
  cp "$run/roster" "$work/roster.planted"
  local out status=0
  out=$("$roster_tool" make "$run" --actors 3 2>&1) || status=$?
  [ "$status" -eq 2 ] || fail "$1: make exited $status, not 2: $out"
  grep -q "not one masa_roster wrote" <<< "$out" || fail "$1: no clear message: $out"
  cmp -s "$run/roster" "$work/roster.planted" || fail "$1: make rewrote the roster"
  [ ! -e "$run/keys/actor2.key" ] || fail "$1: make went on and made actor 2's key"
  echo "refused ($1): $out"
  cp "$work/roster.ours" "$run/roster"
}

echo "actor 2 $stranger MASA_ROLLOUT,MASA_ACTOR_HEARTBEAT" >> "$run/roster"
check_refused "a planted actor 2 (the next actor)"
sed -i "s/$ours0/$stranger/" "$run/roster"
check_refused "actor 0's key swapped"
sed -i "/^actor 0 /s/MASA_ROLLOUT,MASA_ACTOR_HEARTBEAT/MASA_ROLLOUT,MASA_ACTOR_HEARTBEAT,MASA_POLICY/" "$run/roster"
check_refused "actor 0 given the policy channel"

# Ours again: make adopts its own lines and adds actor 2.
"$roster_tool" make "$run" --actors 3 > /dev/null || fail "make of our own roster failed"
grep -q "^actor 2 " "$run/roster" || fail "actor 2 was not added"
echo "PASS: a planted line, a swapped key and widened channels refused by masa_roster make; its own roster taken"
