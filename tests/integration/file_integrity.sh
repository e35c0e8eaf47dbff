# Files that prove they are intact, through the tools a user runs (issue #33, item 3): a policy
# file with one bit flipped (in its header, config, weights, end) is refused by masa_eval and
# masa_deploy naming the file and the reason; an unsealed policy from before the seal evaluates
# with a warning to the same numbers as the sealed one; masa_seal makes a key pair and signs, and
# masa_deploy --require-signed runs a policy signed by a trusted key and refuses an unsigned one,
# one signed by another key, an unsealed one, and a missing --trusted-keys.
#   MASA_BUILD_DIR=build bash tests/integration/file_integrity.sh
set -uo pipefail
source "$(dirname "$0")/lib.sh"
eval="$build/tools/masa_eval"
deploy="$build/deploy/masa_deploy"
seal="$build/tools/masa_seal"
[ -x "$eval" ] && [ -x "$deploy" ] && [ -x "$seal" ] || fail "masa_eval, masa_deploy or masa_seal is missing: build first"
work=$(mktemp -d /tmp/masa_file_integrity.XXXXXX)
trap 'rm -rf "$work"' EXIT
policy=tasks/a1_beam/policy/policy.bin
size=$(stat -c %s "$policy")
# No robot on memq://: the policy file is under test, not the robot channels (--insecure: unsigned).
robot=(--config configs/deploy/a1_beam_sim.yaml --url memq:// --duration 0.3 --quiet --set start_guard_s=0.05 --insecure)

flip() {  # flip FILE BYTE: one bit of that byte
  python3 -c "import sys; p, i = sys.argv[1], int(sys.argv[2]); b = bytearray(open(p, 'rb').read()); b[i] ^= 1 << (i % 8); open(p, 'wb').write(b)" "$1" "$2"
}

"$eval" "$policy" --episodes 1 --max-steps 200 > "$work/intact.log" 2>&1 || fail "masa_eval on the shipped policy: $(cat "$work/intact.log")"
grep -q "warning" "$work/intact.log" && fail "the shipped policy is not sealed: $(cat "$work/intact.log")"
for at in 3 30 200 5000 $((size / 2)) $((size - 3)); do
  cp "$policy" "$work/flipped.bin"
  flip "$work/flipped.bin" "$at"
  "$eval" "$work/flipped.bin" --episodes 1 --max-steps 200 > "$work/eval.log" 2>&1 && fail "masa_eval accepted a bit flipped at byte $at"
  grep -q "flipped.bin: " "$work/eval.log" || fail "masa_eval's refusal does not name the file: $(cat "$work/eval.log")"
  "$deploy" "$work/flipped.bin" "${robot[@]}" > "$work/deploy.log" 2>&1
  rc=$?
  [ $rc -eq 2 ] && grep -q "flipped.bin: " "$work/deploy.log" || fail "masa_deploy ran a bit flipped at byte $at (exit $rc): $(cat "$work/deploy.log")"
done
grep -q "flipped.bin: checksum mismatch (file corrupted or truncated)" "$work/deploy.log" || fail "the reason: $(cat "$work/deploy.log")"
echo "refused: a bit flipped at 6 places, by masa_eval and masa_deploy"

# The format before the seal: the seal's payload (after the 52-byte header and the kind).
tail -c +$((52 + 4 + 11 + 1)) "$policy" > "$work/old.bin"
"$eval" "$work/old.bin" --episodes 1 --max-steps 200 > "$work/old.log" 2>&1 || fail "an unsealed policy was refused: $(cat "$work/old.log")"
grep -q "warning: $work/old.bin: written before masa sealed its files" "$work/old.log" || fail "no warning: $(cat "$work/old.log")"
grep -q '^| return' "$work/intact.log" || fail "no evaluation table: $(cat "$work/intact.log")"
[ "$(grep '^|' "$work/old.log")" = "$(grep '^|' "$work/intact.log")" ] ||
  fail "unsealed and sealed evaluate differently: $(grep '^| return' "$work/old.log" "$work/intact.log")"
echo "unsealed: evaluated with a warning, to the sealed file's numbers"
cp "$work/old.bin" "$work/resealed.bin"
"$seal" add "$work/resealed.bin" > "$work/add.log" 2>&1 || fail "masa_seal add: $(cat "$work/add.log")"
cmp -s "$work/resealed.bin" "$policy" || fail "masa_seal add did not give back the shipped file byte for byte"
echo "masa_seal add: the unsealed copy sealed again is the shipped file byte for byte"

"$seal" keygen --private "$work/release.key" --public "$work/release.pub" > "$work/seal.log" 2>&1 || fail "keygen: $(cat "$work/seal.log")"
"$seal" keygen --private "$work/other.key" --public "$work/other.pub" >> "$work/seal.log" 2>&1 || fail "keygen: $(cat "$work/seal.log")"
[ "$(stat -c %a "$work/release.key")" = 600 ] || fail "the private key is not mode 600"
cp "$policy" "$work/signed.bin"
cp "$policy" "$work/by_other.bin"
"$seal" sign "$work/signed.bin" --key "$work/release.key" >> "$work/seal.log" 2>&1 || fail "sign: $(cat "$work/seal.log")"
"$seal" sign "$work/by_other.bin" --key "$work/other.key" >> "$work/seal.log" 2>&1 || fail "sign: $(cat "$work/seal.log")"
"$seal" check "$work/signed.bin" --trusted-keys "$work/release.pub" > "$work/check.log" 2>&1 || fail "check: $(cat "$work/check.log")"
"$deploy" "$work/signed.bin" --require-signed --trusted-keys "$work/release.pub" "${robot[@]}" > "$work/deploy.log" 2>&1 ||
  fail "masa_deploy refused a policy signed by a trusted key: $(cat "$work/deploy.log")"
grep -q "signed.bin: sealed (SHA-256 checked), signed by ed25519:" "$work/deploy.log" || fail "no signer said: $(cat "$work/deploy.log")"
echo "signed by a trusted key: runs"
expect_refused() {  # expect_refused WHAT PATTERN ARGS...: masa_deploy must exit 2 saying PATTERN
  local what=$1 pattern=$2
  shift 2
  "$deploy" "$@" "${robot[@]}" > "$work/deploy.log" 2>&1
  local rc=$?
  [ $rc -eq 2 ] && grep -q "$pattern" "$work/deploy.log" || fail "$what: exit $rc: $(cat "$work/deploy.log")"
  echo "refused under --require-signed: $what"
}
expect_refused "unsigned" "policy.bin: not signed" "$policy" --require-signed --trusted-keys "$work/release.pub"
expect_refused "signed by another key" "which is not a trusted key" "$work/by_other.bin" --require-signed --trusted-keys "$work/release.pub"
expect_refused "unsealed" "old.bin: not signed" "$work/old.bin" --require-signed --trusted-keys "$work/release.pub"
expect_refused "no --trusted-keys" "needs --trusted-keys" "$work/signed.bin" --require-signed
"$seal" check "$work/by_other.bin" --trusted-keys "$work/release.pub" > "$work/check.log" 2>&1 && fail "masa_seal check passed another key's signature"
echo "PASS: damaged policies refused by masa_eval and masa_deploy; --require-signed runs only a trusted signature"
