#!/usr/bin/env bash
# Runs a command tethered to its standard input: when stdin reaches end of file, the command is
# asked to stop (SIGTERM, then SIGKILL after MASA_TETHER_GRACE_S seconds, default 10). `deploy/train.sh --hosts` starts every remote
# actor (over ssh) and its own learner this way, with its keep-alive pipe as stdin, so that they
# stop when the launcher exits or is killed, or when the ssh session that carries the pipe dies:
# a dead ssh session alone does not reliably stop what it started (without a terminal nothing
# sends it SIGHUP).
#   tethered.sh PROGRAM [ARGS...]     (stdin: a pipe that nothing writes to; its end is the signal)
# SIGHUP, SIGINT and SIGTERM to this script stop the program too. Exit status: the program's.
set -euo pipefail

[ $# -ge 1 ] || { echo "tethered.sh: usage: tethered.sh PROGRAM [ARGS...]" >&2; exit 2; }
if ! command -v "$1" >/dev/null; then
  echo "tethered.sh: $1 is missing on $(hostname) (in $PWD): build there first (scripts/build.sh)" >&2
  exit 2
fi

"$@" </dev/null &
child=$!
trap 'kill -TERM "$child" 2>/dev/null || true' HUP INT TERM

# The watcher reads the pipe with bash's builtin read (no child process that could keep an ssh
# session open) and, at end of file, asks the program to stop, then insists.
exec 3<&0 0</dev/null
(
  trap - HUP INT TERM
  while IFS= read -r -u 3 _; do :; done
  kill -TERM "$child" 2>/dev/null || exit 0
  # The grace period's sleep must not outlive this watcher (it is ended when the program stops).
  sleep "${MASA_TETHER_GRACE_S:-10}" >/dev/null 2>&1 &
  nap=$!
  trap 'kill "$nap" 2>/dev/null; exit 0' TERM
  wait "$nap"
  kill -KILL "$child" 2>/dev/null || true
) &
watcher=$!
exec 3<&-

set +e
while :; do
  wait "$child"
  rc=$?
  # A trapped signal interrupts wait with the program still alive: wait again.
  kill -0 "$child" 2>/dev/null || break
done
kill "$watcher" 2>/dev/null
exit "$rc"
