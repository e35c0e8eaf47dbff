#!/usr/bin/env bash
# Time to recover from kill -9 (issue #9's figures), over real multicast on this machine (udpm,
# ttl=0), the learner and two actors as separate processes in the test's small configuration:
#  1. kill -9 of actor 1: the time from the kill to the learner's next update, and the update rate
#     before and after (one actor left);
#  2. kill -9 of the learner, restarted at once with --resume (same run dir, id and key) while the
#     actor keeps running: the time from the kill to the first update of the resumed learner, and
#     the updates redone (made after the last checkpoint, lost with the learner).
#   MASA_BUILD_DIR=build bench/e2e_recovery.sh [PORT]
set -euo pipefail
cd "$(dirname "$0")/.."
source tests/integration/lib.sh

port=${1:-7699}
begin_local_run recovery "$port"
now() { date +%s.%N; }
# The wall time of the newest update: metrics.csv's rows do not carry one, so poll the row count.
wait_updates() {  # wait_updates N: until N updates, returns the time it was seen
  local deadline=$(( $(date +%s) + 120 ))
  until [ "$(updates_in "$run")" -ge "$1" ]; do
    [ "$(date +%s)" -lt "$deadline" ] || fail "no $1 updates within 120 s"
    sleep 0.01
  done
  now
}
rate() { awk -v n="$1" -v a="$2" -v b="$3" 'BEGIN { printf "%.1f", n * 60 / (b - a) }'; }

echo "e2e_recovery: $(date -u +%FT%TZ), commit $(git rev-parse --short HEAD 2>/dev/null || echo '?'), $(nproc) cores, load $(cut -d' ' -f1-3 /proc/loadavg)"
start_learner "$run" "$url" "$run_id"
start_actor 0 "$url" "$run_id"
a0=$actor_pid
start_actor 1 "$url" "$run_id"
a1=$actor_pid
t0=$(wait_updates 10)
t1=$(wait_updates 60)
before=$(rate 50 "$t0" "$t1")

# 1. An actor dies.
n=$(updates_in "$run")
kill -KILL "$a1"
tk=$(now)
tn=$(wait_updates $((n + 1)))
t2=$(wait_updates $((n + 5)))
t3=$(wait_updates $((n + 45)))
after=$(rate 40 "$t2" "$t3")
echo "actor kill -9: next update after $(awk -v a="$tk" -v b="$tn" 'BEGIN { printf "%.3f", b - a }') s; updates/min with 2 actors $before, with 1 actor $after"

# 2. The learner dies and is resumed at once; actor 0 keeps running.
n=$(updates_in "$run")
kill -KILL "$learner_pid"
wait "$learner_pid" 2> /dev/null || true
tk=$(now)
mv "$work/learner.log" "$work/learner_before_kill.log"
"$learner_bin" "${test_sets[@]}" --url "$url" --resume "$run" --max-updates 100000 "${auth[@]+"${auth[@]}"}" \
  > "$work/learner.log" 2>&1 &
learner_pid=$!
started_pids+=("$learner_pid")
# The resumed learner cuts metrics.csv back to its checkpoint: wait for a row past that.
sleep 0.2
resumed_at=$(sed -n 's/^masa_learner: run id [0-9]*, run dir .*, version \([0-9]*\),.*/\1/p' "$work/learner.log" | head -1)
for _ in $(seq 100); do
  [ -n "$resumed_at" ] && break
  sleep 0.1
  resumed_at=$(sed -n 's/^masa_learner: run id [0-9]*, run dir .*, version \([0-9]*\),.*/\1/p' "$work/learner.log" | head -1)
done
[ -n "$resumed_at" ] || fail "the resumed learner did not start"
tn=$(wait_updates $((resumed_at + 1)))
took_back=$(grep -c "taking parameters version" "$work/actor0.log" || true)
echo "learner kill -9 and --resume: first update after $(awk -v a="$tk" -v b="$tn" 'BEGIN { printf "%.3f", b - a }') s; resumed at update $resumed_at of $n made ($((n - resumed_at)) to redo; checkpoint every 10); actor 0 took the learner's version back $took_back time(s)"
kill -TERM "$a0" 2> /dev/null || true
kill -INT "$learner_pid"
wait "$learner_pid" || true
rm -rf "$work"
