#!/usr/bin/env bash
# experiments/same_training.sh says "the same" for a build against itself, and "they differ" with
# the first update and column for a build that trains otherwise (a stand-in build whose masa_train
# runs the real one with another learning rate); bad use is refused with the reason.
#   tests/experiments/same_training_check.sh BUILD_DIR WORK_DIR
set -euo pipefail
build=$(cd "$1" && pwd) work=$2
src=$(cd "$(dirname "$0")/../.." && pwd)
rm -rf "$work" && mkdir -p "$work" && cd "$work"
fail() { echo "FAIL: $*"; exit 1; }
tiny=(--no-recipe --updates 6 --set task=a1_beam --set model.policy_hidden=[16] --set model.critic_hidden=[16]
      --set ppo.num_envs=8 --set ppo.horizon=8 --set ppo.minibatch_size=64 --set env.max_episode_steps=40
      --set runner.eval_episodes=1)

"$src/experiments/same_training.sh" "$build" "$build" "${tiny[@]}" > same.out 2>&1 || fail "a build against itself: $(cat same.out)"
grep -q "the same, bit for bit (no recipe, seed 7, 6 updates, 1 thread)" same.out || fail "said: $(cat same.out)"

mkdir -p other/tools
cat > other/tools/masa_train <<SH
#!/usr/bin/env bash
[ "\${1:-}" = --version ] && { echo otherwise; exit 0; }
exec "$build/tools/masa_train" "\$@" --set ppo.learning_rate=1.0e-3
SH
chmod +x other/tools/masa_train
rc=0; "$src/experiments/same_training.sh" "$build" other "${tiny[@]}" > differ.out 2>&1 || rc=$?
[ "$rc" = 1 ] || fail "a build that trains otherwise: exit $rc, $(cat differ.out)"
grep -Eq "they differ \(.*\): first at update [0-9]+, column [a-z_]+: " differ.out || fail "said: $(cat differ.out)"

rc=0; "$src/experiments/same_training.sh" "$build" > one.out 2>&1 || rc=$?
[ "$rc" = 2 ] && grep -q "give two build directories" one.out || fail "one build: exit $rc, $(cat one.out)"
rc=0; "$src/experiments/same_training.sh" "$build" nowhere > missing.out 2>&1 || rc=$?
[ "$rc" = 2 ] && grep -q "nowhere/tools/masa_train is missing" missing.out || fail "a missing build: exit $rc, $(cat missing.out)"
echo "PASS: the same build is the same, another learning rate differs ($(sed 's/.*: first/first/' differ.out)), bad use refused"
