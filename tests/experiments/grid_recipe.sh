#!/usr/bin/env bash
# experiments/grid.sh --recipe: every run of the grid is made from the one recipe named (here a
# YAML file) instead of its task's, runs to that recipe's length (here sac.env_steps: 4 rounds of 8 x 8), and the grid remembers
# it: a rerun naming another recipe is refused, a recipe that does not exist is refused up front.
# The recipe is off-policy, so the record (record_grid.sh) is checked to leave its replay state out.
#   tests/experiments/grid_recipe.sh BUILD_DIR WORK_DIR
set -euo pipefail
build=$(cd "$1" && pwd) work=$2
src=$(cd "$(dirname "$0")/../.." && pwd)
export MASA_BUILD_DIR=$build OMP_NUM_THREADS=1
rm -rf "$work" && mkdir -p "$work" && cd "$work"
fail() { echo "FAIL: $*"; for f in grid/a1_beam/*.log grid*.out; do [ -f "$f" ] && { echo "--- $f"; tail -n 20 "$f"; }; done; exit 1; }

cat > tiny.yaml <<'YAML'
task: a1_beam
method: masa
learner: off_policy
model: {policy_hidden: [16], critic_hidden: [16]}
sac: {num_envs: 8, horizon: 8, env_steps: 256, learning_starts: 64, batch_size: 32, policy_hidden: [16], q_hidden: [16],
      updates_per_step: 0.25}
runner: {checkpoint_every: 2, eval_every: 2, eval_episodes: 1}
env: {max_episode_steps: 40, velocity_reward: progress}
YAML

"$src/experiments/grid.sh" --recipe nosuch_recipe --tasks a1_beam --methods masa --seeds 0 --out bad > bad.out 2>&1 && \
  fail "a recipe that does not exist was accepted"
grep -q "no configs/recipes/nosuch_recipe.yaml" bad.out || fail "the missing recipe was not named: $(cat bad.out)"
[ ! -e bad/a1_beam ] || fail "the refused grid started runs"

"$src/experiments/grid.sh" --recipe tiny.yaml --tasks a1_beam --methods "masa sa" --seeds 0 --jobs 1 --out grid \
  > grid1.out 2>&1 || fail "the grid failed"
for m in masa sa; do
  d=grid/a1_beam/${m}_s0
  [ -f "$d/done" ] || fail "$m's run is not done"
  rows=$(($(wc -l < "$d/metrics.csv") - 1))
  [ "$rows" = 4 ] || fail "$m ran $rows updates, not the recipe's 4"
  grep -Eq "velocity_reward: progress" "$d/config.yaml" || fail "$m's run was not made from the recipe"
  grep -Eq "^method: $m" "$d/config.yaml" || fail "$m's run is not of its method"
done
grep -qx "recipe=$work/tiny.yaml" grid/grid.txt || fail "grid.txt does not keep the recipe: $(cat grid/grid.txt)"
"$src/experiments/grid.sh" --status --out grid > status.out 2>&1 || fail "--status failed"
grep -Eq "a1_beam +masa +seed 0 +4/4 +done" status.out || fail "--status does not read the recipe's target: $(cat status.out)"

# Recorded: the off-policy runs' replay state (off_policy_state.bin) stays out, as checkpoints do.
ls grid/a1_beam/masa_s0/off_policy_state.bin > /dev/null 2>&1 || fail "the off-policy run wrote no off_policy_state.bin (the test needs one)"
"$src/experiments/record_grid.sh" --out grid --to rec > rec.out 2>&1 || fail "record_grid.sh failed: $(cat rec.out)"
[ -z "$(find rec -name off_policy_state.bin)" ] || fail "the record kept the replay state: $(find rec -name off_policy_state.bin)"
[ -f rec/a1_beam/masa_s0/metrics.csv ] || fail "the record lacks the run's metrics"
"$src/experiments/grid.sh" --recipe a1_beam --out grid > other.out 2>&1 && fail "a rerun with another recipe was accepted"
grep -q "was made with recipe=" other.out || fail "the other recipe was not refused by name: $(cat other.out)"
echo "PASS: grid.sh --recipe makes every run from the recipe and keeps it"
