#!/usr/bin/env bash
# masa_lcm_probe --log reads an lcm-logger recording with the code that reads the network: a
# learner and an actor train over real multicast while lcm-logger records every channel and a live
# probe listens beside it; stopped together, the log replayed through LogBus gives the live probe's
# count of parameter versions on MASA_POLICY and of rollout chunks, and a damaged copy of the log is
# refused by name (exit 1), not read as if whole.
#   MASA_BUILD_DIR=build bash tests/integration/probe_log.sh [PORT]
set -euo pipefail
cd "$(dirname "$0")/../.."
source tests/integration/lib.sh

port=${1:-7723}
command -v lcm-logger > /dev/null || { echo "SKIP: lcm-logger is not installed"; exit 77; }
probe="$build/tools/masa_lcm_probe"
begin_local_run probe_log "$port"

lcm-logger --lcm-url="$url" --channel='MASA_.*' "$work/run.lcmlog" > "$work/logger.log" 2>&1 &
logger_pid=$!
started_pids+=("$logger_pid")
"$probe" --url "$url" --all --quiet --run-id "$run_id" > "$work/live.txt" 2> "$work/live.err" &
probe_pid=$!
started_pids+=("$probe_pid")
sleep 0.5
start_learner "$run" "$url" "$run_id" --no-auth
start_actor 0 "$url" "$run_id" --no-auth
wait_until 90 "5 updates" at_least_updates "$run" 5
kill -INT "$actor_pid" "$learner_pid"
wait "$actor_pid" "$learner_pid" 2>/dev/null || true
sleep 0.5  # the last datagrams reach both listeners
kill -INT "$probe_pid" "$logger_pid"
wait "$probe_pid" "$logger_pid" 2>/dev/null || true
[ -s "$work/run.lcmlog" ] || fail "lcm-logger recorded nothing: $(cat "$work/logger.log")"

"$probe" --log "$work/run.lcmlog" --all --quiet --run-id "$run_id" > "$work/replayed.txt" 2> "$work/replayed.err" ||
  fail "the probe could not read the log: $(cat "$work/replayed.err")"
cat "$work/live.txt" "$work/replayed.txt"
row() { awk -v ch="$2" '$1 == ch { print $2 }' "$1"; }
versions() { sed -n 's/^  MASA_POLICY: \(versions [0-9]*\.\.[0-9]*\).*/\1/p' "$1"; }
for ch in MASA_POLICY MASA_ROLLOUT; do
  live=$(row "$work/live.txt" $ch) replayed=$(row "$work/replayed.txt" $ch)
  [ "${live:-0}" -gt 0 ] || fail "the live probe heard nothing on $ch"
  [ "$live" = "$replayed" ] || fail "$ch: the live probe counted $live messages, the log $replayed"
done
[ -n "$(versions "$work/replayed.txt")" ] && [ "$(versions "$work/live.txt")" = "$(versions "$work/replayed.txt")" ] ||
  fail "the versions differ: live '$(versions "$work/live.txt")', log '$(versions "$work/replayed.txt")'"
grep -q "events read from the log" "$work/replayed.err" || fail "the probe did not say how many events it read"

# A damaged copy: the second event's sync word broken.
python3 - "$work/run.lcmlog" "$work/damaged.lcmlog" << 'PY'
import struct, sys
b = bytearray(open(sys.argv[1], 'rb').read())
clen, dlen = struct.unpack('>ii', b[20:28])
second = 28 + clen + dlen
b[second] ^= 0xff
open(sys.argv[2], 'wb').write(b)
PY
rc=0
"$probe" --log "$work/damaged.lcmlog" --all --quiet > /dev/null 2> "$work/damaged.err" || rc=$?
[ "$rc" = 1 ] || fail "a damaged log gave exit $rc, not 1"
grep -q "not an LCM log at event 2: no sync word" "$work/damaged.err" || fail "the damage was not named: $(cat "$work/damaged.err")"
"$probe" --log "$work/run.lcmlog" --roster /nonexistent > /dev/null 2>&1 && fail "--log with --roster was accepted"
echo "PASS: the log replayed gives the live probe's counts ($(row "$work/replayed.txt" MASA_POLICY) parameter messages, $(row "$work/replayed.txt" MASA_ROLLOUT) chunks, $(versions "$work/replayed.txt")); a damaged log is refused by name"
rm -rf "$work"
