#!/usr/bin/env bash
# An older signed policy cannot be swapped in (issue #55, item 4). The A1 policy is signed by one
# release key as release 1, as release 2, and without a release; masa_deploy --require-signed
# --min-policy-version 2 must run release 2 and refuse (exit 2, saying why) release 1, the one
# without a release, and release 1 whose version bytes were rewritten to 2 (the signature covers
# them); --min-policy-version without --require-signed is refused. Before, a signature covered no
# version: release 1 ran wherever release 2 did. --release-state keeps the newest release a robot
# ran, so an older one is refused without the operator's pin. Prints PASS and exits 0, or FAIL and exits 1.
#   MASA_BUILD_DIR=build bash tests/integration/policy_release_version.sh
set -euo pipefail
cd "$(dirname "$0")/../.."
build=${MASA_BUILD_DIR:-build}
deploy="$build/deploy/masa_deploy"
seal="$build/tools/masa_seal"
fail() { echo "FAIL: $*"; exit 1; }
work=$(mktemp -d /tmp/masa_policy_release.XXXXXX)
trap 'rm -rf "$work"' EXIT
# No robot on memq://: the policy file is under test, not the robot channels.
robot=(--config configs/deploy/a1_beam_sim.yaml --url memq:// --duration 0.3 --quiet --set start_guard_s=0.05 --insecure)

"$seal" keygen --private "$work/release.key" --public "$work/release.pub" > "$work/seal.log" 2>&1 || fail "keygen: $(cat "$work/seal.log")"
for name in release1 release2 plain forged; do cp tasks/a1_beam/policy/policy.bin "$work/$name.bin"; done
"$seal" sign "$work/release1.bin" --key "$work/release.key" --release-version 1 >> "$work/seal.log" 2>&1 || fail "sign 1: $(cat "$work/seal.log")"
"$seal" sign "$work/release2.bin" --key "$work/release.key" --release-version 2 >> "$work/seal.log" 2>&1 || fail "sign 2: $(cat "$work/seal.log")"
"$seal" sign "$work/plain.bin" --key "$work/release.key" >> "$work/seal.log" 2>&1 || fail "sign: $(cat "$work/seal.log")"
"$seal" sign "$work/forged.bin" --key "$work/release.key" --release-version 1 >> "$work/seal.log" 2>&1 || fail "sign 1: $(cat "$work/seal.log")"
# The release's version is 8 bytes after the signature block's magic and key, 80 bytes from the end
# (version 8, time 8, signature 64): make release 1 claim to be release 2.
python3 -c "import sys; p = sys.argv[1]; b = bytearray(open(p, 'rb').read()); b[-80] = 2; open(p, 'wb').write(b)" "$work/forged.bin"

pin=(--require-signed --trusted-keys "$work/release.pub" --min-policy-version 2)
"$deploy" "$work/release2.bin" "${pin[@]}" "${robot[@]}" > "$work/deploy.log" 2>&1 || fail "release 2 refused: $(cat "$work/deploy.log")"
grep -q "signed by ed25519:[0-9a-f]* as release 2" "$work/deploy.log" || fail "no release said: $(cat "$work/deploy.log")"
echo "release 2: runs"
expect_refused() {  # WHAT FILE PATTERN [OPTIONS...]
  local what=$1 file=$2 pattern=$3 status=0
  shift 3
  "$deploy" "$file" "$@" "${robot[@]}" > "$work/deploy.log" 2>&1 || status=$?
  [ "$status" -eq 2 ] || fail "$what: masa_deploy exited $status, not 2: $(cat "$work/deploy.log")"
  grep -q -- "$pattern" "$work/deploy.log" || fail "$what: not refused for its reason: $(cat "$work/deploy.log")"
  echo "$what: refused ($(grep -o -- "$pattern.*" "$work/deploy.log" | head -1))"
}
expect_refused "release 1" "$work/release1.bin" "release 1, older than the newest accepted" "${pin[@]}"
expect_refused "signed without a release" "$work/plain.bin" "names no release version" "${pin[@]}"
expect_refused "release 1 rewritten as 2" "$work/forged.bin" "signature does not verify" "${pin[@]}"
expect_refused "--min-policy-version alone" "$work/release2.bin" "needs --require-signed" --min-policy-version 2
# --release-state: the robot keeps the newest release it ran, so release 1 is refused after release 2
# ran even when the operator gives no --min-policy-version; a damaged state is refused, not read as 0.
state=(--require-signed --trusted-keys "$work/release.pub" --release-state "$work/robot.release")
"$deploy" "$work/release1.bin" "${state[@]}" "${robot[@]}" > "$work/deploy.log" 2>&1 || fail "release 1 with a new state refused: $(cat "$work/deploy.log")"
[ "$(cat "$work/robot.release")" = 1 ] || fail "the state after release 1 holds '$(cat "$work/robot.release")'"
"$deploy" "$work/release2.bin" "${state[@]}" "${robot[@]}" > "$work/deploy.log" 2>&1 || fail "release 2 after 1 refused: $(cat "$work/deploy.log")"
[ "$(cat "$work/robot.release")" = 2 ] || fail "the state after release 2 holds '$(cat "$work/robot.release")'"
expect_refused "release 1 after release 2 ran" "$work/release1.bin" "release 1, older than the newest accepted" "${state[@]}"
[ "$(cat "$work/robot.release")" = 2 ] || fail "a refused release changed the state"
echo "2x" > "$work/robot.release"
expect_refused "a damaged release state" "$work/release2.bin" "not a release number" "${state[@]}"
expect_refused "--release-state alone" "$work/release2.bin" "needs --require-signed" --release-state "$work/robot.release"
echo "PASS: only a release at or above --min-policy-version signed by a trusted key runs, and none older than the robot's newest (--release-state)"
