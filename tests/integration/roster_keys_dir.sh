#!/usr/bin/env bash
# Per-host key directories (issue #55, item 4): `masa_roster make RUN_DIR --keys DIR` writes the
# roster to RUN_DIR and every private key to DIR (a directory on this host's own disk), so a run
# directory on a file system every host mounts holds no private key, the learner's least. Passes
# when RUN_DIR has the roster and no *.key, DIR has learner0.key and actor0.key (mode 0600), a
# second make with the same --keys adopts its roster and adds actor 1, and a make without --keys
# refuses the roster (no key of RUN_DIR/keys backs its lines). Before --keys every private key was
# in RUN_DIR/keys. Prints PASS and exits 0, or FAIL and exits 1. Under a second.
#   MASA_BUILD_DIR=build bash tests/integration/roster_keys_dir.sh
set -euo pipefail
cd "$(dirname "$0")/../.."
build=${MASA_BUILD_DIR:-build}
roster_tool="$build/tools/masa_roster"
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
fail() { echo "FAIL: $*"; exit 1; }

shared="$work/shared/run" local_keys="$work/local/keys"
"$roster_tool" make "$shared" --keys "$local_keys" --actors 1 > /dev/null || fail "make --keys failed"
[ -f "$shared/roster" ] || fail "no roster in the run directory"
found=$(find "$work/shared" -name '*.key')
[ -z "$found" ] || fail "private keys in the shared run directory: $found"
for k in learner0 actor0; do
  [ "$(stat -c %a "$local_keys/$k.key")" = 600 ] || fail "$local_keys/$k.key is missing or not mode 0600"
done
"$roster_tool" make "$shared" --keys "$local_keys" --actors 2 > /dev/null || fail "a second make with the same --keys failed"
grep -q "^actor 1 " "$shared/roster" || fail "actor 1 was not added"
[ -f "$local_keys/actor1.key" ] || fail "actor 1's key is not in the keys directory"
out=$("$roster_tool" make "$shared" --actors 2 2>&1) && fail "make without --keys adopted a roster whose keys are elsewhere: $out"
grep -q "not one masa_roster wrote" <<< "$out" || fail "no clear message: $out"
echo "PASS: the private keys in the host's own directory, none in the shared run directory; the roster adopted only with them"
