#!/usr/bin/env bash
# A stand-in for ssh in the multi-host tests: `netns_shell.sh NS 'shell command'` runs the command in
# network namespace NS, the way `ssh HOST 'shell command'` runs it on HOST (stdin passed through).
#   MASA_REMOTE_SHELL="bash tests/integration/netns_shell.sh" deploy/train.sh ... --hosts FILE
set -euo pipefail
[ $# -eq 2 ] || { echo "netns_shell.sh: usage: netns_shell.sh NAMESPACE 'shell command'" >&2; exit 2; }
exec ip netns exec "$1" bash -c "$2"
