# The four offline families of one run (masa_dataset families): a tiny run keeping a policy per
# update, then expert, half_expert (half of the expert's own episodes), weak_expert (half weak,
# half expert) and mixed (every stage and the final policy), with their table; and the clear
# error for a run that kept no stages.
#   MASA_BUILD_DIR=build bash tests/integration/dataset_families.sh
set -uo pipefail
source "$(dirname "$0")/lib.sh"
tool="$build/tools/masa_dataset"
train="$build/tools/masa_train"
[ -x "$tool" ] && [ -x "$train" ] || fail "masa_dataset or masa_train is missing: build first"
work=$(mktemp -d /tmp/masa_families.XXXXXX)
trap 'rm -rf "$work"' EXIT
tiny=(--set task=a1_beam --set ppo.num_envs=16 --set ppo.horizon=32 --set ppo.minibatch_size=256
      --set model.policy_hidden=[16] --set model.critic_hidden=[16] --set runner.eval_every=0 --updates 4 --quiet)

"$train" "${tiny[@]}" --set runner.snapshot_every=1 --run-dir "$work/run" > "$work/train.log" 2>&1 || fail "training failed"
[ "$(ls "$work/run/policies" | wc -l)" -eq 4 ] || fail "expected 4 kept stages, got: $(ls "$work/run/policies")"
"$tool" families "$work/run" --episodes 8 --out "$work/data" > "$work/families.log" 2>&1 ||
  fail "families failed: $(cat "$work/families.log")"
for f in expert half_expert weak_expert mixed; do [ -s "$work/data/$f.lcmlog" ] || fail "no $f.lcmlog"; done
info() { "$tool" info "$@" 2>&1; }
info "$work/data/expert.lcmlog" | grep -q "8 episodes" || fail "expert should hold 8 episodes: $(info "$work/data/expert.lcmlog")"
info "$work/data/half_expert.lcmlog" | grep -q "4 episodes" || fail "half_expert should hold 4 episodes"
# Every half_expert episode is one of the expert's: read together, all 4 are refused as duplicates.
info "$work/data/expert.lcmlog" "$work/data/half_expert.lcmlog" | grep -q "refused 4: duplicate" ||
  fail "half_expert holds episodes the expert log does not: $(info "$work/data/expert.lcmlog" "$work/data/half_expert.lcmlog")"
info "$work/data/weak_expert.lcmlog" | grep -q "policy 1 run/policies/policy_u000001.bin: 4 episodes" ||
  fail "weak_expert is not half the weak stage: $(info "$work/data/weak_expert.lcmlog")"
[ "$(info "$work/data/mixed.lcmlog" | grep -c "^  policy ")" -eq 4 ] || fail "mixed should come from stages 1-3 and the final policy (stage 4 is the final policy: not twice)"
[ "$(wc -l < "$work/data/families.csv")" -eq 5 ] || fail "families.csv should have a header and 4 rows"
grep -q "^| mixed | 8 |" "$work/data/families.md" || fail "families.md lacks the mixed row: $(cat "$work/data/families.md")"

# A chosen weak stage is recorded, and families.md names it in the command that rebuilds the table.
"$tool" families "$work/run" --episodes 4 --weak "$work/run/policies/policy_u000002.bin" --out "$work/data3" \
  > "$work/families3.log" 2>&1 || fail "families --weak failed: $(cat "$work/families3.log")"
info "$work/data3/weak_expert.lcmlog" | grep -q "run/policies/policy_u000002.bin: 2 episodes" ||
  fail "weak_expert is not half the chosen stage: $(info "$work/data3/weak_expert.lcmlog")"
grep -q -- "--weak $work/run/policies/policy_u000002.bin" "$work/data3/families.md" ||
  fail "families.md's command leaves out --weak: $(head -3 "$work/data3/families.md")"

# A run without stages is refused with the fix.
"$train" "${tiny[@]}" --set runner.snapshot_every=0 --run-dir "$work/plain" > "$work/train2.log" 2>&1 || fail "training failed"
if "$tool" families "$work/plain" --episodes 4 --out "$work/data2" > "$work/err.log" 2>&1; then fail "families accepted a run with no stages"; fi
grep -q "runner.snapshot_every" "$work/err.log" || fail "the error does not say how to keep stages: $(cat "$work/err.log")"
echo "PASS: expert 8, half_expert 4 of the expert's, weak_expert 4 + 4, mixed from 4 policies (the last stage, identical to the final policy, once); a chosen weak stage is recorded and named; a run without stages is refused"
