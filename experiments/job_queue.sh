# The work queue of grid.sh and offline_table.sh (sourced, not run): a file of job lines that
# parallel workers take one at a time under a lock, and stopping every worker and its runs on a kill.

# pop_job QUEUE LOCK: prints the queue's first line and removes it; prints nothing when it is empty.
pop_job() {
  flock "$2" bash -c 'l=$(head -n 1 "$0"); [ -n "$l" ] && sed -i 1d "$0"; printf %s "$l"' "$1"
}

descendants() { local c; for c in $(pgrep -P "$1"); do echo "$c"; descendants "$c"; done; }

# stop_workers MESSAGE PID...: SIGTERM to the workers and everything they started, waits until each
# has exited (so that a rerun never meets a run still writing), says MESSAGE and exits 143.
stop_workers() {
  local message=$1 p
  shift
  local all=("$@")
  for p in "$@"; do mapfile -t -O "${#all[@]}" all < <(descendants "$p"); done
  kill -TERM "${all[@]}" 2>/dev/null || true
  for p in "${all[@]}"; do while kill -0 "$p" 2>/dev/null; do sleep 0.1; done; done
  echo "$message" >&2
  exit 143
}
