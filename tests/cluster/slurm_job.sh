#!/usr/bin/env bash
# Training as a Slurm job (issue #30) on a one-host cluster that the test starts (munge, slurmctld,
# slurmd; tests/cluster/local_slurm.sh), skipped with the reason where it cannot (not root, no
# Slurm): deploy/cluster/slurm_train.sbatch with 4 tasks, 2 learner ranks and 2 actors,
#  1. trains 20 updates and ends: every rank's rows in metrics.csv, every process gone;
#  2. cancelled with scancel mid-run: every process of the job stops within seconds, and the
#     learners leave a checkpoint of the update they reached.
#   tests/cluster/slurm_job.sh BUILD_DIR     (exit 77: skipped, where root, Slurm or munge is missing)
set -euo pipefail
repo=$(cd "$(dirname "$0")/../.." && pwd)
build=$(cd "${1:-build}" && pwd)
source "$repo/tests/cluster/local_slurm.sh"
work=$(mktemp -d "${TMPDIR:-/tmp}/masa_slurm.XXXXXX")
cleanup() {
  local_slurm_stop > /dev/null 2>&1 || true
  rm -rf "$work"
}
trap cleanup EXIT
fail() {
  echo "FAIL: $*"
  for f in "$work"/*.out "$work"/slurm/log/*.log; do [ -f "$f" ] && { echo "--- tail of $f"; tail -n 20 "$f"; }; done
  exit 1
}
log() { echo "[$(date +%H:%M:%S)] $*"; }
# Missing root, Slurm or munge: skipped (77); present but the cluster does not come up: failed.
slurm_status=0
local_slurm_start "$work/slurm" || slurm_status=$?
[ "$slurm_status" -ne 1 ] || exit 77
[ "$slurm_status" -eq 0 ] || exit 1
cd "$repo"
marker=$((100000 + RANDOM * 7 % 800000))  # the seed marks this test's processes (pgrep)
small=(--set ppo.horizon=16 --set ppo.minibatch_size=128 --set model.policy_hidden=[16] --set model.critic_hidden=[16]
       --set seed=$marker)
submit() {  # submit NAME UPDATES: the job id
  MASA_BUILD_DIR="$build" MASA_LCM_URL="udpm://239.255.76.67:$((7400 + RANDOM % 100 * 4))?ttl=0" \
    sbatch --parsable --ntasks 4 --nodes 1 --overcommit --output="$work/$1.out" \
    deploy/cluster/slurm_train.sbatch a1_beam masa --ranks 2 --envs 8 --updates "$2" --run-dir "$work/$1" "${small[@]}"
}
finished() { ! squeue -h -j "$1" 2> /dev/null | grep -q .; }
job_processes() { pgrep -fc "^($build/learner/masa_learner|$build/actors/masa_actor) .*seed=$marker" || true; }

log "1. a job of 2 learner ranks and 2 actors, 20 updates"
id=$(submit run 20) || fail "sbatch refused the job"
for _ in $(seq 1 600); do finished "$id" && break; sleep 0.2; done
finished "$id" || { scancel "$id"; fail "job $id still runs after 120 s"; }
rows=$(($(wc -l < "$work/run/metrics.csv" 2> /dev/null || echo 1) - 1))
[ "$rows" -eq 20 ] || fail "metrics.csv has $rows rows, expected 20"
[ "$(tail -n 1 "$work/run/metrics.csv" | cut -d, -f2)" -eq $((20 * 16 * 16)) ] || fail "env steps are not both ranks'"
grep -q "rank 1 of 2: stopped after 20 updates" "$work/run.out" || fail "rank 1 did not stop cleanly"
[ "$(grep -c 'masa_actor [01]: stopped after' "$work/run.out")" -eq 2 ] || fail "the actors did not stop cleanly"
log "   20 updates, both ranks and both actors stopped"

log "2. scancel mid-run"
id=$(submit cancelled 100000) || fail "sbatch refused the job"
for _ in $(seq 1 600); do
  [ -f "$work/cancelled/metrics.csv" ] && [ "$(wc -l < "$work/cancelled/metrics.csv")" -ge 6 ] && break
  sleep 0.2
done
[ -f "$work/cancelled/metrics.csv" ] || { scancel "$id"; fail "the job did not start training"; }
[ "$(job_processes)" -eq 4 ] || fail "$(job_processes) processes run, expected 4"
scancel "$id"
t0=$(date +%s)
for _ in $(seq 1 150); do [ "$(job_processes)" -eq 0 ] && finished "$id" && break; sleep 0.1; done
[ "$(job_processes)" -eq 0 ] || fail "$(job_processes) processes left 15 s after scancel"
reached=$(($(wc -l < "$work/cancelled/metrics.csv") - 1))
[ -f "$work/cancelled/checkpoint.bin" ] || fail "no checkpoint after scancel"
log "   every process gone $(( $(date +%s) - t0 )) s after scancel, at update $reached"
echo "PASS"
