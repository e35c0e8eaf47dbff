#!/usr/bin/env bash
# experiments/ship_policy.sh on a tiny run, shipped --to a scratch folder (never over tasks/): the
# policy loads and evaluates, the folder has its evaluation, strip, config and metrics, and its
# README names the commit that trained the run (config.yaml's "Written by masa", which outranks
# --commit) and the run's exact command from the log beside it; a folder that is no run is refused.
#   tests/tools/ship_policy.sh BUILD_DIR WORK_DIR
set -uo pipefail
build=$(cd "$1" && pwd) work=$2
src=$(cd "$(dirname "$0")/../.." && pwd)
export MASA_BUILD_DIR=$build OMP_NUM_THREADS=1
rm -rf "$work" && mkdir -p "$work" && cd "$work" || exit 1
fail() { echo "FAIL: $*"; exit 1; }
echo "# a log as grid.sh writes it" > run.log
"$build/tools/masa_train" --set task=a1_beam --set model.policy_hidden=[16] --set model.critic_hidden=[16] \
  --set ppo.num_envs=8 --set ppo.horizon=8 --set ppo.minibatch_size=64 --set env.max_episode_steps=20 \
  --quiet --updates 2 --run-dir run >> run.log 2>&1 || fail "masa_train failed: $(cat run.log)"
sed -i "1a # $(date -u +%FT%TZ) on localhost: cd $PWD \&\& $build/tools/masa_train --quiet --updates 2 --run-dir $PWD/run --set task=a1_beam" run.log
"$src/experiments/ship_policy.sh" run --episodes 2 --commit 0123abc --to shipped > ship.out 2>&1 || fail "ship_policy.sh failed: $(cat ship.out)"
for f in policy.bin config.yaml metrics.csv eval.txt eval.csv strip.png README.md; do
  [ -s "shipped/$f" ] || fail "the shipped folder has no $f"
done
"$build/tools/masa_eval" shipped/policy.bin --episodes 1 > eval.out 2>&1 || fail "the shipped policy does not evaluate: $(cat eval.out)"
grep -q "over 2 episodes" shipped/eval.txt || fail "eval.txt: $(cat shipped/eval.txt)"
written=$(sed -n 's/^# Written by masa \([0-9a-f]*\).*/\1/p' run/config.yaml)
if [ -n "$written" ]; then
  grep -q "by commit ${written:0:7} on" shipped/README.md || fail "the README does not name the run's commit $written: $(head -4 shipped/README.md)"
else
  grep -q "by commit 0123abc on" shipped/README.md || fail "the README does not name --commit: $(head -4 shipped/README.md)"
fi
grep -q "^3 updates\|^2 updates" shipped/README.md || fail "the README does not give the updates: $(head -4 shipped/README.md)"
grep -q 'The command (from the run.s log): `masa_train --quiet --updates 2 --set task=a1_beam`' shipped/README.md || \
  fail "the README does not give the run's command: $(head -5 shipped/README.md)"
mkdir notarun
"$src/experiments/ship_policy.sh" notarun --to shipped2 > ship2.out 2>&1 && fail "a folder without config.yaml was shipped"
grep -q "notarun is not a run directory" ship2.out && [ ! -e shipped2 ] || fail "no reason given: $(cat ship2.out)"
"$src/experiments/ship_policy.sh" run --frames 3 > ship3.out 2>&1 && fail "an unknown option was accepted"
grep -q "unknown option '--frames'" ship3.out || fail "no reason given: $(cat ship3.out)"
echo "PASS: shipped a 2-update run with its evaluation, strip and provenance; refusals named"
