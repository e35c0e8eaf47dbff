#!/usr/bin/env bash
# Makes a run key (common/transport/run_key.hpp: 64 hex digits of 32 random bytes, mode 0600) at
# PATH unless one is there; a key already there is kept (a resumed run keeps its key).
#   deploy/run_key.sh PATH
# deploy/train.sh calls it before it starts the learner and the actors, and gives both --key-file.
set -euo pipefail

[ $# -eq 1 ] || { echo "run_key.sh: usage: run_key.sh PATH" >&2; exit 2; }
key=$1
[ -e "$key" ] && exit 0
umask 077
tmp="$key.tmp.$$"
od -An -v -tx1 -N32 /dev/urandom | tr -d ' \n' > "$tmp"
echo >> "$tmp"
[ "$(head -c 64 "$tmp" | tr -d '0-9a-f' | wc -c)" = 0 ] && [ "$(wc -c < "$tmp")" = 65 ] ||
  { rm -f "$tmp"; echo "run_key.sh: could not read 32 random bytes" >&2; exit 1; }
# A hard link appears whole and never replaces a key that another process made meanwhile.
ln "$tmp" "$key" 2>/dev/null || [ -e "$key" ] || { rm -f "$tmp"; echo "run_key.sh: cannot create $key" >&2; exit 1; }
rm -f "$tmp"
