# Sourced by the masa_train cases (train_resume_exact.sh, off_policy_resume_exact.sh,
# train_bus_same_run.sh) with BUILD_DIR and WORK_DIR as $1 and $2: a fresh work directory to run
# in, fail() that shows the logs' tails, masa_train on one thread, and strip() for comparing runs.
set -euo pipefail
build=$(cd "$1" && pwd) work=$2
rm -rf "$work" && mkdir -p "$work" && cd "$work"
fail() { echo "FAIL: $*"; for f in *.log; do echo "--- $f"; tail -n 5 "$f"; done; exit 1; }
export OMP_NUM_THREADS=1
train=("$build/tools/masa_train" --quiet --threads 1)
# A metrics file without the clocks (wall_time_s, fps): what two runs of the same seed share.
strip() { awk -F, 'NR == 1 { for (c = 1; c <= NF; c++) skip[c] = ($c == "wall_time_s" || $c == "fps") }
                   { line = ""; for (c = 1; c <= NF; c++) if (!skip[c]) line = line $c ","; print line }' "$1"; }
