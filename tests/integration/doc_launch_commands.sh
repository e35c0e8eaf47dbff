#!/usr/bin/env bash
# Every launch command of the given documents runs as a user copies it (issue #53). The commands are
# taken from the documents' fenced bash blocks: each line (with its continuations) whose program is
# scripts/run.sh, deploy/train.sh, deploy/cluster/mpirun_train.sh or sbatch, so a document that
# drifts from the launchers fails here. What the test changes, and only that:
#  - the run's length: --updates N becomes --updates 2 (4 for a --resume, which counts all
#    updates), and a command that leaves it to the recipe or the default gets --updates 2;
#  - the placeholders a user fills: the hosts file a command names (an Open MPI hostfile of this
#    machine for --hostfile, "localhost 2 8" for train.sh --hosts) and runs/<run dir> (the run the
#    document's command before made);
#  - where things go (environment only): MASA_BUILD_DIR, MASA_RUNS_DIR, MASA_LCM_URL, SBATCH_OUTPUT.
# Each command must end with status 0 and leave a run with a checkpoint and one metrics row per
# update, and no output may hold an internal "check failed". Slurm commands run on a one-host cluster
# the test starts (tests/cluster/local_slurm.sh): without root, Slurm or munge they are skipped with
# the reason; where all are present, a cluster that does not come up fails the test.
#   tests/integration/doc_launch_commands.sh BUILD_DIR DOC...   (relative to the repository; a folder
#                                                                stands for every .md file under it)
set -uo pipefail
repo=$(cd "$(dirname "$0")/../.." && pwd)
build=$(cd "${1:?usage: doc_launch_commands.sh BUILD_DIR DOC...}" && pwd)
shift
source "$repo/tests/cluster/local_slurm.sh"
work=$(mktemp -d "${TMPDIR:-/tmp}/masa_doc_commands.XXXXXX")
slurm_state=""  # "", up, skip or failed
cleanup() {
  [ "$slurm_state" != up ] || local_slurm_stop > /dev/null 2>&1
  rm -rf "$work"
}
trap cleanup EXIT
failures=0 skipped=0
fail() {
  echo "FAIL: $*"
  failures=$((failures + 1))
}
log() { echo "[$(date +%H:%M:%S)] $*"; }

# "LINE<tab>command" for each launch command of a markdown file's bash blocks, comments cut.
launch_commands() {
  awk '
    /^[[:space:]]*```/ {
      if (fence) fence = 0; else { fence = 1; bash = ($0 ~ /^[[:space:]]*```(bash|sh|shell)?[[:space:]]*$/) }
      next
    }
    fence && bash {
      if (joining) cmd = cmd " " $0; else { cmd = $0; at = NR }
      if (cmd ~ /\\$/) { sub(/\\$/, "", cmd); joining = 1; next }
      joining = 0
      sub(/[[:space:]]+#.*$/, "", cmd)
      split(cmd, w, /[[:space:]]+/)
      first = (w[1] == "" ? w[2] : w[1])
      if (first ~ /^(scripts\/run\.sh|deploy\/train\.sh|deploy\/cluster\/mpirun_train\.sh|sbatch)$/) print at "\t" cmd
    }' "$1"
}

# The run directory a launcher said it used (its last "run dir X" or "resuming X").
run_dir_of() {
  sed -n -e 's/.*[ ,]run dir \([^ ,]*\).*/\1/p' -e 's/.*: resuming \([^ ]*\) .*/\1/p' "$1" | tail -n 1
}

# Starts the one-host Slurm cluster once; 0 when it is up.
need_slurm() {
  if [ -z "$slurm_state" ]; then
    local status=0
    # As many CPUs as the documents' jobs ask for: their tasks share this machine's cores.
    local_slurm_start "$work/slurm" 64 || status=$?
    case $status in 0) slurm_state=up ;; 1) slurm_state=skip ;; *) slurm_state=failed ;; esac
  fi
  [ "$slurm_state" = up ]
}

# Runs one command (words in "${words[@]}", as the document has them) and checks its run.
run_command() {
  local where=$1 out=$2
  local is_slurm=0 is_resume=0 updates_given=0 i
  [ "${words[0]}" != sbatch ] || is_slurm=1
  for i in "${!words[@]}"; do [ "${words[i]}" != --resume ] || is_resume=1; done
  local updates=2
  [ "$is_resume" = 0 ] || updates=4
  for i in "${!words[@]}"; do
    case "${words[i]}" in
      --updates) words[i+1]=$updates updates_given=1 ;;
      --hostfile | --hosts)
        local file=$work/$(basename "${words[i+1]}")
        if [ "${words[i]}" = --hostfile ]; then echo "localhost slots=64" > "$file"; else echo "localhost 2 8" > "$file"; fi
        words[i+1]=$file ;;
    esac
  done
  [ "$updates_given" = 1 ] || words+=(--updates "$updates")
  local port=$((7000 + RANDOM % 90 * 4))  # 7000-7359, below every fixed port of the other tests
  export MASA_BUILD_DIR=$build MASA_RUNS_DIR=$work/runs MASA_LCM_URL="udpm://239.255.76.67:$port?ttl=0"
  log "$where: ${words[*]}"
  local status=0
  if [ "$is_slurm" = 1 ]; then
    if ! need_slurm; then
      [ "$slurm_state" = skip ] && { echo "SKIP: $where (see the reason above)"; skipped=$((skipped + 1)); return; }
      fail "$where: the local Slurm cluster did not come up"
      return
    fi
    local id
    id=$(SBATCH_OUTPUT="$work/job-%j.out" "${words[@]}" 2>&1 < /dev/null | tee "$out" | sed -n 's/^Submitted batch job \([0-9]*\).*/\1/p')
    [ -n "$id" ] || { fail "$where: sbatch refused the job: $(cat "$out")"; return; }
    local _
    for _ in $(seq 1 1500); do squeue -h -j "$id" 2> /dev/null | grep -q . || break; sleep 0.2; done
    if squeue -h -j "$id" 2> /dev/null | grep -q .; then
      scancel "$id"
      fail "$where: job $id still runs after 300 s"
    fi
    cat "$work/job-$id.out" >> "$out" 2> /dev/null
    grep -q "stopped after $updates updates" "$out" || status=1
  else
    timeout 300 "${words[@]}" > "$out" 2>&1 < /dev/null || status=$?
  fi
  if grep -q "check failed" "$out"; then fail "$where: an internal check reached the user: $(grep -m1 'check failed' "$out")"; fi
  [ "$status" = 0 ] || { fail "$where: ended with status $status"; tail -n 15 "$out"; return; }
  run_dir=$(run_dir_of "$out")
  [[ $run_dir = /* ]] || run_dir=$repo/$run_dir
  local rows=$(($(wc -l < "$run_dir/metrics.csv" 2> /dev/null || echo 1) - 1))
  if [ ! -f "$run_dir/checkpoint.bin" ] || [ "$rows" -ne "$updates" ]; then
    fail "$where: run dir '$run_dir' has $rows metrics rows, expected $updates, and a checkpoint"
    tail -n 15 "$out"
    return
  fi
  log "   $updates updates in $run_dir"
}

cd "$repo"
docs=()
for doc in "$@"; do
  if [ -d "$doc" ]; then mapfile -t -O "${#docs[@]}" docs < <(find "$doc" -name '*.md' | sort); else docs+=("$doc"); fi
done
commands=0
for doc in "${docs[@]}"; do
  [ -f "$doc" ] || { fail "no document $doc"; continue; }
  run_dir=""
  while IFS=$'\t' read -r line cmd; do
    commands=$((commands + 1))
    where="$doc:$line"
    if [[ $cmd == *"runs/<"*">"* ]]; then
      [ -n "$run_dir" ] || { fail "$where: names runs/<...> but no command before it made a run"; continue; }
      cmd=$(sed "s|runs/<[^>]*>|$run_dir|g" <<< "$cmd")
    fi
    [[ $cmd != *"<"* ]] || { fail "$where: a placeholder this test cannot fill: $cmd"; continue; }
    set -f
    eval "words=($cmd)"
    set +f
    run_command "$where" "$work/command$commands.out"
  done < <(launch_commands "$doc")
done
[ "$commands" -gt 0 ] || fail "no launch command in $*"
if [ "$failures" = 0 ]; then
  skip_note=""
  [ "$skipped" = 0 ] || skip_note=" ($skipped skipped, as said above)"
  echo "PASS: $((commands - skipped)) launch commands of $* ran as written$skip_note"
else
  echo "FAIL: $failures of $commands launch commands"
fi
