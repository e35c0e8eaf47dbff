#!/usr/bin/env bash
# lcm-spy decodes every field of a signed message: a learner with a run key broadcasts its
# parameters over real multicast, lcm-logger records them, and the Java classes lcm-gen made
# (masa_lcmtypes.jar, what lcm-spy decodes with) read each recorded message the way lcm-spy does.
# Every field must come out (the run id the learner printed, the task, all parameters), and the
# decoder must stop exactly before the run key's 36-byte trailer ("MAC1" + HMAC-SHA256).
#   MASA_BUILD_DIR=build bash tests/integration/lcm_spy_signed.sh [PORT]
# Needs java, javac, lcm-logger and the jar (built by default with a JDK), else SKIP (exit 77).
set -euo pipefail
cd "$(dirname "$0")/../.."
source tests/integration/lib.sh

port=${1:-7677}
jar="$build/lcmtypes/masa_lcmtypes.jar"
for tool in java javac lcm-logger; do
  command -v "$tool" > /dev/null || { echo "SKIP: $tool is not installed"; exit 77; }
done
[ -f "$jar" ] || { echo "SKIP: $jar is missing (a JDK at configure time builds it)"; exit 77; }
begin_local_run spy_signed "$port"

lcm-logger --lcm-url="$url" --channel=MASA_POLICY "$work/policy.lcmlog" > "$work/logger.log" 2>&1 &
logger_pid=$!
started_pids+=("$logger_pid")
start_learner "$run" "$url" "$run_id"
wait_until 60 "a parameter broadcast recorded" eval '[ -s "$work/policy.lcmlog" ]'
sleep 1.5  # and its periodic repeat (runner.republish_every_s: 1 s)
kill -INT "$learner_pid" "$logger_pid"
wait "$learner_pid" "$logger_pid" 2>/dev/null || true
grep -q "messages authenticated with the run key" "$work/learner.log" || fail "the learner did not sign its messages"

javac -nowarn -d "$work" -cp "/usr/share/java/lcm.jar:$jar" tests/tools/DecodeSignedPolicyLog.java
java -cp "/usr/share/java/lcm.jar:$jar:$work" DecodeSignedPolicyLog "$work/policy.lcmlog" > "$work/decoded.txt" ||
  fail "the Java decoder failed: $(tail -3 "$work/decoded.txt")"
cat "$work/decoded.txt"
n=$(sed -n 's/^decoded \([0-9]*\) MASA_POLICY messages$/\1/p' "$work/decoded.txt")
[ "${n:-0}" -ge 1 ] || fail "no MASA_POLICY message recorded and decoded"
good=$(grep -cE "^MASA_POLICY run_id $run_id version 0 task a1_beam method masa num_params ([1-9][0-9]*) params \1 obs_dim ([1-9][0-9]*) obs_std \2; 36 bytes after the last field, marker MAC1$" "$work/decoded.txt" || true)
[ "$good" = "$n" ] || fail "$((n - good)) of $n signed messages did not decode whole, or left other than the 36-byte trailer"
echo "PASS: lcm-spy's decoder read every field of $n signed MASA_POLICY messages and left exactly the 36-byte trailer"
rm -rf "$work"
