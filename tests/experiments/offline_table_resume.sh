#!/usr/bin/env bash
# experiments/offline_table.sh as a user meets it: a tiny table (BC as SA and MASA, seeds 0 and 1,
# on a tiny dataset recorded here from the shipped A1 policy) killed after its first run goes on when
# the same command is given again, does not redo the finished run, only evaluates a run whose
# training finished, and writes table.md and table.csv whose numbers are the runs' own (mean and
# standard deviation over the seeds of each run's eval.csv means, the dataset's from masa_dataset info).
#   tests/experiments/offline_table_resume.sh BUILD_DIR WORK_DIR
set -euo pipefail
build=$(cd "$1" && pwd) work=$2
src=$(cd "$(dirname "$0")/../.." && pwd)
export MASA_BUILD_DIR=$build OMP_NUM_THREADS=1
rm -rf "$work" && mkdir -p "$work" && cd "$work"
fail() { echo "FAIL: $*"; for f in table/tiny/*.log table*.out; do [ -f "$f" ] && { echo "--- $f"; tail -n 20 "$f"; }; done; exit 1; }

# A dataset of 4 short episodes of the shipped policy (sampled, as a behaviour policy).
mkdir -p data
"$build/tools/masa_dataset" record "$src/tasks/a1_beam/policy/policy.bin" --episodes 4 --max-steps 60 \
  --out data/tiny.lcmlog > record.out 2>&1 || { cat record.out; fail "masa_dataset record failed"; }
table=("$src/experiments/offline_table.sh" --task a1_beam --datasets data --families tiny --algos bc
       --methods "sa masa" --seeds "0 1" --bc-steps 1500 --episodes 2 --env-of "$src/tasks/a1_beam/policy/policy.bin"
       --jobs 1 --out table --set env.max_episode_steps=60 --set model.policy_hidden=[32,32])

# 1. Killed once the first run (sa, seed 0) is done, while the second (masa) trains or is evaluated.
"${table[@]}" > table1.out 2>&1 &
pid=$!
for _ in $(seq 600); do [ -f table/tiny/bc_sa_s0/done ] && break; sleep 0.1; done
[ -f table/tiny/bc_sa_s0/done ] || fail "the first run was not done in 60 s"
# The same table started twice: the second is refused while the first runs.
"${table[@]}" > table_twice.out 2>&1 && fail "a second table on the same directory was accepted"
grep -q "another table is running in" table_twice.out || fail "the second table did not say why: $(cat table_twice.out)"
# --summarize may look at the running table: the finished run, its cell marked as 1 seed of 2.
"$src/experiments/offline_table.sh" --summarize --out table > table_peek.out 2>&1 || fail "--summarize of a running table failed"
grep -q "^| tiny | [-0-9.]* ± [0-9.]* | [-0-9.]* (1 seed) | " table/table.md || fail "the running table's table.md: $(cat table/table.md)"
kill -TERM "$pid"
wait "$pid" && fail "the killed table exited 0" || true
[ -f table/tiny/bc_masa_s0/done ] && fail "masa's run finished before the kill (make the runs longer)"
pgrep -f "masa_offline.*$PWD/table" > /dev/null && fail "a run of the killed table still runs"

# 2. The same command again: sa is not redone, the others run, the table is written.
"${table[@]}" > table2.out 2>&1 || fail "the resumed table failed"
grep -q "4 runs .*1 already done" table2.out || fail "the resumed table did not see sa done: $(head -1 table2.out)"
[ "$(grep -c '^# .*masa_offline' table/tiny/bc_sa_s0.log)" -eq 1 ] || fail "sa's run was trained again"
for r in sa_s0 masa_s0 sa_s1 masa_s1; do [ -f "table/tiny/bc_$r/done" ] || fail "bc_$r is not done"; done
grep -q -- "--env-of $src/tasks/a1_beam/policy/policy.bin" table/tiny/bc_masa_s0.log || fail "the log has no exact command"
for f in table/table.md table/table.csv table/runs.csv; do [ -s "$f" ] || fail "no $f"; done

# 3. The numbers: each cell is the mean and standard deviation over the seeds of each run's mean
#    over its eval.csv episodes; the dataset's mean return is masa_dataset info's.
run_mean() { awk -F, -v c="$2" 'NR == 1 { for (i = 1; i <= NF; ++i) if ($i == c) k = i; next } { s += $k; ++n } END { printf "%.9g", s / n }' "$1"; }
# mean_of METHOD COLUMN DIGITS: "mean ± std" over seeds 0 and 1, as table.md writes it.
mean_of() { awk -v a="$(run_mean "table/tiny/bc_$1_s0/eval.csv" "$2")" -v b="$(run_mean "table/tiny/bc_$1_s1/eval.csv" "$2")" -v d="$3" \
            'BEGIN { m = (a + b) / 2; printf "%." d "f ± %." d "f", m, sqrt((a - m) ^ 2 + (b - m) ^ 2) }'; }
ds=$("$build/tools/masa_dataset" info data/tiny.lcmlog | sed -n 's/.* return \([-0-9.]*\) +- .*/\1/p' | head -1)
[ -n "$ds" ] || fail "masa_dataset info gave no return"
ds=$(printf '%.1f' "$ds")
for r in sa_s0 masa_s0 sa_s1 masa_s1; do
  [ "$(awk -F, 'END { print NR - 1 }' "table/tiny/bc_$r/eval.csv")" -eq 2 ] || fail "bc_$r's eval.csv has not 2 episodes"
done
r_sa=$(mean_of sa return 1) r_masa=$(mean_of masa return 1) d_sa=$(mean_of sa distance_m 3) d_masa=$(mean_of masa distance_m 3)
grep -qx "| tiny | $ds ± [0-9.]* | $r_sa | $r_masa |" table/table.md || \
  fail "table.md's return row is not '| tiny | $ds ± .. | $r_sa | $r_masa |':"$'\n'"$(cat table/table.md)"
grep -qx "| tiny | $d_sa | $d_masa |" table/table.md || fail "table.md's distance row is not '| tiny | $d_sa | $d_masa |'"
awk -F, -v r="${r_masa%% ±*}" 'NR > 1 && $3 == "masa" { found = 1; if (sprintf("%.1f", $6) != r || $5 != 2 || $7 == "nan") bad = 1 }
  END { exit !found || bad }' table/table.csv || fail "table.csv's masa row is not return ${r_masa%% ±*} over 2 seeds:"$'\n'"$(cat table/table.csv)"

# 4. A third call redoes nothing and rewrites the table; a run trained but not evaluated (no `done`)
#    is only evaluated; --summarize alone writes the table; a different table for the same directory
#    is refused.
trained=$(cat table/tiny/*.log | grep -c '^# .*masa_offline')
rm table/table.md table/tiny/bc_masa_s1/done table/tiny/bc_masa_s1/eval.csv
"${table[@]}" > table3.out 2>&1 || fail "the third call failed"
grep -q "4 runs .*3 already done" table3.out || fail "the third call did not see 3 runs done: $(head -1 table3.out)"
[ "$(cat table/tiny/*.log | grep -c '^# .*masa_offline')" -eq "$trained" ] || fail "the third call trained something again"
[ "$(grep -c '^# .*masa_eval' table/tiny/bc_masa_s1.log)" -eq 2 ] || fail "masa seed 1 was not evaluated again"
[ -f table/tiny/bc_masa_s1/done ] && [ -s table/table.md ] || fail "the third call did not finish the run and write the table"
grep -qx "| tiny | $ds ± [0-9.]* | $r_sa | $r_masa |" table/table.md || fail "the re-evaluation changed the table"
"$src/experiments/offline_table.sh" --summarize --out table > table4.out 2>&1 || fail "--summarize failed"
"$src/experiments/offline_table.sh" --out table --seeds "0 1 2" > table5.out 2>&1 && fail "a different table in the same directory was accepted"
grep -q "is the table seeds='0 1', not '0 1 2'" table5.out || fail "the refusal does not say why: $(cat table5.out)"
echo "PASS: killed after run 1 of 4, resumed without redoing it, table.md: dataset $ds, BC SA $r_sa, BC MASA $r_masa ($d_masa m)"
