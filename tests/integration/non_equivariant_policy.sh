# A MASA policy that is not equivariant is refused by every tool that runs one (issue #54). MASA is
# equivariant by construction for any finite parameters (one network shared by the agents, a tied
# log-std, a normalizer projected onto the symmetry on load: a shifted normalizer or a changed kind in
# the file's spec still loads as an equivariant policy), so what the check stands against is a file
# whose outputs are no symmetry's image: the shipped a1_beam policy with one output bias of its mean
# set to NaN, sealed again so that it loads as an intact file (the check dropped NaN errors and all
# three tools ran it). masa_eval, masa_deploy and masa_export each exit non-zero naming the
# equivariance failure and write nothing; the shipped file itself passes each of them.
#   MASA_BUILD_DIR=build bash tests/integration/non_equivariant_policy.sh
set -uo pipefail
source "$(dirname "$0")/lib.sh"
eval="$build/tools/masa_eval"
deploy="$build/deploy/masa_deploy"
export_bin="$build/tools/masa_export"
seal="$build/tools/masa_seal"
for b in "$eval" "$deploy" "$export_bin" "$seal"; do [ -x "$b" ] || fail "$b is missing: build first"; done
work=$(mktemp -d /tmp/masa_non_equivariant.XXXXXX)
trap 'rm -rf "$work"' EXIT
policy=tasks/a1_beam/policy/policy.bin
# No robot on memq://: the policy is under test (as in file_integrity.sh).
robot=(--config configs/deploy/a1_beam_sim.yaml --url memq:// --duration 0.3 --quiet --set start_guard_s=0.05 --insecure)
reason="the MASA policy is not equivariant under its spec"

# The payload without the seal (its 52-byte header and the kind), the first output bias of the
# policy's mean (policy.layer3.bias) set to NaN, sealed again.
tail -c +$((52 + 4 + 11 + 1)) "$policy" > "$work/payload.bin"
python3 - "$work/payload.bin" policy.layer3.bias <<'PY' || fail "cannot find the parameter in $policy"
import struct, sys
path, wanted = sys.argv[1], sys.argv[2]
b = bytearray(open(path, "rb").read())
at = b.find(b"MASAPAR1")  # the parameters: u32 scalar size, u32 segments, each (u32 name length,
if at < 0 or b.find(b"MASAPAR1", at + 1) >= 0:  # name, i32 rows, i32 cols), then every value
    raise SystemExit("no single parameter block")
at += 8
_, count = struct.unpack_from("<II", b, at)
at += 8
segments = []
for _ in range(count):
    n = struct.unpack_from("<I", b, at)[0]
    name = b[at + 4:at + 4 + n].decode()
    rows, cols = struct.unpack_from("<ii", b, at + 4 + n)
    segments.append((name, rows * cols))
    at += 4 + n + 8
for name, size in segments:
    if name == wanted:
        struct.pack_into("<f", b, at, float("nan"))
        break
    at += 4 * size
else:
    raise SystemExit(f"no segment {wanted}")
open(path, "wb").write(bytes(b))
print(f"{wanted}[0] = NaN")
PY
cp "$work/payload.bin" "$work/broken.bin"
"$seal" add "$work/broken.bin" > "$work/seal.log" 2>&1 || fail "masa_seal add: $(cat "$work/seal.log")"

refused() {  # refused TOOL STATUS LOG: a non-zero STATUS and the reason, naming the file
  [ "$2" -ne 0 ] || fail "$1 ran the non-equivariant policy (exit 0): $(cat "$3")"
  grep -q "broken.bin: $reason" "$3" || fail "$1 exited $2 without naming the equivariance failure: $(cat "$3")"
  echo "refused by $1 (exit $2): $(grep -o "$reason[^)]*)" "$3" | head -1)"
}

"$eval" "$work/broken.bin" --episodes 1 --max-steps 50 > "$work/eval.log" 2>&1
rc=$?
refused masa_eval $rc "$work/eval.log"
grep -q '^| return' "$work/eval.log" && fail "masa_eval printed an evaluation of the refused policy"
"$deploy" "$work/broken.bin" "${robot[@]}" > "$work/deploy.log" 2>&1
rc=$?
refused masa_deploy $rc "$work/deploy.log"
[ $rc -eq 2 ] || fail "masa_deploy's refusal of its input is exit 2, this was $rc"
grep -q "masa_deploy: task" "$work/deploy.log" && fail "masa_deploy started the refused policy: $(cat "$work/deploy.log")"
"$export_bin" "$work/broken.bin" "$work/broken.onnx" > "$work/export.log" 2>&1
rc=$?
refused masa_export $rc "$work/export.log"
[ -e "$work/broken.onnx" ] && fail "masa_export wrote an ONNX file of the refused policy"

# The shipped file, the same tools: accepted, its equivariance checked.
"$eval" "$policy" --episodes 1 --max-steps 50 > "$work/eval_ok.log" 2>&1 || fail "masa_eval on the shipped policy: $(cat "$work/eval_ok.log")"
grep -q "equivariance checked on load" "$work/eval_ok.log" || fail "masa_eval did not check the shipped policy: $(cat "$work/eval_ok.log")"
"$deploy" "$policy" "${robot[@]}" > "$work/deploy_ok.log" 2>&1 || fail "masa_deploy on the shipped policy: $(cat "$work/deploy_ok.log")"
"$export_bin" "$policy" "$work/ok.onnx" > "$work/export_ok.log" 2>&1 && [ -s "$work/ok.onnx" ] ||
  fail "masa_export on the shipped policy: $(cat "$work/export_ok.log")"
echo "accepted: the shipped policy by masa_eval, masa_deploy and masa_export"
echo "PASS: masa_eval, masa_deploy and masa_export each refuse a MASA policy that is not equivariant"
