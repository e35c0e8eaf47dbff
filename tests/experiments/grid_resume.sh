#!/usr/bin/env bash
# experiments/grid.sh as a user meets it: a grid of 2 tiny runs killed during its first run goes
# on from that run's checkpoint when the same command is given again (not from the start), finishes
# both, does not redo finished runs on a third call, draws the comparison (masa_compare), and goes
# on to more updates with --extend; --status shows where each run stands; record_grid.sh copies it
# for the record, with the checkpoints of unfinished runs when asked, and restore_grid.sh brings
# such a record back to go on (a grid that outlives its machine).
#   tests/experiments/grid_resume.sh BUILD_DIR WORK_DIR
set -euo pipefail
build=$(cd "$1" && pwd) work=$2
src=$(cd "$(dirname "$0")/../.." && pwd)
export MASA_BUILD_DIR=$build OMP_NUM_THREADS=1
rm -rf "$work" && mkdir -p "$work" && cd "$work"
fail() { echo "FAIL: $*"; for f in grid/a1_beam/*.log grid*.out; do [ -f "$f" ] && { echo "--- $f"; tail -n 20 "$f"; }; done; exit 1; }
grid=("$src/experiments/grid.sh" --tasks a1_beam --methods "masa sa" --seeds 0 --updates 150 --jobs 1 --no-recipe
      --out grid --set model.policy_hidden=[16] --set model.critic_hidden=[16] --set ppo.num_envs=8
      --set ppo.horizon=8 --set ppo.minibatch_size=64 --set env.max_episode_steps=40
      --set runner.checkpoint_every=5 --set runner.eval_every=5 --set runner.eval_episodes=1
      --set runner.plot_every=0)  # curves drawn on exit only: 15 renders a run cost seconds here

# 1. Killed during masa's run, after a checkpoint or two.
"${grid[@]}" > grid1.out 2>&1 &
pid=$!
csv=grid/a1_beam/masa_s0/metrics.csv
for _ in $(seq 600); do
  [ -f "$csv" ] && [ "$(wc -l < "$csv")" -ge 12 ] && break
  sleep 0.1
done
[ -f "$csv" ] && [ "$(wc -l < "$csv")" -ge 12 ] || fail "masa's run wrote no 11 updates in 60 s"
# The same grid started twice: the second is refused while the first runs (it would redo its runs).
"${grid[@]}" > grid_twice.out 2>&1 && fail "a second grid on the same directory was accepted"
grep -q "another grid is running in" grid_twice.out || fail "the second grid did not say why: $(cat grid_twice.out)"
kill -TERM "$pid"
wait "$pid" && fail "the killed grid exited 0" || true
[ -f grid/a1_beam/masa_s0/done ] && fail "the killed run is marked done"
[ -f grid/a1_beam/masa_s0/checkpoint.bin ] || fail "the killed run left no checkpoint"
rows_at_kill=$(($(wc -l < "$csv") - 1))
[ "$rows_at_kill" -lt 150 ] || fail "masa's run finished before the kill (make the runs longer)"
echo "killed at $rows_at_kill of 150 updates"
# --status: the killed run where it stopped, the other waiting, and an ETA from the measured speed.
"$src/experiments/grid.sh" --status --out grid > status.out 2>&1 || fail "--status failed: $(cat status.out)"
grep -Eq "a1_beam +masa +seed 0 +$rows_at_kill/150 +stopped +[0-9.]+ s/update +last eval -?[0-9.]+" status.out || \
  fail "--status: $(cat status.out)"
# The last evaluation shown is the last eval_return in the run's metrics.
last_eval=$(awk -F, 'NR == 1 { for (c = 1; c <= NF; c++) if ($c == "eval_return") col = c; next }
                     $col != "" && $col != "nan" { v = $col } END { printf "%.1f", v }' "$csv")
grep -Eq "a1_beam +masa +seed 0 .* last eval $last_eval\$" status.out || fail "--status does not show the last evaluation $last_eval: $(cat status.out)"
grep -Eq "a1_beam +sa +seed 0 +0/150 +waiting" status.out || fail "--status does not show sa waiting: $(cat status.out)"
grep -Eq "^0 done, 0 running, 1 stopped, 1 waiting; $rows_at_kill of 300 updates .*ETA [0-9]+:[0-9]{2} h" status.out || \
  fail "--status summary: $(cat status.out)"
# While a grid runs (its lock held, one slot here), a run is running exactly when its masa_train is:
# the killed run, its metrics.csv seconds old, is stopped (--status said "running" for 5 minutes
# after a stop before 2026-12-04), and running once a process trains it.
[ -f grid/.slots ] && cp grid/.slots slots.kept
echo localhost > grid/.slots
( flock 9; sleep 4 ) 9> grid/.grid.lock & lock_pid=$!
sleep 0.3
"$src/experiments/grid.sh" --status --out grid > status_lock.out 2>&1 || fail "--status failed: $(cat status_lock.out)"
grep -Eq "a1_beam +masa +seed 0 +$rows_at_kill/150 +stopped " status_lock.out && grep -q "^0 done, 0 running, 1 stopped" status_lock.out ||
  fail "--status of a running grid calls the stopped run running: $(cat status_lock.out)"
( exec -a "masa_train --run-dir $(realpath grid/a1_beam/masa_s0)" sleep 3 ) & fake_pid=$!
sleep 0.3
"$src/experiments/grid.sh" --status --out grid > status_run.out 2>&1 || fail "--status failed: $(cat status_run.out)"
grep -Eq "a1_beam +masa +seed 0 +$rows_at_kill/150 +running " status_run.out ||
  fail "--status does not see the run its masa_train trains: $(cat status_run.out)"
kill "$fake_pid" "$lock_pid" 2>/dev/null; wait "$fake_pid" "$lock_pid" 2>/dev/null || true
rm -f grid/.slots; [ -f slots.kept ] && mv slots.kept grid/.slots

# 1b. The stopped grid recorded with its checkpoint (record_grid.sh --checkpoints, what a session
# keeps when its machine goes), and without.
"$src/experiments/record_grid.sh" --out grid --to rec_stopped --checkpoints > rec_stopped.out 2>&1 || \
  fail "record_grid.sh --checkpoints failed: $(cat rec_stopped.out)"
[ -s rec_stopped/a1_beam/masa_s0/checkpoint.bin ] && [ -s rec_stopped/a1_beam/masa_s0/actor_state.bin.xz ] || \
  fail "--checkpoints did not keep the stopped run's checkpoint and its environments, compressed"
[ ! -e rec_stopped/a1_beam/masa_s0/actor_state.bin ] || fail "the environments were kept uncompressed as well"
cmp -s <(xz -dc rec_stopped/a1_beam/masa_s0/actor_state.bin.xz) grid/a1_beam/masa_s0/actor_state.bin || \
  fail "the recorded environments are not the stopped run's"
grep -q "^checkpoints: 1 unfinished runs keep theirs" rec_stopped/RECORD.txt || fail "RECORD.txt: $(cat rec_stopped/RECORD.txt)"
"$src/experiments/record_grid.sh" --out grid --to rec_stopped_plain > rec_stopped_plain.out 2>&1 || \
  fail "record_grid.sh of the stopped grid failed: $(cat rec_stopped_plain.out)"

# 2. The same command again: masa goes on from its checkpoint, sa runs, the comparison is drawn.
"${grid[@]}" > grid2.out 2>&1 || fail "the resumed grid failed"
grep -q "0 already done" grid2.out || fail "the resumed grid thought a run was done"
grep -Eq "^grid.sh: 1 done, [01] running, .* of 300 updates \([0-9]+%\); ETA [0-9]+:[0-9]{2} h" grid2.out || \
  fail "no progress line after the first finished run: $(cat grid2.out)"
grep -q -- "--resume .*masa_s0" grid/a1_beam/masa_s0.log || fail "masa's run was not resumed from its checkpoint"
[ -f grid/a1_beam/masa_s0/done ] && [ -f grid/a1_beam/sa_s0/done ] || fail "a run is not marked done"
# Which code made each run: the log names the binaries' commit at every start, config.yaml too.
version=$("$build/tools/masa_train" --version) || fail "masa_train --version failed"
[[ "$version" =~ ^([0-9a-f]{7,}(-dirty)?|unknown)$ ]] || fail "masa_train --version printed '$version'"
[ "$(grep -c "^# binaries: masa $version\$" grid/a1_beam/masa_s0.log)" -eq 2 ] || fail "masa's log does not name the binaries twice"
grep -qx "# Written by masa $version" grid/a1_beam/sa_s0/config.yaml || fail "config.yaml does not name the commit"
[ "$(($(wc -l < "$csv") - 1))" -eq 150 ] || fail "masa's metrics.csv has $(($(wc -l < "$csv") - 1)) rows, not 150"
# One row per update, no update twice: the updates are 1..150 in order.
awk -F, 'NR > 1 && $1 != NR - 1 { bad = 1 } END { exit bad }' "$csv" || fail "masa's updates are not 1..150 in order"
for f in grid/verdict.md grid/a1_beam/runs.csv grid/a1_beam/curves/return_masa.dat grid/a1_beam/curves/eval_return_sa.dat; do
  [ -s "$f" ] || fail "no $f"
done
if command -v gnuplot > /dev/null; then
  [ -s grid/a1_beam/compare.png ] && [ -s grid/compare_all.png ] || fail "no figures"
fi
grep -q "| sa | " grid/verdict.md || fail "the verdict has no row for sa"
# 2b. A recorded grid keeps its metrics as metrics.csv.xz (experiments/README.md, the tree's budget):
# masa_compare reads them as it reads the plain files.
mkdir -p packed/a1_beam
for m in masa sa; do mkdir -p "packed/a1_beam/${m}_s0" && xz -c "grid/a1_beam/${m}_s0/metrics.csv" > "packed/a1_beam/${m}_s0/metrics.csv.xz"; done
"$build/tools/masa_compare" packed > packed.out 2>&1 || fail "masa_compare on a grid of metrics.csv.xz failed: $(cat packed.out)"
"$build/tools/masa_compare" grid > plain.out 2>&1 || fail "masa_compare on the grid failed: $(cat plain.out)"
cmp -s <(grep "^| " grid/verdict.md) <(grep "^| " packed/verdict.md) ||
  fail "masa_compare's verdict on metrics.csv.xz differs from the plain files': $(diff <(grep '^| ' grid/verdict.md) <(grep '^| ' packed/verdict.md) | head -4)"

# 3. A third call redoes nothing and redraws the comparison.
logs_before=$(cat grid/a1_beam/*.log | wc -l)
rm -f grid/a1_beam/compare.png grid/verdict.md
"${grid[@]}" > grid3.out 2>&1 || fail "the third call failed"
grep -q "2 already done" grid3.out || fail "the third call did not see both runs done"
[ "$(cat grid/a1_beam/*.log | wc -l)" -eq "$logs_before" ] || fail "the third call ran something again"
[ -s grid/verdict.md ] || fail "the third call did not redo the comparison"
# --replot, and a grid definition that differs from the directory's is refused.
"$src/experiments/grid.sh" --replot --out grid > grid4.out 2>&1 || fail "--replot failed"
"$src/experiments/grid.sh" --out grid --seeds 1 > grid5.out 2>&1 && fail "a different grid in the same directory was accepted"
grep -q "is the grid seeds='0', not '1'" grid5.out || fail "the refusal does not say why: $(cat grid5.out)"
# 3b. --extend: the finished grid goes on to 160 updates, both runs from their checkpoints at 150;
# fewer updates, or other grid options with it, are refused with the reason.
"$src/experiments/grid.sh" --extend 150 --out grid > grid_ext0.out 2>&1 && fail "--extend to the grid's own 150 updates was accepted"
grep -q "already go to 150 updates; --extend 150 must be more" grid_ext0.out || fail "no reason given: $(cat grid_ext0.out)"
"$src/experiments/grid.sh" --extend 160 --seeds 1 --out grid > grid_ext1.out 2>&1 && fail "--extend with --seeds was accepted"
grep -q "give it no other grid options" grid_ext1.out || fail "no reason given: $(cat grid_ext1.out)"
"$src/experiments/grid.sh" --extend 160 --out grid > grid_ext.out 2>&1 || fail "--extend failed"
grep -q "extended from 150 to 160 updates" grid_ext.out || fail "--extend did not say what it did"
grep -q "^updates=160$" grid/grid.txt && grep -q "^# extended from 150 to 160 updates" grid/grid.txt || \
  fail "grid.txt does not record the extension"
for m in masa sa; do
  [ -f "grid/a1_beam/${m}_s0/done" ] || fail "the extended $m run is not marked done"
  grep -q -- "--updates 160 --resume .*${m}_s0" "grid/a1_beam/${m}_s0.log" || fail "$m was not resumed to 160 updates"
  awk -F, 'NR > 1 && $1 != NR - 1 { bad = 1 } END { exit bad || NR != 161 }' "grid/a1_beam/${m}_s0/metrics.csv" || \
    fail "$m's updates are not 1..160 in order"
done
[ -s grid/verdict.md ] || fail "the extended grid did not redo the comparison"

# 3b'. A grid grows (a copy of it, here): naming its seed and one more runs the new seed's runs
# with the grid's options and updates, redoes none of seed 0's, and compares over both seeds.
# Growing with --replot, or with other --set options, is refused and changes nothing.
cp -a grid grown
"$src/experiments/grid.sh" --replot --seeds "0 1" --out grown > grow0.out 2>&1 && fail "--replot grew the grid"
grep -q "take the grid as it is" grow0.out || fail "no reason given: $(cat grow0.out)"
"$src/experiments/grid.sh" --seeds "0 1" --set ppo.num_envs=16 --out grown > grow1.out 2>&1 && fail "a grid grew with other --set options"
grep -q "^seeds=0$" grown/grid.txt || fail "a refused growth changed grid.txt"
logs_before=$(cat grown/a1_beam/*_s0.log | wc -l)
"$src/experiments/grid.sh" --seeds "0 1" --out grown > grow.out 2>&1 || fail "growing the grid failed: $(cat grow.out)"
grep -q "grows: seeds '0' -> '0 1'" grow.out && grep -q "4 runs .*, 2 already done" grow.out || fail "growing did not say what it did"
grep -q "^seeds=0 1$" grown/grid.txt && grep -q "^# grew: seeds '0' -> '0 1'" grown/grid.txt || fail "grid.txt does not record the growth"
[ "$(cat grown/a1_beam/*_s0.log | wc -l)" -eq "$logs_before" ] || fail "growing ran seed 0 again"
for m in masa sa; do
  [ -f "grown/a1_beam/${m}_s1/done" ] || fail "the new $m seed is not done"
  [ "$(($(wc -l < "grown/a1_beam/${m}_s1/metrics.csv") - 1))" -eq 160 ] || fail "the new $m seed did not run the grid's 160 updates"
  grep -q "num_envs: 8" "grown/a1_beam/${m}_s1/config.yaml" || fail "the new $m seed lost the grid's --set options"
done
grep -q "^| masa | 2 |" grown/verdict.md || fail "the grown grid's comparison is not over both seeds: $(cat grown/verdict.md)"

# 3b''. Milestones: when each run first reaches a level of a column, added to the finished grid
# with --replot and kept in grid.txt (a later --replot still has it); a column the runs lack, or a
# malformed one, is refused and changes nothing. The same seeds in another order are the grid as
# it is, not a growth.
"$src/experiments/grid.sh" --replot --out grown --milestone a1_beam:update=11 --milestone update=100000 > ms.out 2>&1 || \
  fail "--replot with milestones failed: $(cat ms.out)"
grep -qx "milestone=a1_beam:update=11" grown/grid.txt && grep -qx "milestone=update=100000" grown/grid.txt || \
  fail "grid.txt does not keep the milestones: $(cat grown/grid.txt)"
"$src/experiments/grid.sh" --replot --out grown > ms2.out 2>&1 || fail "--replot after milestones failed"
at11=$(awk -F, 'NR > 1 && $1 == 11 { print $2 }' grown/a1_beam/masa_s1/metrics.csv)
[ "$at11" = 704 ] || fail "update 11 is at $at11 env steps, not 8 envs x 8 steps x 11 = 704"
grep -q "^Milestone update >= 11:" grown/verdict.md || fail "no milestone in the verdict: $(cat grown/verdict.md)"
grep -qx "| masa | 2 of 2 | s0 704, s1 704 | 704 |  |" grown/verdict.md || fail "masa's milestone row: $(cat grown/verdict.md)"
grep -qx "| sa | 2 of 2 | s0 704, s1 704 | 704 | 0 \[0, 0\] |" grown/verdict.md || fail "sa's milestone row: $(cat grown/verdict.md)"
grep -qx "| sa | 0 of 2 | s0 -, s1 - | not within the budget | n/a (a seed never reached it) |" grown/verdict.md || \
  fail "a milestone never reached: $(cat grown/verdict.md)"
cp grown/grid.txt grid_before_ms.txt
"$src/experiments/grid.sh" --replot --out grown --milestone no_such_column=1 > ms3.out 2>&1 && fail "a milestone on a missing column was accepted"
grep -q "have no column 'no_such_column'" ms3.out || fail "no reason given: $(cat ms3.out)"
"$src/experiments/grid.sh" --replot --out grown --milestone update > ms4.out 2>&1 && fail "a malformed milestone was accepted"
grep -q "write \[TASK:\]COLUMN=LEVEL" ms4.out || fail "no reason given: $(cat ms4.out)"
"$src/experiments/grid.sh" --replot --out grown --seeds "1 0" > ms5.out 2>&1 || fail "the grid's seeds in another order were refused: $(cat ms5.out)"
cmp -s grid_before_ms.txt grown/grid.txt || fail "a refused milestone or a reordering changed grid.txt: $(diff grid_before_ms.txt grown/grid.txt)"
# A milestone on a figure that falls (COLUMN<=LEVEL, an error): the first row at or below the level,
# update 1 at 64 steps (read as "reaches 3" it would be update 3, 192 steps).
"$src/experiments/grid.sh" --replot --out grown --milestone 'update<=3' > ms6.out 2>&1 || fail "a <= milestone was refused: $(cat ms6.out)"
grep -q "^Milestone update <= 3:" grown/verdict.md || fail "no <= milestone in the verdict: $(cat grown/verdict.md)"
grep -qx "| masa | 2 of 2 | s0 64, s1 64 | 64 |  |" grown/verdict.md || fail "masa's <= milestone row: $(cat grown/verdict.md)"
grep -qx "milestone=update<=3" grown/grid.txt || fail "grid.txt does not keep the <= milestone: $(cat grown/grid.txt)"

# 3b'''. A build without masa_compare (a frozen one may hold masa_train alone): the comparison falls
# back on this checkout's build/tools/masa_compare and says so, or, without one, says how to draw it.
mkdir -p trainonly/tools && ln -sf "$build/tools/masa_train" trainonly/tools/masa_train
rm -f grown/verdict.md
if [ -x "$src/build/tools/masa_compare" ]; then
  MASA_BUILD_DIR=$PWD/trainonly "$src/experiments/grid.sh" --replot --out grown > nocmp.out 2>&1 || fail "--replot with a build without masa_compare failed: $(cat nocmp.out)"
  grep -q "has no masa_compare: the comparison will use this checkout's build/tools/masa_compare" nocmp.out && [ -s grown/verdict.md ] || \
    fail "no fallback to the checkout's masa_compare: $(cat nocmp.out)"
else
  MASA_BUILD_DIR=$PWD/trainonly "$src/experiments/grid.sh" --replot --out grown > nocmp.out 2>&1 && fail "--replot without any masa_compare succeeded"
  grep -q "no masa_compare in .* or build/: the runs are done" nocmp.out || fail "no reason given: $(cat nocmp.out)"
  "$src/experiments/grid.sh" --replot --out grown > /dev/null 2>&1 || fail "--replot with the build failed"
fi

# 3c. record_grid.sh: the grid as experiments/results/ keeps it (redrawn, no checkpoints, policies
# or per-run PNGs, with RECORD.txt); refused over an existing folder, while a grid runs, for a
# folder that is no grid, and over the grid itself.
rm -f grid/verdict.md
"$src/experiments/record_grid.sh" --out grid --to rec > rec.out 2>&1 || fail "record_grid.sh failed: $(cat rec.out)"
for f in verdict.md grid.txt status.txt RECORD.txt a1_beam/runs.csv a1_beam/masa_s0/config.yaml \
         a1_beam/masa_s0/metrics.csv a1_beam/sa_s0/metrics.csv a1_beam/masa_s0.log; do
  [ -s "rec/$f" ] || fail "the record has no $f"
done
[ -s grid/verdict.md ] || fail "record_grid.sh did not redraw the comparison first"
left_in=$(find rec -name checkpoint.bin -o -name actor_state.bin -o -name policy.bin -o -name learning_curve.png -o -name '.grid.lock')
[ -z "$left_in" ] || fail "the record keeps what it should leave out: $left_in"
cmp -s rec/a1_beam/masa_s0/metrics.csv grid/a1_beam/masa_s0/metrics.csv || fail "the recorded metrics differ"
grep -Eq "^checkout: [0-9a-f]{40}" rec/RECORD.txt && grep -q "^grid: tasks=a1_beam methods=masa sa" rec/RECORD.txt || \
  fail "RECORD.txt: $(cat rec/RECORD.txt)"
# The machine with its vector ISA: -march=native builds on AVX2 and on AVX-512 round differently.
cpu_isa="\((x86 family [0-9]+ model [0-9]+; )?(avx2|avx|no avx)(, (no )?avx512)?\)"
grep -Eq "^machine: .*, [0-9]+ cores, .*$cpu_isa\$" rec/RECORD.txt || fail "RECORD.txt does not name the CPU's ISA: $(grep machine rec/RECORD.txt)"
grep -q "^2 done, 0 running" rec/status.txt || fail "the recorded status: $(cat rec/status.txt)"
# Where each run was resumed: masa at the kill and at the extension, sa at the extension only.
# masa_train says so in the log; logs of binaries from before that give the same from where each
# process stopped.
grep -q "^masa_train: resumed at update $rows_at_kill (" grid/a1_beam/masa_s0.log || fail "masa_train did not say where it resumed"
grep -Eq "^  a1_beam/masa_s0: $rows_at_kill\(exact\) 150\(exact\) \$" rec/RECORD.txt && \
  grep -Eq "^  a1_beam/sa_s0: 150\(exact\) \$" rec/RECORD.txt || fail "RECORD.txt does not list the resumes: $(cat rec/RECORD.txt)"
cp -a grid grid_old_logs && sed -i '/^masa_train: resumed at update/d' grid_old_logs/a1_beam/*.log
"$src/experiments/record_grid.sh" --out grid_old_logs --to rec_old > rec_old.out 2>&1 || fail "record_grid.sh failed: $(cat rec_old.out)"
grep -Eq "^  a1_beam/masa_s0: $rows_at_kill 150 \$" rec_old/RECORD.txt || fail "resumes from older logs: $(cat rec_old/RECORD.txt)"
"$src/experiments/record_grid.sh" --out grid --to rec > rec2.out 2>&1 && fail "recording over an existing folder was accepted"
grep -q "rec exists (--force replaces it)" rec2.out || fail "no reason given: $(cat rec2.out)"
echo "what a person wrote about this record" > rec/README.md
touch rec/stale_figure.png
"$src/experiments/record_grid.sh" --out grid --to rec --force --policies > rec3.out 2>&1 || fail "--force failed: $(cat rec3.out)"
[ -s rec/a1_beam/masa_s0/policy.bin ] || fail "--policies kept no policy"
[ "$(cat rec/README.md)" = "what a person wrote about this record" ] && [ ! -e rec/stale_figure.png ] || \
  fail "--force lost the record's README.md or kept the rest of the old folder"
grep -q "kept rec/README.md" rec3.out || fail "--force did not say it kept the README: $(cat rec3.out)"
exec 8> grid/.grid.lock
flock -n 8 || fail "could not take the grid's lock"
"$src/experiments/record_grid.sh" --out grid --to rec_running > rec4.out 2>&1 && fail "recording a running grid was accepted"
grep -q "a grid is running in" rec4.out && [ ! -e rec_running ] || fail "no reason given: $(cat rec4.out)"
exec 8>&-
"$src/experiments/record_grid.sh" --out rec/a1_beam --to rec5 > rec5.out 2>&1 && fail "a folder without grid.txt was accepted"
grep -q "is not a grid" rec5.out || fail "no reason given: $(cat rec5.out)"
"$src/experiments/record_grid.sh" --out grid --to . --force > rec6.out 2>&1 && fail "recording over the grid's parent was accepted"
grep -q "would hold or replace the grid itself" rec6.out && [ -d grid/a1_beam ] || fail "no reason given: $(cat rec6.out)"

# 3d. film_grid.sh: each method's policy of one seed in the same episode, one strip a row, stacked;
# refused for a seed no run has, a task the grid has not, a folder that is no grid.
command -v xvfb-run > /dev/null || fail "xvfb-run is missing (scripts/install_deps.sh installs it)"
"$src/experiments/film_grid.sh" --out grid --seed 0 --frames 4 --width 160 --height 120 > film.out 2>&1 || \
  fail "film_grid.sh failed: $(cat film.out)"
for m in masa sa; do
  grep -Eq "^$m seed 0 \(160 updates\): return -?[0-9.]+, length [0-9]+, (terminated|time limit)" film.out || \
    fail "film_grid.sh did not report $m's episode: $(cat film.out)"
done
size=$(ffprobe -v error -select_streams v:0 -show_entries stream=width,height -of csv=p=0 grid/a1_beam/film_s0.png) || \
  fail "no grid/a1_beam/film_s0.png"
[ "$size" = "640,240" ] || fail "the film is $size pixels, not 4 frames of 160 wide by 2 rows of 120"
"$src/experiments/film_grid.sh" --out grid --seed 1 > film2.out 2>&1 && fail "a seed without runs was filmed"
grep -q "no method of seed 1 has a policy or checkpoint" film2.out || fail "no reason given: $(cat film2.out)"
"$src/experiments/film_grid.sh" --out grid --seed 0 --task ant_acrobatic > film3.out 2>&1 && fail "a task not in the grid was filmed"
grep -q "the grid has no task 'ant_acrobatic'" film3.out || fail "no reason given: $(cat film3.out)"
"$src/experiments/film_grid.sh" --out grid/a1_beam --seed 0 > film4.out 2>&1 && fail "a folder without grid.txt was filmed"
grep -q "is not a grid" film4.out || fail "no reason given: $(cat film4.out)"

# 3e. compare_runs.sh: any runs under labels of one's own (variants, runs of several grids), cut at
# a common budget, through masa_compare; refusals change nothing.
"$src/experiments/compare_runs.sh" --out cmp --updates 100 --reference b a=grid/a1_beam/sa_s0 b=grid/a1_beam/masa_s0 \
  --milestone update=11 > cmp.out 2>&1 || fail "compare_runs.sh failed: $(cat cmp.out)"
grep -qx "| b | 1 of 1 | s0 704 | 704 |  |" cmp/verdict.md || fail "compare_runs.sh's milestone: $(cat cmp/verdict.md)"
for l in a b; do
  [ "$(wc -l < cmp/a1_beam/${l}_s0/metrics.csv)" = 101 ] && [ -f cmp/a1_beam/${l}_s0/done ] || \
    fail "cmp/a1_beam/${l}_s0: not the first 100 updates, or not marked done"
done
cmp -s cmp/a1_beam/b_s0/metrics.csv <(head -n 101 grid/a1_beam/masa_s0/metrics.csv) || fail "b_s0 is not masa_s0's first 100 updates"
[ -s cmp/a1_beam/compare.png ] && grep -q "^# Comparison: b against each baseline" cmp/verdict.md || fail "no figure or verdict: $(cat cmp.out)"
grep -q "^methods=a b$" cmp/grid.txt && grep -q "^b 0 a1_beam 100 $PWD/grid/a1_beam/masa_s0$" cmp/sources.txt || \
  fail "sources: $(cat cmp/grid.txt cmp/sources.txt)"
"$src/experiments/compare_runs.sh" --out cmp2 --updates 999 a=grid/a1_beam/sa_s0 b=grid/a1_beam/masa_s0 > cmp2.out 2>&1 || \
  fail "compare_runs.sh with runs short of the budget failed: $(cat cmp2.out)"
grep -q "fewer than 999 updates, kept as unfinished: a_s0 (160 updates) b_s0 (160 updates)" cmp2.out && \
  [ ! -e cmp2/a1_beam/a_s0/done ] || fail "short runs not named unfinished: $(cat cmp2.out)"
refuse() {  # expected message, then the arguments
  local want=$1; shift
  "$src/experiments/compare_runs.sh" "$@" > refused.out 2>&1 && fail "compare_runs.sh $* was accepted"
  grep -q -- "$want" refused.out && [ ! -e cmp3 ] || fail "compare_runs.sh $*: no reason given, or it wrote: $(cat refused.out)"
}
refuse "cmp exists (--force replaces it)" --out cmp a=grid/a1_beam/sa_s0 b=grid/a1_beam/masa_s0
refuse "a has two runs of a1_beam with seed 0" --out cmp3 a=grid/a1_beam/sa_s0 a=grid/a1_beam/masa_s0 b=grid/a1_beam/sa_s0
refuse "label 'a_b'" --out cmp3 a_b=grid/a1_beam/sa_s0 b=grid/a1_beam/masa_s0
refuse "is not a run directory" --out cmp3 a=grid/a1_beam b=grid/a1_beam/masa_s0
refuse "--reference c is none of the labels (a b)" --out cmp3 --reference c a=grid/a1_beam/sa_s0 b=grid/a1_beam/masa_s0
refuse "give at least two LABEL=RUN_DIR (got 1)" --out cmp3 a=grid/a1_beam/sa_s0

# 4. Over a hosts file: every run goes through MASA_SSH and its directory through MASA_RSYNC (here
# stand-ins that run on this machine and log what they were asked to do).
cat > fake_ssh.sh <<'SH'
host=$1; shift; echo "ssh $host $*" >> "$(dirname "$0")/remote.log"; bash -c "$*"
SH
cat > fake_rsync.sh <<'SH'
echo "rsync $*" >> "$(dirname "$0")/remote.log"
SH
printf '# test hosts\nfar-host 2\n' > hosts
MASA_SSH="bash $PWD/fake_ssh.sh" MASA_RSYNC="bash $PWD/fake_rsync.sh" \
  "$src/experiments/grid.sh" --tasks a1_beam --methods "masa sa" --seeds 0 --updates 3 --no-recipe --out remote \
  --hosts hosts --set model.policy_hidden=[16] --set model.critic_hidden=[16] --set ppo.num_envs=8 \
  --set ppo.horizon=8 --set ppo.minibatch_size=64 > grid6.out 2>&1 || fail "the grid over a hosts file failed"
grep -q "2 at a time" grid6.out || fail "the hosts file's 2 slots were not used"
[ -f remote/a1_beam/masa_s0/done ] && [ -f remote/a1_beam/sa_s0/done ] || fail "a remote run is not done"
[ "$(grep -c '^ssh far-host .*masa_train' remote.log)" -eq 2 ] || fail "the runs did not go through ssh to far-host"
grep -q "^rsync -a far-host:$PWD/remote/a1_beam/masa_s0/ $PWD/remote/a1_beam/masa_s0/" remote.log || \
  fail "masa's run directory was not copied back"
# 5. restore_grid.sh: the stopped grid's record, brought back into a new directory (a new machine),
# goes on from the recorded checkpoint and finishes; masa's run is the one that never moved (same
# training returns, update by update: same checkpoint, same seeds). Without a checkpoint in the
# record, the begun run starts afresh. Refused over an existing directory and for a non-grid.
"$src/experiments/restore_grid.sh" --from rec_stopped --out restored > restore.out 2>&1 || fail "restore_grid.sh failed: $(cat restore.out)"
grep -q "0 runs finished, 1 go on from their checkpoints, 0 start afresh" restore.out || fail "restore said: $(cat restore.out)"
grep -Eq "^# restored .* from rec_stopped at commit .* on .*$cpu_isa: 0 finished, 1 go on" \
  restored/grid.txt || fail "grid.txt does not say where (which CPU) it was restored: $(cat restored/grid.txt)"
[ ! -e restored/RECORD.txt ] && [ ! -e restored/status.txt ] || fail "the record's own files came along"
cmp -s <(xz -dc rec_stopped/a1_beam/masa_s0/actor_state.bin.xz) restored/a1_beam/masa_s0/actor_state.bin && \
  [ ! -e restored/a1_beam/masa_s0/actor_state.bin.xz ] || fail "restore_grid.sh did not unpack the environments"
"$src/experiments/grid.sh" --out restored > grid7.out 2>&1 || fail "the restored grid failed: $(cat grid7.out)"
grep -q "^masa_train: resumed at update $rows_at_kill (.*); the environments go on as they were" restored/a1_beam/masa_s0.log || \
  fail "the restored masa run did not go on from $rows_at_kill with its environments: $(grep resumed restored/a1_beam/masa_s0.log)"
[ -f restored/a1_beam/masa_s0/done ] && [ -f restored/a1_beam/sa_s0/done ] || fail "a restored run is not done"
col=$(head -1 "$csv" | tr , '\n' | grep -nx return | cut -d: -f1)
[ -n "$col" ] || fail "metrics.csv has no return column: $(head -1 "$csv")"
cmp -s <(cut -d, -f"$col" restored/a1_beam/masa_s0/metrics.csv) <(head -n 151 "$csv" | cut -d, -f"$col") || \
  fail "the restored run's training returns differ from the run that stayed"
"$src/experiments/restore_grid.sh" --from rec_stopped_plain --out restored_plain > restore2.out 2>&1 || fail "restore failed: $(cat restore2.out)"
grep -q "0 runs finished, 0 go on from their checkpoints, 1 start afresh" restore2.out && [ ! -e restored_plain/a1_beam/masa_s0 ] || \
  fail "a run without checkpoint was not set to start afresh: $(cat restore2.out)"
"$src/experiments/restore_grid.sh" --from rec_stopped --out restored > restore3.out 2>&1 && fail "restoring over a grid was accepted"
grep -q "restored exists" restore3.out || fail "no reason given: $(cat restore3.out)"
"$src/experiments/restore_grid.sh" --from rec_stopped/a1_beam --out restored4 > restore4.out 2>&1 && fail "restoring a non-grid was accepted"
grep -q "is not a recorded grid" restore4.out && [ ! -e restored4 ] || fail "no reason given: $(cat restore4.out)"
# A damaged environments file in the record is refused by name, not resumed from.
cp -r rec_stopped rec_damaged
head -c 1000 rec_stopped/a1_beam/masa_s0/actor_state.bin.xz > rec_damaged/a1_beam/masa_s0/actor_state.bin.xz
"$src/experiments/restore_grid.sh" --from rec_damaged --out restored5 > restore5.out 2>&1 && fail "a damaged record was restored"
grep -q "unpacking a run's environments (actor_state.bin.xz) failed; nothing restored" restore5.out && [ ! -e restored5 ] || \
  fail "damaged record: $(cat restore5.out)"
# 5b. A finished grid recorded without its finished runs' checkpoints cannot be extended where it is
# restored (its runs would start afresh): refused by name, nothing changed. With --all-checkpoints
# the restored grid goes on to more updates from where each run finished, environments and all.
"$src/experiments/restore_grid.sh" --from rec --out restored_fin > restore6.out 2>&1 || fail "restore failed: $(cat restore6.out)"
"$src/experiments/grid.sh" --extend 170 --out restored_fin > grid8.out 2>&1 && fail "a grid without its runs' checkpoints was extended"
grep -q "needs each finished run's checkpoint, and these have none: a1_beam/masa_s0 a1_beam/sa_s0" grid8.out || \
  fail "no reason given: $(cat grid8.out)"
grep -q "^updates=160$" restored_fin/grid.txt && [ -f restored_fin/a1_beam/masa_s0/done ] || fail "the refused extension changed the grid"
"$src/experiments/record_grid.sh" --out grid --to rec_all --all-checkpoints > rec7.out 2>&1 || fail "--all-checkpoints failed: $(cat rec7.out)"
for m in masa sa; do
  [ -s "rec_all/a1_beam/${m}_s0/checkpoint.bin" ] && [ -s "rec_all/a1_beam/${m}_s0/actor_state.bin.xz" ] || \
    fail "--all-checkpoints did not keep finished $m's checkpoint and environments"
done
grep -q "^checkpoints: 2 runs keep theirs" rec_all/RECORD.txt || fail "RECORD.txt: $(grep checkpoints rec_all/RECORD.txt)"
"$src/experiments/restore_grid.sh" --from rec_all --out restored_all > restore7.out 2>&1 || fail "restore failed: $(cat restore7.out)"
"$src/experiments/grid.sh" --extend 170 --out restored_all > grid9.out 2>&1 || fail "extending the restored grid failed: $(cat grid9.out)"
for m in masa sa; do
  grep -q "^masa_train: resumed at update 160 (.*); the environments go on as they were" "restored_all/a1_beam/${m}_s0.log" && \
    [ -f "restored_all/a1_beam/${m}_s0/done" ] && [ "$(wc -l < "restored_all/a1_beam/${m}_s0/metrics.csv")" -eq 171 ] || \
    fail "the restored $m run did not go on from 160 to 170: $(grep resumed "restored_all/a1_beam/${m}_s0.log")"
done
echo "PASS: killed at update $rows_at_kill, resumed to 150, finished runs not redone, comparison drawn, extended to 160, recorded, filmed, hosts file used, restored from its record, extended after a restore"
